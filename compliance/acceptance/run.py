"""``accept``: a site's commissioning recordings judged by a requirement file, beside the model's prediction.

    results = accept("site-p2", load_requirements("shpp-400kw"), load_plant("plant-a"))

reads the site (``site.folder``), makes each recording ready (``site.prepared``: the test as run,
stated or recognised, its instruments), measures every case with its uncertainty (``measure``),
judges every requirement on the measured cases (``judge.entries``), runs each test in simulation
under its recorded conditions and sets the predicted figure with its band beside the measured one
(``predict``), and with ``diagnose`` explains a disagreement with the joint diagnosis
(``acceptance.diagnosis``). The result is the site dict (``site_results``, docs/acceptance.md).
"""

from __future__ import annotations

import time

from compliance.acceptance.judge.entries import judge_requirement
from compliance.acceptance.measure.recording import measure_test
from compliance.acceptance.predict.agreement import attach_predictions
from compliance.acceptance.predict.site_prediction import predict_site
from compliance.acceptance.site.folder import read_site
from compliance.acceptance.site.prepared import prepare
from compliance.acceptance.site_results import site_results

__all__ = ["accept", "measure_site", "options_key", "step_options_of"]


def options_key(req) -> str:
    """The key of a requirement's step options among the measured case sets ("" for the defaults)."""
    opts = step_options_of(req)
    return repr(sorted(opts.items())) if opts else ""


def step_options_of(req) -> dict:
    """A requirement's step-metric options in SI (``final_window`` ...), or {}."""
    return {k: getattr(v, "value", v) for k, v in (req.options or {}).items()}


def _sine_settings(reqset) -> dict | None:
    sines = [p for p in reqset.procedures.values() if p.kind == "sine"]
    if not sines:
        return None
    s = sines[0].settings
    return {"skip_cycles": s.get("skip_cycles", 0.5), "cycles": s.get("cycles")}


def measure_site(prepared: list, cfg, reqset) -> dict:
    """Measured cases of every recording, per set of step options the requirements ask: options key -> [Case]."""
    sine = _sine_settings(reqset)
    base = [c for p in prepared for c in measure_test(p, cfg, sine=sine)]
    out = {"": base}
    for req in reqset.requirements:
        opts = step_options_of(req)
        key = options_key(req)
        if opts and key not in out:
            out[key] = [c for p in prepared for c in (measure_test(p, cfg, step_options=opts, sine=sine)
                                                      if p.test.kind == "step_series" else [])] + \
                       [c for c in base if c.kind != "steps"]
    return out


def accept(site, reqset, cfg, *, column_map=None, recordings=None, predict: bool = True, diagnose: bool | dict = False,
           workers=None, progress: bool = False, command_line: str | None = None) -> dict:
    """Judge a site's recordings by a requirement set (see the module docstring).

    Parameters
    ----------
    site : str or pathlib.Path
        A folder of recordings with their sidecars.
    reqset : RequirementSet
    cfg : PlantConfig
        The plant model the predictions run (by default the sidecars' plant, chosen by the caller).
    column_map : optional
        Column map of recordings in a logger's own names and units.
    recordings : list of SiteRecording, optional
        The site already read (``site.folder.read_site``); read here when not given.
    predict : bool
        Run each test in simulation and set the prediction beside each measured verdict.
    diagnose : bool or dict
        Explain a disagreement with the joint diagnosis of the site's closed-loop recordings (a dict: its
        options, ``effects`` and ``recalibrate``, as ``acceptance.diagnosis.diagnose_site`` takes them).
    workers : int, optional
        Worker processes of the predictions and the diagnosis.

    Returns
    -------
    dict
        The site results (schema ``govcheck-site/1``, ``site_results``).

    Raises
    ------
    InputError
        A bad site, recording or sidecar (before any figure is taken).
    """
    t0 = time.perf_counter()
    recordings = read_site(site, column_map) if recordings is None else recordings
    prepared = [prepare(r, cfg) for r in recordings]
    by_options = measure_site(prepared, cfg, reqset)
    keys = {req.id: options_key(req) for req in reqset.requirements}
    entries = [judge_requirement(req, reqset, by_options[keys[req.id]], cfg) for req in reqset.requirements]
    t_measure = time.perf_counter() - t0
    predicted = {}
    if predict:
        option_sets = {options_key(r): step_options_of(r) for r in reqset.requirements if step_options_of(r)}
        predicted = predict_site(cfg, prepared, sine=_sine_settings(reqset), option_sets=option_sets, workers=workers,
                                 progress=progress)
        attach_predictions(entries, by_options, predicted, keys.get)
    diagnosis = None
    if diagnose:
        from compliance.acceptance.diagnosis import diagnose_site

        options = diagnose if isinstance(diagnose, dict) else {}
        diagnosis = diagnose_site(cfg, prepared, by_options[""], entries, workers=workers, sine=_sine_settings(reqset), **options)
    timing = {"wall": time.perf_counter() - t0, "measure": t_measure, "recordings": len(prepared)}
    return site_results(site, prepared, by_options[""], entries, predicted, cfg, reqset, command_line=command_line,
                        diagnosis=diagnosis, timing=timing)
