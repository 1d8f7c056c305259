"""The staged remedies search: settings (and the governor's rate limiter), then catalogue hardware.

Stages, cheapest first (costs: ``sweep.candidates.ranking``; a hardware option costs its catalogue weight):

1. The on-site settings: :func:`~compliance.sweep.remedies.smallest_change.find_remedy`.
2. For a PID governor without one, the same settings plus its set-point rate limiter, from the
   closest settings of stage 1 and the limiter start a commissioning engineer would set
   (``remedies.limiter_space``).
3. Each catalogue option that applies, alone, at the best settings of stage 1 (one candidate
   each), ranked; the best-ranked option gets its own settings search; then the best two
   options of different groups together.

Every candidate is ranked lexicographically (failing mandatory requirements, total shortfall,
cost) together with the configuration as given, so the closest reported never fails more
mandatory requirements than the configuration does. The first verified pass in stage order is
the remedy (a cheaper stage's pass is never passed over for hardware).
"""

from __future__ import annotations

from compliance.requirements.verdict import Overall
from compliance.sweep.remedies.limiter_space import limiter_stage_start
from compliance.sweep.candidates.ranking import SETTINGS_COST, candidate_passes, failing_mandatory, rank_key
from compliance.sweep.remedies.smallest_change import find_remedy
from compliance.sweep.candidates.runner import run_candidates
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["staged_search"]


def _stage(ctx, adjust, base, verify, run_kw, iterations, fixed=None, cost=0.0, label="", given=None):
    adjust = tuple(a for a in adjust if a.param.path not in (fixed or {}))  # the hardware sets these
    rem = find_remedy(ctx, adjust, base, verify=verify, iterations=iterations, run_kw={**run_kw, "label": label},
                      fixed=fixed, cost=cost)
    _report_from(rem, adjust, given or base)
    rem["hardware_cost"] = cost
    if rem["status"] == RemedyStatus.ALREADY_PASSES and fixed:  # the hardware alone, at these settings, passes: verify it
        results = verify({**fixed, **rem["closest"]["values"]})
        if results.passed:
            remedy = {**rem["closest"], "verified": {"status": Overall.PASS, "failed_mandatory": []}}
            rem.update(status=RemedyStatus.FOUND, remedy=remedy, closest=None,
                       note=f"verified by a full campaign of the changed configuration ({len(results.runs)} runs)")
        else:
            rem["status"] = RemedyStatus.NONE_FOUND
    return rem


def _report_from(rem, adjust, given) -> None:
    """Measure the reported changes of the stage's remedy or closest candidate from the configuration as given."""
    for key in ("remedy", "closest"):
        pick = rem.get(key)
        if pick:
            pick["changes"] = [{"path": a.param.path, "unit": a.param.unit, "from": float(given.get(a.param.path, 0.0)),
                                "to": float(pick["values"][a.param.path])} for a in adjust
                               if a.param.path in pick["values"]
                               and abs(pick["values"][a.param.path] - given.get(a.param.path, 0.0)) > 1e-6 * a.span]


def _option_rows(ctx, cfg, options, settings, run_kw):
    """Judge each option alone at ``settings`` -> [(option, values, row)], ranked."""
    cands = [{**settings, **o.values(cfg)} for o in options]
    rows, _ = run_candidates(ctx, cands, **{**run_kw, "label": "hardware options"})
    ranked = sorted(zip(options, cands, rows), key=lambda t: rank_key(t[2], t[0].cost))
    return ranked


