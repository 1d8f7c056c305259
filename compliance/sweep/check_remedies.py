"""``govcheck check --remedies``: the remedies search over a declared space for one configuration.

The space is a sweep file's ``adjust`` table when one is named, else the settings that can be
changed on site without new hardware, around the configuration's own values (DEFAULT_SPACE):
controller gains and dead-zone compensation, the meter-out flow-control valves, the supply
pressure regulator. Hardware (cylinder, valve size) is left to a sweep file that declares it.
"""

from __future__ import annotations

from compliance.sweep.evaluate import make_context
from compliance.sweep.parameter_paths import describe
from compliance.sweep.remedies import find_remedy
from compliance.sweep.spec import Adjustable
from compliance.sweep.yield_mc import nominal_values

__all__ = ["DEFAULT_SPACE", "default_space", "remedies_for_check"]

# path -> (low factor, high factor, absolute floor of the high end [SI]) around the configured value;
# factors are commissioning ranges (gains x0.5-x3, throttles x0.6-x1.5, regulator -20 %/+15 %)
DEFAULT_SPACE = {
    "pid": {
        "controller.kp": (0.5, 3.0, 0.0),
        "controller.ki": (0.0, 10.0, 50.0),
        "controller.kd": (0.0, 2.0, 10.0),
        "controller.compensation_width": (0.0, 2.0, 0.8),
        "controller.compensation_dead_zone_positive": (0.7, 1.3, 0.0),
        "controller.compensation_dead_zone_negative": (0.7, 1.3, 0.0),
        "flow_control.opening_conductance": (0.6, 1.5, 0.0),
        "flow_control.closing_conductance": (0.6, 1.5, 0.0),
        "air.supply_pressure": (0.8, 1.15, 0.0),
    },
    "state_feedback": {
        "controller.closed_loop_bandwidth": (0.5, 2.0, 0.0),
        "controller.acceleration_observer_bandwidth": (0.5, 2.0, 0.0),
        "controller.friction_observer_bandwidth": (0.5, 2.0, 0.0),
        "air.supply_pressure": (0.8, 1.15, 0.0),
    },
}


def default_space(cfg) -> tuple[Adjustable, ...]:
    """The on-site settings of ``cfg`` with ranges around their values (zero-valued ones left out)."""
    out = []
    for path, (f_lo, f_hi, floor) in DEFAULT_SPACE[cfg.options["controller.type"]].items():
        pp = describe(path, "default remedies space")
        v = float(cfg.params[path])
        lo, hi = max(pp.low, f_lo * v), min(pp.high, max(f_hi * v, floor))
        if path == "air.supply_pressure":
            lo = max(lo, 1.5 * cfg.params["air.atmospheric_pressure"])
        if hi > lo:
            out.append(Adjustable(pp, lo, hi, None, 3))
    return tuple(out)


def remedies_for_check(cfg, reqset, sweep_file: str | None, *, workers=None, progress=True, iterations=4,
                       linear=False, client=None, scheduler=None) -> dict:
    """The ``remedies`` section for ``cfg`` against ``reqset`` (docs/results-schema.md)."""
    from compliance.sweep.run import verify_settings

    if sweep_file and sweep_file != "default":
        from compliance.sweep.spec import load_sweep

        adjust = load_sweep(sweep_file).adjust
    else:
        adjust = default_space(cfg)
    paths = {a.param.path: a.param for a in adjust}
    ctx = make_context(cfg, reqset, paths, linear)
    base = nominal_values(cfg, paths)
    from compliance.campaign.executor import dask_session

    with dask_session(scheduler, client) as session:
        run_kw = {"workers": workers, "progress": progress, "client": session, "scheduler": scheduler}
        rem = find_remedy(ctx, adjust, base, iterations=iterations,
                          verify=lambda v: verify_settings(cfg, reqset, paths, v, workers=workers), run_kw=run_kw)
    rem["space_source"] = sweep_file if sweep_file and sweep_file != "default" else "default on-site settings"
    return rem
