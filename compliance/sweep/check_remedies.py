"""``govcheck check --remedies``: the remedies search over a declared space for one configuration.

For a governor with a set-point rate limiter and the default space, the governor design comes first
(``remedies.governor_stage``: the set-point rate limiter for the stroke times, the flow-control valves as
its backstop, the time constant tuned on the file's own test, with the hardware as given and then with
each catalogue option that lowers the load's share of the cylinders' force). When it finds nothing, the
staged local search runs over a declared space: a sweep file's ``adjust`` table when one is named, else the
settings that can be changed on site without new hardware, around the configuration's own values (its plant
kind's ``remedy_space``, compliance.plants):
controller gains and dead-zone compensation, the meter-out flow-control valves, the supply
pressure regulator; for a PID governor also its set-point rate limiter (``remedies.limiter_space``).
Then the options of a hardware catalogue (``sweep.sizing.hardware_catalogue``; the shipped one by default).
A remedy found is verified by a full campaign and its tolerance yield (DEFAULT_TOLERANCES:
manufacturing and site tolerances of a delivered unit, our choice, the same as
models/sweeps/plant-a-remedies.toml); when none is found the binding requirement is explained
physically (``remedies.binding_physics``).
"""

from __future__ import annotations

from compliance.plants import kind_of
from compliance.sweep.candidates.evaluate import make_context
from compliance.model.parameters import param_handle
from compliance.sweep.candidates.spec import Adjustable, Uncertain
from compliance.sweep.tolerance.yield_mc import nominal_values
from compliance.sweep.remedies.outcome import RemedyStatus

__all__ = ["DEFAULT_TOLERANCES", "YIELD_UNITS", "default_space", "remedies_for_check"]

# path -> (distribution, spread): relative spreads of a delivered unit around its nominal values
DEFAULT_TOLERANCES = {
    "friction.static_force": ("uniform", 0.20),
    "friction.viscous_coefficient": ("uniform", 0.30),
    "valve.sonic_conductance": ("normal", 0.05),
    "air.supply_pressure": ("normal", 0.02),  # 0.16 bar of 8 bar abs: a regulator's repeatability
}
YIELD_UNITS = 59  # 59 of 59 passing is the fewest that shows >= 95 % yield at 95 % confidence (success-run rule)


def default_space(cfg) -> tuple[Adjustable, ...]:
    """The on-site settings of ``cfg`` with ranges around their values (zero-valued ones left out)."""
    out = []
    for path, (f_lo, f_hi, floor) in kind_of(cfg).remedy_space.items():
        pp = param_handle(path, "default remedies space")
        v = float(cfg.params[path])
        lo, hi = max(pp.low, f_lo * v), min(pp.high, max(f_hi * v, floor))
        if path == "air.supply_pressure":
            lo = max(lo, 1.5 * cfg.params["air.atmospheric_pressure"])
        if hi > lo:
            out.append(Adjustable(pp, lo, hi, None, 3))
    return tuple(out)


def _space(cfg, reqset, sweep_file):
    """(adjustables, start values, uncertain parameters) of the search."""
    from compliance.sweep.remedies.limiter_space import limiter_space

    uncertain = tuple(Uncertain(param_handle(p, "remedies tolerances"), d, s, True, None) for p, (d, s) in DEFAULT_TOLERANCES.items())
    if sweep_file and sweep_file != "default":
        from compliance.sweep.candidates.spec import load_sweep

        spec = load_sweep(sweep_file)
        adjust, uncertain = spec.adjust, spec.uncertain or uncertain
    else:
        adjust = default_space(cfg)
    base = nominal_values(cfg, {a.param.path: a.param for a in adjust})
    limiter = None  # a sweep file's space is as declared; the default space adds the limiter to a loop that has one
    if kind_of(cfg).setpoint_limiter and not cfg.setpoint_rate_limited and not (sweep_file and sweep_file != "default"):
        lim, start = limiter_space(cfg, reqset)
        adjust = tuple(a for a in adjust if a.param.path not in start)
        limiter = (lim, start)
    return adjust, base, uncertain, limiter


def remedies_for_check(cfg, reqset, sweep_file: str | None, *, workers=None, progress=True, iterations=1,
                       linear=False, client=None, scheduler=None, catalogue="default", yield_units=YIELD_UNITS,
                       store=None) -> dict:
    """The ``remedies`` section for ``cfg`` against ``reqset`` (docs/results-schema.md).

    Parameters
    ----------
    catalogue : str or None
        Hardware catalogue file, ``"default"`` (shipped) or None (settings only).
    yield_units : int
        Units of the tolerance yield of a remedy found (0: no yield run).
    store : str or None
        Folder keeping every judged candidate, so an interrupted search resumes (``candidates.candidate_store``).
    """
    from compliance.processes import dask_session
    from compliance.sweep.sizing.hardware_catalogue import load_catalogue
    from compliance.sweep.remedies.finish import as_given, finish
    from compliance.sweep.remedies.staged_search import staged_search
    from compliance.sweep.run import verify_settings

    if isinstance(store, str):
        from compliance.sweep.candidates.candidate_store import CandidateStore

        store = CandidateStore(store)
    cat = load_catalogue(catalogue) if catalogue else None
    adjust, base, uncertain, limiter = _space(cfg, reqset, sweep_file)
    paths = {a.param.path: a.param for a in adjust + (limiter[0] if limiter else ())}
    paths.update({u.param.path: u.param for u in uncertain})
    for o in (cat.options if cat else ()):
        paths.update({p: param_handle(p, o.where) for p in o.values(cfg)} if o.applies_to(cfg) is None else {})
    ctx = make_context(cfg, reqset, paths, linear)
    with dask_session(scheduler, client) as session:
        run_kw = {"workers": workers, "progress": progress, "client": session, "scheduler": scheduler, "store": store}
        given = as_given(ctx, run_kw)
        if given["status"] == RemedyStatus.ALREADY_PASSES:
            return given
        gov = None
        if kind_of(cfg).setpoint_limiter and not (sweep_file and sweep_file != "default"):
            from compliance.sweep.remedies.governor_stage import governor_stage

            gov = governor_stage(ctx, cfg, reqset, cat, workers=workers, uncertain=uncertain, run_kw=run_kw,
                                 yield_units=yield_units)
        if gov is not None and gov["status"] == RemedyStatus.FOUND:
            rem = gov
        else:
            rem = staged_search(ctx, cfg, adjust, base, cat, iterations=iterations, run_kw=run_kw, limiter=limiter,
                                verify=lambda v: verify_settings(cfg, reqset, paths, v, workers=workers))
            if gov is not None:
                rem["governor_design"] = {k: gov[k] for k in ("stages", "skipped_options", "note")}
                rem["stages"] = gov["stages"] + rem.get("stages", [])
                rem["evaluated"] += gov["evaluated"]
        rem = finish(rem, given, ctx, cfg, reqset, uncertain, cat, run_kw=run_kw, yield_units=yield_units)
    rem["space_source"] = sweep_file if sweep_file and sweep_file != "default" else "default on-site settings"
    rem["catalogue"] = cat.path if cat else None
    return rem
