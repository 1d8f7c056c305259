"""The end of a remedies search: never worse than as given, the remedy's yield, or why none exists.

- The configuration as given is judged beside the candidates: a closest candidate that ranks
  after it (``sweep.candidates.ranking``) is not reported; the configuration as given is.
- A remedy found (verified by a full campaign) gets its tolerance yield: ``units`` delivered
  units drawn around it (``tolerance.yield_mc``); it meets the acceptance statement when the one-sided
  exact lower bound of the pass fraction is >= ``YIELD_TARGET`` at ``CONFIDENCE``; otherwise the
  section says how close it gets.
- When nothing passes, the binding requirement is explained physically (``remedies.binding_physics``),
  and the catalogue's unmodelled hardware is named.
"""

from __future__ import annotations

from compliance.sweep.remedies.binding_physics import explain_closest
from compliance.sweep.candidates.ranking import SETTINGS_COST, candidate_passes, rank_key
from compliance.sweep.remedies.smallest_change import describe_candidate
from compliance.sweep.candidates.runner import run_candidates
from compliance.requirements.verdict import Severity
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["CONFIDENCE", "YIELD_TARGET", "as_given", "finish", "remedy_configuration", "remedy_values", "tolerance_yield"]

YIELD_TARGET = 0.95
CONFIDENCE = 0.95
YIELD_SEED = 7


def remedy_values(rem: dict) -> dict | None:
    """Every parameter value the remedy sets (hardware and settings), SI; None when there is no remedy."""
    r = rem.get("remedy")
    if not r:
        return None
    return {**r.get("hardware_values", {}), **r["values"]}


def as_given(ctx, run_kw) -> dict:
    """Judge the configuration as given: ``{"status": RemedyStatus.ALREADY_PASSES | "fails", "row", "candidate", ...}``."""
    (row,), _ = run_candidates(ctx, [{}], **{**run_kw, "label": "as given"})
    out = {"status": RemedyStatus.ALREADY_PASSES if candidate_passes(row) else RemedyStatus.FAILS, "row": row,
           "candidate": describe_candidate((), {}, {}, row)}
    if out["status"] == RemedyStatus.ALREADY_PASSES:
        out.update(space=[], failed=[], sensitivities=[], out_of_reach=[], remedy=None, closest=out.pop("candidate"),
                   evaluated=1, note="every mandatory requirement passes as configured: nothing to change")
        out.pop("row")
    return out


def _never_worse(rem, given) -> None:
    """Report the configuration as given when the closest candidate ranks after it."""
    rem["evaluated"] += 1
    close = rem.get("closest")
    k_close = (len(close["failed_mandatory"]), close.get("total_shortfall", 0.0)) if close else (float("inf"),)
    if k_close > rank_key(given["row"], 0.0)[:2]:
        rem["closest"] = {**given["candidate"], "note": "no candidate judged ranks before the configuration as given"}


def tolerance_yield(rem, ctx, cfg, uncertain, run_kw, units) -> dict:
    """Run the tolerance yield of ``rem``'s remedy and put it in ``rem["tolerance_yield"]`` (returned too)."""
    _yield(rem, ctx, cfg, uncertain, run_kw, units)
    return rem["tolerance_yield"]


def _yield(rem, ctx, cfg, uncertain, run_kw, units):
    from compliance.sweep.tolerance.yield_mc import run_yield

    y, _, _, _ = run_yield(ctx, cfg, remedy_values(rem), uncertain, units=units, seed=YIELD_SEED, confidence=CONFIDENCE,
                           run_kw={**run_kw, "label": "tolerance yield"})
    a = y["all_mandatory"]
    rem["evaluated"] += units
    rem["tolerance_yield"] = {
        "units": units, "valid": y["valid"], "pass": a["pass"], "fraction": a["fraction"], "lower_bound": a["lower_bound"],
        "target": YIELD_TARGET, "confidence": CONFIDENCE, "meets": a["lower_bound"] >= YIELD_TARGET,
        "uncertain": y["uncertain"], "drivers": [{"path": d["path"], "rho": d["worst_margin"]} for d in y["drivers"][:3]],
        "worst_requirements": sorted(({"requirement": r["requirement"], "fraction": r["fraction"]} for r in y["requirements"]
                                      if r["severity"] == Severity.MANDATORY and r["fraction"] is not None),
                                     key=lambda r: r["fraction"])[:3],
    }


