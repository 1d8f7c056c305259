"""ANDES 2.x as a client of the governor export: a bare positioner built from the exported HYGOV4 /
HYGOV parameters reproduces govcheck's gate steps (t63) and large-move slopes (docs/linear.md section 7).

The case is ANDES's bundled SMIB (Sb = 100 MVA) with the governor on GENCLS_1 at Tn = 50 MVA, so
every machine-base parameter goes through ANDES's Tn/Sb conversion (the pitfall the docs name).
The machine's inertia is raised to 1e4 s so that the speed deviation fed back into the governor
stays negligible: what is compared is the positioner, not the turbine.
"""

from __future__ import annotations

import numpy as np
import pytest

from compliance import metrics as M
from compliance.model.config import load_plant

andes = pytest.importorskip("andes")  # a test extra (pyproject [test]); CI installs it

SB, TN = 100.0, 50.0  # system base of SMIB.json, the unit's rating [MVA]
K = TN / SB  # machine base -> system base for ANDES's power=True parameters
TM0 = 0.9  # SMIB's PV dispatch [pu on Sb], the mechanical power the governor is initialised at


@pytest.fixture(scope="module")
def gov():
    from compliance.linear.governor_model import governor_parameters

    return governor_parameters(load_plant("plant-a"))


def _andes_gate(model: str, params: dict, g0: float, moves: list, tf: float, tstep: float = 0.005):
    """Gate [pu of stroke] of a bare positioner in ANDES: (t, gate) after reference changes ``moves`` [(t, gate)]."""
    andes.config_logger(stream_level=40)
    ss = andes.load(andes.get_case("smib/SMIB.json"), setup=False, no_output=True, default_config=True)
    # unity gate loop: HYGOV4 gate' = (pref + paux - Rperm GATE)/Tg needs Rperm = 1 on Sb, i.e. Tn/Sb on the
    # machine base (ipower); HYGOV's integrator gain R (on Sb): 1/R = 10 ms, temporary droop path ~0 (large r)
    # Hdam is a power=True parameter too: Sb/Tn on the machine base gives 1 pu head. At sets the initial gate.
    if model == "HYGOV4":
        base = dict(Rperm=1.0 * K, Rtemp=0.0, Tr=1.0, Tw=1.0, At=TM0 / (g0 * K), Dturb=0.0, Hdam=1.0 / K, qNL=0.0)
    else:
        base = dict(R=100.0 * K, r=1e6 * K, Tr=1.0, Tf=1e-3, Tw=1.0, At=TM0 / (g0 * K), Dt=0.0, qNL=0.0)
    ss.add(model, dict(idx="G1", syn="GENCLS_1", Tn=TN, **base, **params))
    ss.setup()
    ss.Fault.u.v[:] = 0  # SMIB.json carries a bus fault; the positioner test needs none
    ss.GENCLS.M.v[0] = 1e4
    ss.TDS.config.criteria = 0
    ss.PFlow.run()
    ss.TDS.config.tstep = tstep
    ss.TDS.config.no_tqdm = 1
    ss.TDS.init()
    h = getattr(ss, model)
    gain = h.Rperm.v[0] if model == "HYGOV4" else h.R.v[0]
    for t_at, g in moves:
        ss.TDS.config.tf = t_at
        ss.TDS.run()
        h.paux0.v[:] = gain * (g - g0) * K  # the reference moves the gate set-point by (g - g0) pu
    ss.TDS.config.tf = tf
    ss.TDS.run()
    y = h.GATE_y if model == "HYGOV4" else h.LAG_y
    return np.array(ss.dae.ts.t), np.asarray(ss.dae.ts.x[:, y.a[0]]) / K, h


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


