"""Reference paths for continuous path tracking: circle, helix, CSV polylines; time-parameterised.

A path is a geometric curve in the robot's workspace [m] (origin = workspace centre). It is
made of *pieces* joined at stop points (sharp corners, pen lifts); inside a piece the curve is
a cubic spline through its points, parameterised by chord length (close to arc length for
densely sampled curves; exact for straight segments).

Time parameterisation (a one-pass version of the classical phase-plane method, Bobrow,
Dubowsky & Gibson 1985): on a fine arc-length grid the speed is limited by ``speed_limit``,
by the curvature (normal acceleration v^2 kappa <= ``acceleration_limit``) and by zero at
the stop points; a forward and a backward pass with the tangential acceleration limit give
the fastest profile with piecewise-constant tangential acceleration. Position, velocity and
acceleration then follow exactly from the spline derivatives: r' = c'(s) s', r'' = c''(s) s'^2
+ c'(s) s''.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path as _FsPath

import numpy as np
from scipy.interpolate import CubicSpline

from compliance.errors import InputError
from compliance.files.shipped import resolve_shipped

GRID_SPACING = 2e-4  # m: arc-length grid of the time parameterisation (0.2 mm)
CORNER_ANGLE = math.radians(20.0)  # a polyline turning more than this at a point stops there
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Trajectory:
    """A time-parameterised 3-D reference sampled at a fixed period.

    Attributes
    ----------
    time : ndarray
        [s], t_k = k * sample_time.
    position, velocity, acceleration : ndarray
        (n, 3) arrays [m], [m/s], [m/s^2] in workspace coordinates (x, y, z).
    path : ndarray
        (m, 3) dense points of the geometric path [m] (for path-deviation metrics and plots).
    name : str
    """

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    path: np.ndarray
    name: str

    @property
    def sample_time(self) -> float:
        """Sample period [s]."""
        return float(self.time[1] - self.time[0])

    @property
    def duration(self) -> float:
        """[s]."""
        return float(self.time[-1])

    def hold(self, lead: float = 0.0, tail: float = 0.0) -> "Trajectory":
        """The same trajectory with the start held for ``lead`` and the end for ``tail`` seconds."""
        ts = self.sample_time
        n0 = int(round(lead / ts))
        n1 = int(round(tail / ts))
        pad = lambda a, v0, v1: np.vstack([np.repeat(v0[None, :], n0, 0), a, np.repeat(v1[None, :], n1, 0)])  # noqa: E731
        z = np.zeros(3)
        pos = pad(self.position, self.position[0], self.position[-1])
        return Trajectory(np.arange(pos.shape[0]) * ts, pos, pad(self.velocity, z, z), pad(self.acceleration, z, z),
                          self.path, self.name)


# ----------------------------------------------------------------------------------------------
def _speed_profile(s, vlim, a_max):
    """Forward/backward pass: fastest speeds on grid ``s`` under ``vlim`` and |s''| <= a_max [m/s]."""
    v = np.array(vlim, dtype=float)
    v[0] = 0.0
    v[-1] = 0.0
    ds = np.diff(s)
    for i in range(len(ds)):
        v[i + 1] = min(v[i + 1], math.sqrt(v[i] * v[i] + 2.0 * a_max * ds[i]))
    for i in range(len(ds) - 1, -1, -1):
        v[i] = min(v[i], math.sqrt(v[i + 1] * v[i + 1] + 2.0 * a_max * ds[i]))
    return v


def _sample_piece(spline, length, t_start, ts, speed_limit, a_max):
    """Sample one piece (from rest to rest) on the global grid k*ts from ``t_start``.

    Returns (t_end, first sample index, positions, velocities, accelerations, dense points).
    """
    n = max(2, int(math.ceil(length / GRID_SPACING)) + 1)
    s = np.linspace(0.0, length, n)
    d1 = spline(s, 1)
    d2 = spline(s, 2)
    speed_s = np.linalg.norm(d1, axis=1)
    # curvature of a chord-parameterised spline: |c' x c''| / |c'|^3
    kappa = np.linalg.norm(np.cross(d1, d2), axis=1) / np.maximum(speed_s, 1e-12) ** 3
    vlim = np.full(n, speed_limit)
    curved = kappa > 1e-9
    vlim[curved] = np.minimum(speed_limit, np.sqrt(a_max / kappa[curved]))
    # chord parameter vs path speed: s' is the parameter rate, |c'| ~ 1
    vlim = vlim / np.maximum(speed_s, 1e-12)
    v = _speed_profile(s, vlim, a_max)
    ds = np.diff(s)
    vsum = v[:-1] + v[1:]
    dt = np.where(vsum > 0, 2.0 * ds / np.where(vsum > 0, vsum, 1.0), 2.0 * np.sqrt(ds / a_max))
    acc = np.where(vsum > 0, (v[1:] ** 2 - v[:-1] ** 2) / (2.0 * ds), 0.0)
    t_nodes = np.concatenate([[0.0], np.cumsum(dt)])
    total = float(t_nodes[-1])
    k0 = int(math.ceil(t_start / ts - 1e-9))
    k1 = int(math.floor((t_start + total) / ts + 1e-9))
    tk = np.arange(k0, k1 + 1) * ts - t_start
    tk = np.clip(tk, 0.0, total)
    i = np.clip(np.searchsorted(t_nodes, tk, side="right") - 1, 0, n - 2)
    tau = tk - t_nodes[i]
    sd = v[i] + acc[i] * tau  # s'
    sk = np.minimum(s[i] + v[i] * tau + 0.5 * acc[i] * tau * tau, length)
    sdd = acc[i]
    pos = spline(sk)
    c1 = spline(sk, 1)
    c2 = spline(sk, 2)
    vel = c1 * sd[:, None]
    accel = c2 * (sd * sd)[:, None] + c1 * sdd[:, None]
    dense = spline(s)
    return t_start + total, k0, pos, vel, accel, dense


def _pieces_from_points(points, corner_angle=CORNER_ANGLE):
    """Split a polyline into pieces at sharp corners and coincident points."""
    pts = np.asarray(points, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9])
    pts = pts[keep]
    if pts.shape[0] < 2:
        raise InputError("path: needs at least two distinct points")
    d = np.diff(pts, axis=0)
    u = d / np.linalg.norm(d, axis=1)[:, None]
    cosang = np.clip(np.sum(u[:-1] * u[1:], axis=1), -1.0, 1.0)
    corners = np.nonzero(np.arccos(cosang) > corner_angle)[0] + 1
    bounds = [0, *corners.tolist(), pts.shape[0] - 1]
    return [pts[a:b + 1] for a, b in zip(bounds[:-1], bounds[1:]) if b > a]


def _spline(piece):
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))])
    if piece.shape[0] == 2:
        # straight segment: exact linear parameterisation (a two-point CubicSpline is linear too)
        return CubicSpline(chord, piece, axis=0, bc_type="natural"), float(chord[-1])
    return CubicSpline(chord, piece, axis=0, bc_type="not-a-knot"), float(chord[-1])


def time_parameterise(points, *, speed_limit, acceleration_limit, sample_time, name="path",
                      corner_angle=CORNER_ANGLE) -> Trajectory:
    """Time-parameterise a polyline / densely sampled curve under speed and acceleration limits.

    Parameters
    ----------
    points : array_like
        (m, 3) points [m] in workspace coordinates.
    speed_limit : float
        Path speed limit [m/s].
    acceleration_limit : float
        Tangential and normal acceleration limit [m/s^2].
    sample_time : float
        Controller period [s].
    corner_angle : float
        Turning angle above which the path stops at a point [rad].

    Returns
    -------
    Trajectory
        From rest at the first point to rest at the last.
    """
    if not (speed_limit > 0 and acceleration_limit > 0 and sample_time > 0):
        raise InputError("path: speed limit, acceleration limit and sample time must be > 0")
    pieces = _pieces_from_points(points, corner_angle)
    t = 0.0
    chunks = []
    dense = []
    for piece in pieces:
        spl, length = _spline(piece)
        t_end, k0, pos, vel, acc, pts = _sample_piece(spl, length, t, sample_time, speed_limit, acceleration_limit)
        chunks.append((k0, pos, vel, acc))
        dense.append(pts)
        t = t_end
    n = int(math.floor(t / sample_time + 1e-9)) + 1
    P = np.zeros((n, 3))
    V = np.zeros((n, 3))
    A = np.zeros((n, 3))
    for k0, pos, vel, acc in chunks:
        k1 = min(n, k0 + pos.shape[0])
        P[k0:k1] = pos[: k1 - k0]
        V[k0:k1] = vel[: k1 - k0]
        A[k0:k1] = acc[: k1 - k0]
    return Trajectory(np.arange(n) * sample_time, P, V, A, np.vstack(dense), name)


# ----------------------------------------------------------------------------------------------
def _plane_points(u, v, plane):
    zeros = np.zeros_like(u)
    if plane == "xy":
        return np.column_stack([u, v, zeros])
    if plane == "xz":
        return np.column_stack([u, zeros, v])
    if plane == "yz":
        return np.column_stack([zeros, u, v])
    raise InputError(f"path: plane '{plane}' is not one of xy, xz, yz")


def circle(radius, frequency, *, cycles=1.0, plane="xy", acceleration_limit=2.0, sample_time=1e-3,
           points_per_turn=720) -> Trajectory:
    """A circle of ``radius`` centred on the origin, run at ``frequency`` turns per second.

    Starts and ends at rest at (radius, 0) of the plane; the path speed 2 pi f R is the speed
    limit, reached with ``acceleration_limit``.

    Parameters
    ----------
    radius : float [m]
    frequency : float [Hz]
    cycles : float
        Number of turns.
    plane : {"xy", "xz", "yz"}
    acceleration_limit : float [m/s^2]
    sample_time : float [s]
    """
    if not (radius > 0 and frequency > 0 and cycles > 0):
        raise InputError("circle: radius, frequency and cycles must be > 0")
    th = np.linspace(0.0, 2.0 * math.pi * cycles, int(math.ceil(points_per_turn * cycles)) + 1)
    pts = _plane_points(radius * np.cos(th), radius * np.sin(th), plane)
    speed = 2.0 * math.pi * frequency * radius
    a_lim = max(acceleration_limit, 1.05 * speed * speed / radius)  # the normal acceleration of the circle itself
    return time_parameterise(pts, speed_limit=speed, acceleration_limit=a_lim, sample_time=sample_time,
                             name=f"circle R{radius*1e3:g} mm at {frequency:g} Hz")


def helix(radius, frequency, pitch, *, cycles=1.0, acceleration_limit=2.0, sample_time=1e-3, points_per_turn=720) -> Trajectory:
    """A helix about the z axis: a circle in xy rising ``pitch`` per turn, centred on the origin in z.

    Parameters
    ----------
    radius : float [m]
    frequency : float
        Turns per second [Hz].
    pitch : float
        Rise per turn [m].
    cycles : float
    acceleration_limit : float [m/s^2]
    sample_time : float [s]
    """
    if not (radius > 0 and frequency > 0 and cycles > 0):
        raise InputError("helix: radius, frequency and cycles must be > 0")
    th = np.linspace(0.0, 2.0 * math.pi * cycles, int(math.ceil(points_per_turn * cycles)) + 1)
    z = pitch * th / (2.0 * math.pi) - 0.5 * pitch * cycles
    pts = np.column_stack([radius * np.cos(th), radius * np.sin(th), z])
    turn = math.hypot(2.0 * math.pi * radius, pitch)
    speed = frequency * turn
    kappa = radius / (radius * radius + (pitch / (2.0 * math.pi)) ** 2)
    a_lim = max(acceleration_limit, 1.05 * speed * speed * kappa)
    return time_parameterise(pts, speed_limit=speed, acceleration_limit=a_lim, sample_time=sample_time,
                             name=f"helix R{radius*1e3:g} mm pitch {pitch*1e3:g} mm at {frequency:g} Hz")


_UNITS = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6}


def read_path_csv(source) -> np.ndarray:
    """Read a path of points from CSV: header ``x_<unit>,y_<unit>,z_<unit>`` (unit m, cm, mm, um).

    Lines starting with ``#`` are comments. ``source`` is a file path or the name of a path
    shipped in ``compliance/data/paths/`` (``"jiang"``).

    Returns
    -------
    ndarray
        (m, 3) points [m].

    Raises
    ------
    InputError
        Missing file, bad header, a non-numeric or non-finite cell (row and column named).
    """
    path = resolve_shipped(source, "path")
    rows = [ln for ln in path.read_text(encoding="utf-8").splitlines()]
    data = [(i + 1, ln) for i, ln in enumerate(rows) if ln.strip() and not ln.lstrip().startswith("#")]
    if not data:
        raise InputError(f"{path}: no header line (expected x_mm,y_mm,z_mm)")
    header_line, header = data[0]
    cols = [c.strip() for c in next(csv.reader([header]))]
    scale = []
    for axis in AXES:
        match = [c for c in cols if c.split("_")[0] == axis]
        if not match:
            raise InputError(f"{path}: line {header_line}: no column for axis '{axis}' (expected e.g. '{axis}_mm')")
        unit = match[0].split("_", 1)[1] if "_" in match[0] else ""
        if unit not in _UNITS:
            raise InputError(f"{path}: line {header_line}: column '{match[0]}' has unit '{unit}'; expected one of {', '.join(_UNITS)}")
        scale.append((cols.index(match[0]), _UNITS[unit], match[0]))
    pts = []
    for line_no, ln in data[1:]:
        cells = next(csv.reader([ln]))
        row = []
        for idx, factor, name in scale:
            if idx >= len(cells):
                raise InputError(f"{path}: line {line_no}: column '{name}' is missing")
            try:
                val = float(cells[idx])
            except ValueError:
                raise InputError(f"{path}: line {line_no}, column '{name}': '{cells[idx].strip()}' is not a number") from None
            if not math.isfinite(val):
                raise InputError(f"{path}: line {line_no}, column '{name}': value is not finite")
            row.append(val * factor)
        pts.append(row)
    if len(pts) < 2:
        raise InputError(f"{path}: needs at least two points")
    return np.asarray(pts)


def stroke_path(source="jiang", *, scale=1.0, speed_limit=0.05, acceleration_limit=0.5, sample_time=1e-3) -> Trajectory:
    """A hand-drawn stroke path from CSV, centred on the origin, scaled by ``scale``.

    Parameters
    ----------
    source : str or path
        CSV file or shipped name.
    scale : float
        Factor applied to the drawing about its centre [-].
    speed_limit : float [m/s]
    acceleration_limit : float [m/s^2]
    sample_time : float [s]
    """
    pts = read_path_csv(source)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    pts = (pts - centre) * scale
    name = _FsPath(str(source)).stem
    return time_parameterise(pts, speed_limit=speed_limit, acceleration_limit=acceleration_limit, sample_time=sample_time,
                             name=f"stroke path '{name}'")
