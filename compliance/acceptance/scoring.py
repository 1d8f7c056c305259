"""A site's measured verdicts and figures scored against a known truth (a practice set's ``ANSWERS.json``).

Two questions, each answered like with like:

- **verdicts**: every requirement the truth judges has the truth's status, read the way the
  requirement file reads it (a requirement judging the time constant to the achieved travel is
  compared with the truth's ``alt:TC-ACH`` row; a marginal truth - within 3 % of its limit - may be
  UNCERTAIN);
- **figures**: every figure the truth gives lies within its stated expanded uncertainty of the truth,
  and within the acceptance tolerance of it (time constant 10 % or 5 ms, stroke times 2 %, errors,
  drift and dead band 0.1 mm); whether the stated uncertainty itself is narrower than the tolerance
  is reported beside (a stick-slip crossing can leave the log unable to say more). The figure is measured with the truth's own definition where it
  differs from the requirement file's (the positioning error as the mean |x - r| over the last 1 s of
  the plateau, the sinusoid's errors from a quarter period): the measurement is scored, not the
  reading.
"""

from __future__ import annotations

from compliance.acceptance.measure.recording import measure_test
from compliance.requirements.verdict import Status

__all__ = ["TOLERANCE", "score_figures", "score_verdicts", "truth_row"]

# acceptance tolerance per figure: (relative, absolute [SI]); a figure passes when within either
TOLERANCE = {"tau": (0.10, 0.005), "stroke": (0.02, 0.0), "error": (0.0, 1e-4), "speed": (0.02, 0.0)}
_STEP = (("time_constant", "tau_cmd_s", "tau"), ("time_constant_achieved", "tau_ach_s", "tau"),
         ("mean_positioning_error", "pos_error_m", "error"))
_STROKE = (("{d}_time", "T2575x2_s", "stroke"), ("stroke_speed", "v_mean_mps", "speed"), ("start_delay", "start_delay_s", "stroke"))
_HOLD = (("drift", "drift_fit_m", "error"), ("drift_excursion", "drift_max_m", "error"))


def truth_row(entry: dict) -> str:
    """The truth's row that judges a requirement entry as its file reads it."""
    if entry["measured_metric"] == "time_constant_achieved":
        return "alt:TC-ACH"
    if entry["measured_metric"] == "time_to_end":
        return "alt:TOPEN-T100" if "OPEN" in entry["id"] else "alt:TCLOSE-T100"
    return entry["id"]


def score_verdicts(results: dict, truth_site: dict) -> list:
    """One row per requirement the truth judges: ours, the truth's, whether they agree."""
    out = []
    for e in results["requirements"]:
        t = truth_site["verdicts"].get(truth_row(e))
        if t is None:
            continue
        want = t["verdict"].lower()
        ok = e["status"] == want or (t["marginal"] and e["status"] == Status.UNCERTAIN)
        w = e.get("worst") or {}
        out.append({"id": e["id"], "truth_row": truth_row(e), "status": e["status"], "truth": want, "marginal": t["marginal"],
                    "value": w.get("value"), "u": w.get("u"), "truth_value": t["worst"], "ok": ok})
    return out


def _row(site, test, what, m, true, kind) -> dict:
    rel, ab = TOLERANCE[kind]
    tol = max(rel * abs(true), ab)
    inside = m.value is not None and abs(m.value - true) <= m.u + 1e-12
    close = m.value is not None and abs(m.value - true) <= tol + 1e-12
    return {"site": site, "test": test, "figure": what, "value": m.value, "u": m.u, "truth": true, "tolerance": tol,
            "within_u": inside, "within_tolerance": close, "u_within_tolerance": m.u <= tol, "ok": inside and close}


def _step_rows(site, prep, cfg, truth) -> list:
    out = []
    cases = measure_test(prep, cfg, step_options={"final_window": 1.0})  # the truth's window: the last 1 s of the plateau
    for case, st in zip(cases, truth["steps"]):
        for key, tkey, kind in _STEP:
            if kind == "tau" and not st["tc_eligible"]:
                continue  # the truth judges the time constant on these steps only
            if st.get(tkey) is None:
                continue
            out.append(_row(site, prep.name, f"{key} @ {st['t_step_s']:g} s", case.values[key], st[tkey], kind))
    return out


def score_figures(site: str, prepared: list, cfg, truth_site: dict) -> list:
    """One row per figure the truth gives for the recordings of a site (see the module docstring)."""
    out = []
    for prep in prepared:
        t = truth_site["tests"].get(prep.name)
        if t is None or prep.problem:
            continue
        truth = t["truth"]
        if t["kind"] == "step_series":
            out += _step_rows(site, prep, cfg, truth)
            continue
        if t["kind"] == "sine":
            (case,) = measure_test(prep, cfg, sine={"skip_cycles": 0.25})  # the truth's window: from a quarter period
            out.append(_row(site, prep.name, "tracking_max_error", case.values["tracking_max_error"], truth["track_max_m"], "error"))
            continue
        (case,) = measure_test(prep, cfg)
        if t["kind"] == "full_stroke":
            for key, tkey, kind in _STROKE:
                key = key.format(d=truth["direction"])
                out.append(_row(site, prep.name, key, case.values[key], truth[tkey], kind))
        elif t["kind"] == "hold":
            for key, tkey, kind in _HOLD:
                out.append(_row(site, prep.name, key, case.values[key], truth[tkey], kind))
        elif t["kind"] == "dead_band_staircase":
            out.append(_row(site, prep.name, "dead_band", case.values["dead_band"], truth["dead_band_m"], "error"))
    return out