def staged_search(ctx, cfg, adjust, base, catalogue, *, verify, run_kw, iterations=1, limiter=None) -> dict:
    """Run the stages; returns the ``remedies`` section with ``stages`` and the hardware tried.

    Parameters
    ----------
    ctx : compliance.sweep.candidates.evaluate.Context
        Its ``paths`` cover the settings, the limiter and every catalogue option's parameters.
    adjust, base : tuple of Adjustable, dict
        The settings space and the configuration's values.
    catalogue : compliance.sweep.sizing.hardware_catalogue.Catalogue or None
    verify : callable
        values dict -> results of a full campaign.
    limiter : tuple or None
        (limiter adjustables, limiter start) for a PID governor without a rate limiter.
    """
    rem = _stage(ctx, adjust, base, verify, run_kw, iterations, label="remedies: settings")
    rem["stages"] = [{"stage": "settings", "status": rem["status"], "evaluated": rem["evaluated"]}]
    rem["hardware_tried"] = []
    adjust_all = tuple(adjust)
    if rem["status"] == RemedyStatus.NONE_FOUND and limiter is not None:
        lim_adjust, lim_start = limiter
        start = limiter_stage_start(adjust, (rem["closest"] or {}).get("values") or base, lim_start)
        rl = _stage(ctx, tuple(adjust) + tuple(lim_adjust), start, verify, run_kw, iterations,
                    label="remedies: settings + rate limiter", given=base)
        rl["stages"] = rem["stages"] + [{"stage": "settings + rate limiter", "status": rl["status"],
                                         "evaluated": rl["evaluated"]}]
        rl["evaluated"] += rem["evaluated"]
        rl["hardware_tried"] = []
        if rl["status"] == RemedyStatus.FOUND or _better(rl.get("closest"), rem.get("closest"), 0.0):
            rl["settings_only"] = {k: rem[k] for k in ("closest", "sensitivities", "out_of_reach")}
            rem, adjust_all = rl, tuple(adjust) + tuple(lim_adjust)
        else:
            rem["stages"], rem["evaluated"] = rl["stages"], rl["evaluated"]
    if rem["status"] != RemedyStatus.NONE_FOUND or catalogue is None:
        return rem
    best_settings = {a.param.path: (rem["closest"] or {}).get("values", base).get(a.param.path, base.get(a.param.path))
                     for a in adjust_all}
    options = [o for o in catalogue.options if o.applies_to(cfg) is None]
    ranked = _option_rows(ctx, cfg, options, best_settings, run_kw)
    rem["evaluated"] += len(ranked)
    rem["hardware_tried"] = [{"option": o.name, "group": o.group, "title": o.title, "cost": o.cost,
                              "status": Overall.PASS if candidate_passes(row) else row["status"],
                              "failed_mandatory": failing_mandatory(row)} for o, _, row in ranked]
    tries = [[ranked[0][0]]] if ranked else []
    pair = [t[0] for t in ranked if t[0].group != ranked[0][0].group][:1] if ranked else []
    if pair:
        tries.append([ranked[0][0], pair[0]])
    for opts in tries:
        fixed = {k: v for o in opts for k, v in o.values(cfg).items()}
        cost = sum(o.cost for o in opts)
        hw = _stage(ctx, adjust_all, best_settings, verify, run_kw, max(1, iterations - 1), fixed=fixed, cost=cost,
                    label="remedies: " + " + ".join(o.name for o in opts), given=base)
        rem["evaluated"] += hw["evaluated"]
        rem["stages"].append({"stage": "hardware", "options": [o.name for o in opts], "status": hw["status"],
                              "evaluated": hw["evaluated"]})
        pick = hw.get("remedy") or hw.get("closest")
        if pick is not None:
            pick["hardware"] = [{"option": o.name, "group": o.group, "title": o.title, "cost": o.cost} for o in opts]
            pick["hardware_values"] = fixed
            pick["cost"] = cost + SETTINGS_COST * pick["change"]
        if hw["status"] == RemedyStatus.FOUND:
            hw["remedy"].update(hardware=pick["hardware"], hardware_values=fixed, cost=pick["cost"])
            rem.update(status=RemedyStatus.FOUND, remedy=hw["remedy"], closest=None,
                       note=hw["note"] + "; hardware: " + ", ".join(o.title for o in opts))
            return rem
        if _better(pick, rem.get("closest"), cost):
            rem["closest"] = pick
    return rem


def _better(a, b, cost_a) -> bool:
    """Closest candidate ``a`` ranks before ``b`` (fewer failing, then smaller total shortfall)."""
    if a is None:
        return False
    if b is None:
        return True
    ka = (len(a["failed_mandatory"]), a.get("total_shortfall", 0.0), cost_a)
    kb = (len(b["failed_mandatory"]), b.get("total_shortfall", 0.0), b.get("cost", 0.0))
    return ka < kb