def test_hygov4_bare_positioner_reproduces_the_gate_steps_and_rates(gov):
    p = gov.andes()["HYGOV4"]
    x0 = gov.point["position"] / gov.stroke
    t, g, h = _andes_gate("HYGOV4", p, x0, [(0.5, x0 + 0.05), (2.0, x0), (3.5, 0.0), (7.5, 1.0)], 12.5)
    # Tn/Sb conversion of the machine-base limits (what a user must not apply twice)
    assert h.UO.v[0] == pytest.approx(p["UO"] * K) and h.UC.v[0] == pytest.approx(p["UC"] * K)
    up, down = _t63(t, g, 0.5, 2.0), _t63(t, g, 2.0, 3.5)
    ref = _govcheck_t63(gov)
    # one symmetric lag (Tg) with Tp for the dead time against the servo's asymmetric steps: the mean
    # within 10 %; each direction within 20 % (the servo's own +5 %/-5 % spread is +/-14 %)
    assert 0.5 * (up + down) == pytest.approx(0.5 * (ref["opening"] + ref["closing"]), rel=0.10)
    assert up == pytest.approx(ref["opening"], rel=0.20) and down == pytest.approx(ref["closing"], rel=0.20)
    # large moves: the gate slope over 25-75 % is the exported rate (limits on the gate velocity), 2 %
    assert _slope(t, g, 3.5, "closing") == pytest.approx(-gov.UC, rel=0.02)
    assert _slope(t, g, 7.5, "opening") == pytest.approx(gov.UO, rel=0.02)


def test_hygov_velm_limits_the_integrator_so_small_steps_slow_down(gov):
    """HYGOV reproduces the large-move slope (VELM) but its 5 % step is slower than the servo's: the
    rate limit acts on the integrator before the Tg lag (docs/linear.md section 7, ANDES pitfalls)."""
    p = gov.andes()["HYGOV"]
    x0 = gov.point["position"] / gov.stroke
    t, g, h = _andes_gate("HYGOV", p, x0, [(0.5, x0 + 0.05), (2.0, x0), (3.5, 0.0)], 6.5)
    assert h.VELM.v[0] == pytest.approx(p["VELM"] * K)
    assert _slope(t, g, 3.5, "closing") == pytest.approx(gov.VELM, rel=0.03)
    ref = _govcheck_t63(gov)
    step = 0.5 * (_t63(t, g, 0.5, 2.0) + _t63(t, g, 2.0, 3.5))
    # integrator ramps 5 % at VELM (~0.2 s) and the gate lags it by Tg: > 25 % slower than the servo
    assert step > 1.25 * 0.5 * (ref["opening"] + ref["closing"])


def test_psse_dyr_record_loads_in_andes(gov, tmp_path):
    """The HYGOV record, pasted into a PSS/E .dyr in place of a TGOV1, is read by ANDES's PSS/E parser."""
    import pathlib

    case = pathlib.Path(andes.get_case("kundur/kundur.raw"))
    dyr = (case.parent / "kundur_full.dyr").read_text()
    blocks = dyr.split("/")
    keep = [b for b in blocks if not ("'TGOV1'" in b and b.strip().startswith("1 "))]
    out = tmp_path / "kundur_hygov.dyr"
    out.write_text("/".join(keep).rstrip() + "\n" + gov.dyr(bus=1, machine="1") + "\n")
    andes.config_logger(stream_level=40)
    ss = andes.load(str(case), addfile=str(out), no_output=True, default_config=True)
    assert ss.HYGOV.n == 1
    gen_sn = ss.GENROU.Sn.v[list(ss.GENROU.bus.v).index(1)]
    k = gen_sn / ss.config.mva  # Tn = 0 in a .dyr: ANDES takes the generator's MVA base
    assert ss.HYGOV.Tg.v[0] == pytest.approx(gov.Tg, rel=1e-5)
    assert ss.HYGOV.VELM.v[0] == pytest.approx(gov.VELM * k, rel=1e-5)
    assert ss.HYGOV.GMAX.v[0] == pytest.approx(gov.GMAX * k, rel=1e-5)