def _closest_configuration(cfg, ctx, closest):
    """``cfg`` with the closest candidate's hardware and settings: its binding physics is told with its own numbers."""
    from compliance.model.parameters import apply

    values = {**closest.get("hardware_values", {}), **closest.get("values", {})}
    known = [k for k in values if k in ctx.paths]
    return apply(cfg, [ctx.paths[k] for k in known], [values[k] for k in known])


def finish(rem, given, ctx, cfg, reqset, uncertain, catalogue, *, run_kw, yield_units) -> dict:
    """Complete the ``remedies`` section (see the module note); ``given`` is :func:`as_given`'s answer."""
    rem["as_given_failed"] = given["candidate"]["failed_mandatory"]
    if rem["status"] == RemedyStatus.NONE_FOUND:
        _never_worse(rem, given)
        c = rem["closest"]
        tried_limiter = any(s["path"].startswith("controller.setpoint_") for s in rem["space"])
        rem["explanation"] = explain_closest(c, _closest_configuration(cfg, ctx, c), reqset, tried_limiter)
        stages = ", ".join(s["stage"] + (f" ({' + '.join(s['options'])})" if s.get("options") else "") for s in rem.get("stages", []))
        hw = " with " + " + ".join(h["title"] for h in c["hardware"]) if c.get("hardware") else ""
        rem["note"] = (f"no candidate of the {rem['evaluated']} judged (stages: {stages}) passes every mandatory requirement; "
                       f"the closest{hw} fails {len(c['failed_mandatory'])} ({', '.join(c['failed_mandatory'])}) where the "
                       f"configuration as given fails {len(given['candidate']['failed_mandatory'])}. Why: {rem['explanation']} "
                       "This is the evidence of a search, not a proof that no pass exists.")
    elif rem["status"] == RemedyStatus.FOUND:
        r = rem["remedy"]
        r.setdefault("cost", SETTINGS_COST * r["change"])
        if yield_units and "tolerance_yield" not in rem:  # the governor stage yields its designs itself
            _yield(rem, ctx, cfg, uncertain, run_kw, yield_units)
    if catalogue is not None:
        rem["not_modelled"] = [{"option": n, "title": t, "reason": why} for n, t, why in catalogue.not_modelled]
        rem["not_applicable"] = [{"option": o.name, "title": o.title, "reason": o.applies_to(cfg)}
                                 for o in catalogue.options if o.applies_to(cfg)]
    return rem


def remedy_configuration(cfg, rem, paths):
    """The configuration with the remedy applied, named ``<name>-remedy`` (for ``--save-remedy``)."""
    from compliance.model.parameters import apply

    values = remedy_values(rem)
    changed = apply(cfg, [paths[p] for p in values], values.values())
    note = "remedies search of govcheck check --remedies: " + ", ".join(
        f"{c['path']} {c['from']:.4g} -> {c['to']:.4g}" for c in rem["remedy"]["changes"])
    hw = ", ".join(h["title"] for h in rem["remedy"].get("hardware", []))
    prov = {**cfg.provenance, "remedy": note + (f"; hardware: {hw}" if hw else "")}
    y = rem.get("tolerance_yield")
    if y:
        prov["remedy_yield"] = (f"tolerance yield {y['pass']} of {y['valid']} delivered units pass every mandatory requirement "
                                f"(one-sided {100 * y['confidence']:.0f} % lower bound {100 * y['lower_bound']:.1f} %: "
                                f"{'meets' if y['meets'] else 'does not show'} >= {100 * y['target']:.0f} %)")
    changed = changed.replace(name=f"{cfg.name}-remedy", provenance=prov)
    # the governor design's settings are made on site by measurement: the saved file says so ([commissioning])
    return changed.with_commissioning(rem["remedy"]["commissioning"]) if rem["remedy"].get("commissioning") else changed
