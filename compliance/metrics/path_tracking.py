"""Path-tracking metrics: per-axis errors, 3-D path deviation, stick-slip episodes.

Per-axis errors use the ONE implementation of ``compliance.metrics.tracking_errors``; the
measured speed uses ``compliance.metrics.speed``. Definitions (docs/plant-b.md, "Metrics"):

- axis error: RMS and max of reference - position of one axis over the window (time-synchronous);
- path deviation: distance of the measured tool point from the reference *path* (the nearest
  point of the dense reference polyline, not the point the reference is at now), i.e. the
  contour error a drawing shows; RMS and max over the window;
- stick-slip episode: a stretch of at least ``min_duration`` during which the reference of an
  axis moves faster than ``moving_speed`` but the axis moves slower than ``stop_fraction`` of
  the reference speed in the reference's direction (stopped, stuck or going backwards);
- stick-slip fraction of an axis: time in its episodes / time its reference moves faster than
  ``moving_speed``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from compliance import metrics as M

MOVING_SPEED = 5e-3  # m/s: the reference counts as moving above this axis speed
STOP_FRACTION = 0.2  # an axis slower than this fraction of its reference speed is stopped
MIN_DURATION = 0.01  # s: shorter dips are not an episode
SPEED_WINDOW = 0.01  # s: centred difference of the measured position (metrics.speed)


def path_deviation(points, path) -> np.ndarray:
    """Distance of each point to the polyline ``path`` [m].

    Parameters
    ----------
    points : array_like
        (n, 3) measured positions [m].
    path : array_like
        (m, 3) dense reference path [m] (m >= 2).
    """
    pts = np.asarray(points, float)
    poly = np.asarray(path, float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(poly, axis=0), axis=1) > 0])
    poly = poly[keep]
    if poly.shape[0] < 2:
        return np.linalg.norm(pts - poly[0], axis=1)
    tree = cKDTree(poly)
    k = min(4, poly.shape[0])
    _, idx = tree.query(pts, k=k)
    idx = np.atleast_2d(idx).reshape(pts.shape[0], k)
    best = np.full(pts.shape[0], np.inf)
    m = poly.shape[0]
    for j in range(k):
        for off in (-1, 0):  # the segments on either side of each near vertex
            i0 = np.clip(idx[:, j] + off, 0, m - 2)
            a = poly[i0]
            b = poly[i0 + 1]
            ab = b - a
            t = np.clip(np.sum((pts - a) * ab, axis=1) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0.0, 1.0)
            d = np.linalg.norm(pts - (a + t[:, None] * ab), axis=1)
            best = np.minimum(best, d)
    return best


@dataclass(frozen=True)
class Episode:
    """One stick-slip episode of one axis."""

    axis: str
    t_start: float
    t_end: float

    @property
    def duration(self) -> float:
        """[s]."""
        return self.t_end - self.t_start


def stick_slip_episodes(time, position, reference_velocity, *, axis="x", moving_speed=MOVING_SPEED,
                        stop_fraction=STOP_FRACTION, min_duration=MIN_DURATION, window=SPEED_WINDOW) -> list[Episode]:
    """Episodes where the reference moves but the axis is stopped or reversed.

    Parameters
    ----------
    time : array [s]
    position : array
        Measured position [m].
    reference_velocity : array
        Reference velocity of the axis [m/s].
    moving_speed : float
        Reference speed above which the axis should move [m/s].
    stop_fraction : float
        The axis counts as stopped below this fraction of the reference speed, in its direction [-].
    min_duration : float
        Shortest episode [s].
    window : float
        Span of the centred difference for the measured speed [s].
    """
    t = np.asarray(time, float)
    vr = np.asarray(reference_velocity, float)
    v = M.speed(t, position, window)
    moving = np.abs(vr) > moving_speed
    along = v * np.sign(vr)
    bad = moving & (along < stop_fraction * np.abs(vr))
    out = []
    if not bad.any():
        return out
    edges = np.diff(np.concatenate([[0], bad.astype(int), [0]]))
    starts = np.nonzero(edges == 1)[0]
    ends = np.nonzero(edges == -1)[0] - 1
    for a, b in zip(starts, ends):
        if t[b] - t[a] >= min_duration:
            out.append(Episode(axis, float(t[a]), float(t[b])))
    return out


@dataclass(frozen=True)
class TrackingMetrics:
    """Metrics of one tracking run over its window (SI)."""

    axis_rms: dict
    axis_max: dict
    path_rms: float | None
    path_max: float | None
    episodes: tuple
    window: tuple
    moving_time: dict

    def stick_fraction(self, axis: str) -> float | None:
        """Time the axis spends in episodes / time its reference moves [-] (None: never moves)."""
        mt = self.moving_time.get(axis, 0.0)
        if not mt > 0:
            return None
        return sum(e.duration for e in self.episodes if e.axis == axis) / mt

    @property
    def stick_slip_count(self) -> int:
        """Episodes over all axes."""
        return len(self.episodes)

    def as_dict(self) -> dict:
        """Plain-JSON form."""
        return {
            "axis_rms_error": self.axis_rms,
            "axis_max_error": self.axis_max,
            "path_rms_error": self.path_rms,
            "path_max_error": self.path_max,
            "stick_slip_episodes": self.stick_slip_count,
            "stick_slip_fraction": {a: self.stick_fraction(a) for a in self.axis_rms},
            "episodes": [{"axis": e.axis, "t_start": e.t_start, "t_end": e.t_end} for e in self.episodes],
            "window": list(self.window),
        }


def axis_metrics(frame, axis="x", t_from=-np.inf, t_to=np.inf, **episode_options) -> TrackingMetrics:
    """Metrics of one axis run (a canonical frame with ``reference_velocity``)."""
    t, x, r, vr = M.frame_columns(frame, "time", "position", "reference", "reference_velocity")
    rms, mx = M.tracking_errors(t, x, r, t_from, t_to)
    sl = (t >= t_from) & (t < t_to)
    eps = stick_slip_episodes(t[sl], x[sl], vr[sl], axis=axis, **episode_options)
    return TrackingMetrics({axis: rms}, {axis: mx}, None, None, tuple(eps), (float(t[sl][0]), float(t[sl][-1])),
                           {axis: _moving_time(t[sl], vr[sl], episode_options)})


def _moving_time(t, vr, options) -> float:
    """Time the reference moves faster than the moving speed [s] (sample-period weighted)."""
    if t.size < 2:
        return 0.0
    dt = float(np.median(np.diff(t)))
    return float(np.count_nonzero(np.abs(vr) > options.get("moving_speed", MOVING_SPEED)) * dt)


def robot_metrics(run, t_from=-np.inf, t_to=np.inf, **episode_options) -> TrackingMetrics:
    """Metrics of a robot run (``robot.RobotRun``) over [t_from, t_to)."""
    t = run.time
    sl = (t >= t_from) & (t < t_to)
    rms, mx, eps, moving = {}, {}, [], {}
    for a in run.robot.axes:
        f = run.frames[a.name]
        tt, x, r, vr = M.frame_columns(f, "time", "position", "reference", "reference_velocity")
        rms[a.name], mx[a.name] = M.tracking_errors(tt, x, r, t_from, t_to)
        eps += stick_slip_episodes(tt[sl], x[sl], vr[sl], axis=a.name, **episode_options)
        moving[a.name] = _moving_time(tt[sl], vr[sl], episode_options)
    dev = path_deviation(run.stacked("position")[sl], run.trajectory.path)
    return TrackingMetrics(rms, mx, float(np.sqrt(np.mean(dev * dev))), float(np.max(dev)), tuple(eps),
                           (float(t[sl][0]), float(t[sl][-1])), moving)
