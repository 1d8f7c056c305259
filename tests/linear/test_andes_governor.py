"""ANDES 2.x as a client of the governor export: a bare positioner built from the exported HYGOV4 /
HYGOV parameters, entered as exported (no arithmetic in the test), reproduces govcheck's gate steps
(t63) and large-move slopes (docs/linear.md section 7).

The case is ANDES's bundled SMIB (Sb = 100 MVA, the unit dispatched at 90 MW) with the governor on
GENCLS_1 at Tn = 50 MVA, so every machine-base parameter goes through ANDES's Tn/Sb conversion (the
pitfall the docs name); the export is asked for that rating, system base and dispatch. The machine's
inertia is raised to 1e4 s so that the speed deviation fed back into the governor stays negligible:
what is compared is the positioner, not the turbine.
"""

from __future__ import annotations

import numpy as np
import pytest

from compliance import metrics as M
from compliance.model.config import load_plant

andes = pytest.importorskip("andes")  # a test extra (pyproject [test]); CI installs it

SB, TN = 100.0, 50.0  # system base of SMIB.json, the unit's rating [MVA]
DISPATCH = 90.0  # [MW] SMIB's PV dispatch (p0 = 0.9 pu on Sb), the mechanical power the governor is initialised at


@pytest.fixture(scope="module")
def gov():
    from compliance.linear.governor_model import governor_parameters

    return governor_parameters(load_plant("plant-a"))


def _andes_gate(model: str, a: dict, moves: list, tf: float, tstep: float = 0.005):
    """Gate [pu of stroke] of a bare positioner in ANDES from the export ``a`` (``gov.andes(...)``):
    (t, gate, model) after set-point changes ``moves`` [(t, gate)]."""
    andes.config_logger(stream_level=40)
    ss = andes.load(andes.get_case("smib/SMIB.json"), setup=False, no_output=True, default_config=True)
    ss.add(model, dict(idx="G1", syn="GENCLS_1", **a[model]))
    ss.setup()
    ss.Fault.u.v[:] = 0  # SMIB.json carries a bus fault; the positioner test needs none
    ss.GENCLS.M.v[0] = 1e4
    ss.TDS.config.criteria = 0
    ss.PFlow.run()
    ss.TDS.config.tstep = tstep
    ss.TDS.config.no_tqdm = 1
    ss.TDS.init()
    h = getattr(ss, model)
    g0 = a["gate0"]
    for t_at, g in moves:
        ss.TDS.config.tf = t_at
        ss.TDS.run()
        h.paux0.v[:] = a["setpoint"][model] * (g - g0)  # the set-point moves the gate by (g - g0) pu
    ss.TDS.config.tf = tf
    ss.TDS.run()
    y = h.GATE_y if model == "HYGOV4" else h.LAG_y
    return np.array(ss.dae.ts.t), np.asarray(ss.dae.ts.x[:, y.a[0]]) / a["gate_output"]["per_pu_gate"], h


def _t63(t, g, t0, t1):
    i = (t >= t0) & (t < t1)
    tt, gg = t[i] - t0, g[i]
    return float(tt[np.argmax(np.abs(gg - gg[0]) >= 0.632 * abs(gg[-1] - gg[0]))])


def _slope(t, g, t0, direction):
    i = t >= t0
    T = M.stroke_time(t[i], g[i], 1.0, direction)[0]
    return None if T is None else 1.0 / T


def _govcheck_t63(gov):
    """govcheck's 5 % steps from the step instant: dead time + time constant [s], per direction."""
    return {("opening" if s["step"] > 0 else "closing"): s["dead_time"] + s["time_constant"] for s in gov.steps}


@pytest.fixture(scope="module")
def export(gov):
    return gov.andes(rating_mva=TN, system_mva=SB, dispatch_mw=DISPATCH)


def test_hygov4_bare_positioner_reproduces_the_gate_steps_and_rates(gov, export):
    p = export["HYGOV4"]
    x0 = export["gate0"]
    t, g, h = _andes_gate("HYGOV4", export, [(0.5, x0 + 0.05), (2.0, x0), (3.5, 0.0), (7.5, 1.0)], 12.5)
    assert g[0] == pytest.approx(x0, abs=1e-6)  # At puts the initial gate at the operating point
    # Tn/Sb conversion of the machine-base limits (what a user must not apply twice)
    assert h.UO.v[0] == pytest.approx(p["UO"] * TN / SB) and h.UC.v[0] == pytest.approx(p["UC"] * TN / SB)
    up, down = _t63(t, g, 0.5, 2.0), _t63(t, g, 2.0, 3.5)
    ref = _govcheck_t63(gov)
    # one symmetric lag (Tg) with Tp for the dead time against the servo's asymmetric steps: the mean
    # within 10 %; each direction within 20 % (the servo's own +5 %/-5 % spread is +/-14 %)
    assert 0.5 * (up + down) == pytest.approx(0.5 * (ref["opening"] + ref["closing"]), rel=0.10)
    assert up == pytest.approx(ref["opening"], rel=0.20) and down == pytest.approx(ref["closing"], rel=0.20)
    # large moves: the gate slope over 25-75 % is the exported rate (limits on the gate velocity), 2 %
    assert _slope(t, g, 3.5, "closing") == pytest.approx(-gov.UC, rel=0.02)
    assert _slope(t, g, 7.5, "opening") == pytest.approx(gov.UO, rel=0.02)


