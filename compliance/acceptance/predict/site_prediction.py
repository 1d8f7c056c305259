"""The model's prediction of every recorded test, with its band over the plant file's declared ranges.

Each test is replayed under its recorded conditions (``predict.replay_test``) with the nominal plant
and, one at a time, with every ranged parameter (``campaign.uncertainty.ranged_parameters``) at
each end of its range. The band of a predicted figure is the interval sum of those swings (each
parameter anywhere in its range, the worst combination; the same rule as ``check``'s local
bands):

    low = v0 + sum_k min(0, d_k+, d_k-)        high = v0 + sum_k max(0, d_k+, d_k-)

The replays run on the one executor (``processes.map_tasks``); a replay the model cannot run
(non-physical, or a recording the replay cannot use) leaves that test without a prediction and
says why.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from compliance.acceptance.predict.replay_test import predict_cases
from compliance.campaign.uncertainty import ranged_parameters
from compliance.errors import GovcheckError
from compliance.model.parameters import apply, param_handle
from compliance.processes import map_tasks

__all__ = ["Predicted", "predict_site", "TRACE_POINTS"]

TRACE_POINTS = 1500  # samples of a predicted trace kept for the report's figures


@dataclass
class Predicted:
    """The model's figures of one recorded test: per options key, per case, metric -> (value, low, high) [SI]."""

    recording: str
    figures: dict = field(default_factory=dict)
    trace: dict | None = None
    error: str | None = None

    def figure(self, options_key: str, index: int, metric: str):
        """(value, low, high) of a case's metric, or None."""
        cases = self.figures.get(options_key) or self.figures.get("")
        if cases is None or index >= len(cases):
            return None
        return cases[index].get(metric)


def _values(cases) -> list:
    return [{k: m.value for k, m in c.values.items() if m.value is not None} for c in cases]


def _task(context, item):
    """Worker: one test with one plant variant -> {options key: [metric -> value per case]}, trace, error."""
    cfg, prepared, sine, option_sets = context
    index, variant = item
    moved = cfg if variant is None else apply(cfg, [param_handle(variant[0], "prediction band")], [variant[1]])
    out, trace = {}, None
    try:
        for key, opts in option_sets.items():
            if key and prepared[index].test.kind != "step_series":
                continue
            cases, frame = predict_cases(moved, prepared[index], sine=sine, step_options=opts or None,
                                         keep_trace=variant is None and key == "")
            out[key] = _values(cases)
            if frame is not None:
                step = max(1, len(frame) // TRACE_POINTS)
                trace = {c: frame[c].to_numpy()[::step].tolist() for c in frame.columns}
    except GovcheckError as exc:
        return index, variant, None, None, str(exc)
    return index, variant, out, trace, None


def _band(nominal: list, variants: dict) -> list:
    """Per case, metric -> (value, low, high) from the nominal values and each parameter's two ends."""
    out = []
    for i, nom in enumerate(nominal):
        figs = {}
        for metric, v0 in nom.items():
            lo = hi = v0
            for ends in variants.values():
                d = [e[i][metric] - v0 for e in ends if e is not None and i < len(e) and metric in e[i]]
                if d:
                    lo += min(0.0, *d)
                    hi += max(0.0, *d)
            figs[metric] = (v0, max(lo, 0.0) if v0 >= 0.0 else lo, hi)  # every metric of the catalogue is a magnitude
        out.append(figs)
    return out


def predict_site(cfg, prepared: list, *, sine=None, option_sets: dict | None = None, workers=None, progress=False,
                 extra_ranges: list | None = None) -> dict:
    """Predicted figures with bands of every prepared recording: name -> :class:`Predicted`.

    Parameters
    ----------
    cfg : PlantConfig
    prepared : list of PreparedTest
        Recordings that cannot be judged as run are not predicted.
    sine : dict, optional
        The requirement file's sine settings (``skip_cycles``, ``cycles``).
    option_sets : dict, optional
        Options key -> step options (SI) the requirements ask besides the defaults.
    extra_ranges : list, optional
        (parameter path, {"low": SI, "high": SI}) moved like the declared ranges (a fitted value's own interval).
    """
    from compliance.campaign.executor import warm_up

    option_sets = {"": {}, **(option_sets or {})}
    ranged = ranged_parameters(cfg) + list(extra_ranges or [])
    variants = [None] + [(k, rng[end]) for k, rng in ranged for end in ("low", "high")]
    usable = [i for i, p in enumerate(prepared) if not p.problem]
    items = [(i, v) for i in usable for v in variants]
    warm_up(cfg)  # the compiled core loaded once, before the workers fork
    results, _ = map_tasks(_task, (cfg, prepared, sine, option_sets), items, workers=workers, progress=progress,
                           label="predictions", retries=0)
    raw: dict = {}
    for res in results:
        if res is None:
            continue
        index, variant, values, trace, error = res
        raw.setdefault(index, {})[variant] = (values, trace, error)
    out = {}
    for i in usable:
        runs = raw.get(i, {})
        nominal = runs.get(None)
        pred = Predicted(prepared[i].name)
        if nominal is None or nominal[2] is not None:
            pred.error = nominal[2] if nominal else "the replay did not run"
        else:
            pred.trace = nominal[1]
            for key in nominal[0]:
                ends = {k: [runs.get((k, rng[e]), (None,))[0] for e in ("low", "high")] for k, rng in ranged}
                ends = {k: [None if v is None else v.get(key) for v in vs] for k, vs in ends.items()}
                pred.figures[key] = _band(nominal[0][key], ends)
        out[prepared[i].name] = pred
    return out