def test_hygov4_limit_clips_the_five_per_cent_step_as_exported(gov, export):
    """The export's own statement: HYGOV4's gate-velocity limit clips a +5 % step for ~80 ms (0.05/Tg > UO)."""
    x0 = export["gate0"]
    t, g, _ = _andes_gate("HYGOV4", export, [(0.5, x0 + 0.05)], 1.5, tstep=0.001)
    i = (t > 0.5) & (t < 1.5)
    speed = np.gradient(g[i], t[i])
    at_limit = float(np.sum(speed > 0.98 * gov.UO) * 0.001)
    assert gov.hygov4_clipped(0.05) == pytest.approx(0.079, abs=0.01)
    assert at_limit == pytest.approx(gov.hygov4_clipped(0.05), abs=0.02)
    assert "clip a +5 % for" in gov.family["why"]


def test_hygov_velm_limits_the_integrator_so_small_steps_slow_down(gov, export):
    """HYGOV reproduces the large-move slope (VELM) but its 5 % step is slower than the servo's: the
    rate limit acts on the integrator before the Tg lag (docs/linear.md section 7, ANDES pitfalls)."""
    p = export["HYGOV"]
    x0 = export["gate0"]
    t, g, h = _andes_gate("HYGOV", export, [(0.5, x0 + 0.05), (2.0, x0), (3.5, 0.0)], 6.5)
    assert g[0] == pytest.approx(x0, abs=1e-6)
    assert h.VELM.v[0] == pytest.approx(p["VELM"] * TN / SB)
    assert _slope(t, g, 3.5, "closing") == pytest.approx(gov.VELM, rel=0.03)
    ref = _govcheck_t63(gov)
    step = 0.5 * (_t63(t, g, 0.5, 2.0) + _t63(t, g, 2.0, 3.5))
    # integrator ramps 5 % at VELM (~0.2 s) and the gate lags it by Tg: > 25 % slower than the servo
    assert step > 1.25 * 0.5 * (ref["opening"] + ref["closing"])


def test_psse_dyr_record_moves_the_gate_in_andes(gov, tmp_path):
    """The HYGOV record, pasted into a PSS/E .dyr in place of a TGOV1 and exported for that machine's MBASE,
    is read by ANDES's PSS/E parser with the same numbers and moves the gate at the servo's rate (not the
    near-still gate of placeholder governor settings)."""
    import pathlib

    case = pathlib.Path(andes.get_case("kundur/kundur.raw"))
    dyr = (case.parent / "kundur_full.dyr").read_text()
    blocks = dyr.split("/")
    keep = [b for b in blocks if not ("'TGOV1'" in b and b.strip().startswith("1 "))]
    andes.config_logger(stream_level=40)
    # the machine's MBASE and its power-flow dispatch, as ANDES reads the case (bus 1 is Kundur's slack)
    probe = andes.load(str(case), addfile=str(case.parent / "kundur_full.dyr"), no_output=True, default_config=True)
    probe.PFlow.run()
    row = list(probe.GENROU.bus.v).index(1)
    mbase, sbase = float(probe.GENROU.Sn.v[row]), float(probe.config.mva)
    gen = probe.GENROU.gen.v[row]
    src = probe.PV if gen in probe.PV.idx.v else probe.Slack
    dispatch = float(src.p.v[list(src.idx.v).index(gen)]) * sbase
    out = tmp_path / "kundur_hygov.dyr"
    out.write_text("/".join(keep).rstrip() + "\n" + gov.dyr(bus=1, machine="1", rating_mva=mbase, system_mva=sbase,
                                                             dispatch_mw=dispatch) + "\n")
    ss = andes.load(str(case), addfile=str(out), no_output=True, default_config=True)
    assert ss.HYGOV.n == 1
    a = gov.andes(rating_mva=mbase, system_mva=sbase, dispatch_mw=dispatch)
    k = a["gate_output"]["per_pu_gate"]
    assert ss.HYGOV.Tg.v[0] == pytest.approx(gov.Tg, rel=1e-5)
    assert ss.HYGOV.VELM.v[0] == pytest.approx(gov.VELM * k, rel=1e-5)
    assert ss.HYGOV.GMAX.v[0] == pytest.approx(gov.GMAX * k, rel=1e-5)
    assert ss.HYGOV.R.v[0] == pytest.approx(a["HYGOV"]["R"] / k, rel=1e-5)  # 1/R = 10 ms on Sb
    ss.TDS.config.criteria = 0
    ss.TDS.config.no_tqdm = 1
    ss.PFlow.run()
    ss.TDS.config.tstep = 0.005
    ss.TDS.init()
    y = ss.HYGOV.LAG_y.a[0]
    g0 = float(ss.dae.x[y]) / k
    assert g0 == pytest.approx(a["gate0"], abs=1e-3)  # At puts the gate at the operating point
    ss.TDS.config.tf = 0.5
    ss.TDS.run()
    ss.HYGOV.paux0.v[:] = a["setpoint"]["HYGOV"] * -0.2  # close the gate by 20 % of stroke
    ss.TDS.config.tf = 2.5
    ss.TDS.run()
    t, g = np.array(ss.dae.ts.t), np.asarray(ss.dae.ts.x[:, y]) / k
    assert g[-1] == pytest.approx(g0 - 0.2, abs=0.01)  # it got there (placeholders: r = 1 left it almost still)
    i = t > 0.5
    assert float(np.min(np.gradient(g[i], t[i]))) == pytest.approx(-gov.VELM, rel=0.05)  # at the servo's rate
