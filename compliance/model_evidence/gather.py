"""The model's evidence beside its verdicts: is the model validated, and which verdicts rest on figures
the measurements contradict (results key ``model_evidence``, docs/results-schema.md).

The sources are the ones the plant file names in ``[model_evidence]``: the plant paper's measured
figures (:mod:`compliance.model_evidence.paper_figures`) and recordings of the servo
(:mod:`compliance.model_evidence.recording_fits`). The model is **validated** when at least one
independent measured figure was compared and every one agrees; **contradicted** when one does not;
**not validated** when nothing independent was compared (no source, or only figures the model was
fitted or derived to give). A verdict rests on a contradicted figure when its metric is one the
figure is evidence for; the direction of the miss says whether the model errs towards or away
from the limit.
"""

from __future__ import annotations

from compliance.errors import InputError
from compliance.model_evidence.paper_figures import PAPERS, paper_source
from compliance.model_evidence.recording_fits import recording_source
from compliance.requirements.verdict import Status
from compliance.results.evidence import ModelEvidence
from compliance.presentation.measured_figures import direction as _direction, figure_text, miss as _miss

__all__ = ["check_sources", "contradicted_verdicts", "model_evidence"]


def check_sources(cfg) -> None:
    """Refuse a ``[model_evidence]`` table govcheck cannot compare before any work (exit 2)."""
    paper = (cfg.model_evidence or {}).get("paper")
    where = cfg.path or cfg.name
    if paper and paper not in PAPERS:
        raise InputError(f"{where}: model_evidence.paper = '{paper}': govcheck holds the measured results of "
                         f"{', '.join(PAPERS)} only (docs/reference-plant.md)")
    if paper == "plant-a" and cfg.options.get("cylinder.arrangement") != "tandem":
        raise InputError(f"{where}: model_evidence.paper = 'plant-a': the paper's tests are of the tandem gate servo "
                         "(cylinder.arrangement = 'tandem')")


def _contradicting(sources: list[dict]) -> list[tuple[dict, dict]]:
    """(source, figure) of every independent figure that contradicts the model; a recording is one figure."""
    out = []
    for s in sources:
        if s["kind"] == "paper":
            out += [(s, f) for f in s["figures"]
                    if f["agreement"] == "contradicts" and f["independent"] and not f["by_construction"]]
        elif s["agreement"] == "contradicts":
            out.append((s, {"metric": "recorded position", "bears_on": s["bears_on"], "recording": s["path"]}))
    return out


_CONSEQUENCE = {  # (comparator family, where the model lies) -> what that means for the verdict
    ("upper", "above"): "the model errs towards the limit: the measured servo did better, so the verdict is pessimistic",
    ("upper", "below"): "the model errs away from the limit: the measured servo did worse, so the verdict is optimistic",
    ("lower", "above"): "the model errs away from the limit: the verdict is optimistic",
    ("lower", "below"): "the model errs towards the limit: the verdict is pessimistic",
}


def _consequence(comparator: str, directions: set) -> str:
    family = "upper" if comparator in ("<=", "<") else "lower" if comparator in (">=", ">") else "band"
    if len(directions) == 1 and family != "band":
        return _CONSEQUENCE[(family, next(iter(directions)))]
    if len(directions) > 1:
        return "the measurements differ from the model in both directions: the verdict may move either way"
    return "the measured figure differs from the modelled one: the verdict may move either way"


def contradicted_verdicts(verdicts, sources: list[dict]) -> list[dict]:
    """Every judged requirement whose metric a contradicting figure is evidence for, with those figures.

    ``verdicts``: the result's ``RequirementVerdict`` records.
    """
    bad = _contradicting(sources)
    out = []
    for e in verdicts:
        if e.status in (Status.DISABLED,):
            continue
        hits = [(s, f) for s, f in bad if e.metric in f.get("bears_on", ())]
        if not hits:
            continue
        figs = [f for _, f in hits if "test" in f]
        recs = sorted({f["recording"] for _, f in hits if "recording" in f})
        kinds = sorted({f["metric"] for f in figs})
        worst = max(figs, key=_miss) if figs else None
        dirs = {d for d in (_direction(f) for f in figs) if d}
        n = sum(1 for s in sources if s["kind"] == "paper" for f in s["figures"] if e.metric in f["bears_on"]
                and f["agreement"] is not None and f["independent"] and not f["by_construction"])
        parts = [f"{len(figs)} of {n} measured figures of the paper ({', '.join(kinds)}) disagree, e.g. "
                 f"{figure_text(worst)}"] if figs else []
        parts += [f"the recording {r} (position windows outside their limits)" for r in recs]
        out.append({"requirement": e.id, "title": e.title, "severity": e.severity, "status": e.status,
                    "metric": e.metric, "figures": [figure_text(f) for f in figs], "recordings": recs,
                    "example": figure_text(worst, test=False) if worst else f"the recording {recs[0]}",
                    "direction": sorted(dirs), "consequence": _consequence(e.comparator or "", dirs),
                    "text": "; ".join(parts)})
    return out


def _status(sources: list[dict]) -> tuple[str, int, int]:
    """(status, independent figures compared, contradicting) over every source."""
    compared = contradict = 0
    for s in sources:
        if s["kind"] == "paper":
            compared += s["compared"]
            contradict += s["contradict"]
        else:
            compared += 1
            contradict += s["agreement"] == "contradicts"
    if contradict:
        return "contradicted", compared, contradict
    return ("validated" if compared else "not validated"), compared, contradict


def _examples(sources: list[dict]) -> list[str]:
    """The largest miss of each kind of contradicted figure, short: ``steady error 0.905 mm modelled, 0.240 mm measured``."""
    worst: dict = {}
    for _, f in _contradicting(sources):
        if "test" in f and (f["metric"] not in worst or _miss(f) > _miss(worst[f["metric"]])):
            worst[f["metric"]] = f
    return [figure_text(f, test=False) for f in sorted(worst.values(), key=_miss, reverse=True)]


def _summary(status: str, sources: list[dict], compared: int, contradict: int) -> str:
    if not sources:
        return "not validated: the plant file names no measurement of this servo ([model_evidence])"
    if status == "not validated":
        return "not validated: no independent measured figure was compared (the ones compared were fitted or derived)"
    if status == "validated":
        return f"validated: all {compared} independent measured figures agree with the model"
    examples = []
    for s, f in _contradicting(sources):
        if "test" in f and f["metric"] not in [e[0] for e in examples]:
            same = [g for t, g in _contradicting(sources) if "test" in g and g["metric"] == f["metric"]]
            examples.append((f["metric"], figure_text(max(same, key=_miss))))
    recs = [s["path"] for s in sources if s["kind"] == "recording" and s["agreement"] == "contradicts"]
    text = f"contradicted: {contradict} of {compared} independent measured figures disagree with the model"
    if examples:
        text += " (" + "; ".join(t for _, t in examples) + ")"
    if recs:
        text += "; recordings outside their validation limits: " + ", ".join(recs)
    return text


def model_evidence(cfg, result) -> ModelEvidence:
    """The ``model_evidence`` section of a check's result (docs/results-schema.md).

    Parameters
    ----------
    cfg : PlantConfig
        Its ``[model_evidence]`` table names the sources.
    result : CheckResult
        The check's verdicts (their final statuses: after the bands).

    Returns
    -------
    ModelEvidence
    """
    check_sources(cfg)
    declared = cfg.model_evidence or {}
    sources = []
    if declared.get("paper"):
        sources.append(paper_source(cfg, declared["paper"]))
    for entry in declared.get("recordings") or ():
        sources.append(recording_source(cfg, entry))
    status, compared, contradict = _status(sources)
    return ModelEvidence.from_dict({
        "status": status, "validated": status == "validated", "compared": compared, "contradict": contradict,
        "summary": _summary(status, sources, compared, contradict), "examples": _examples(sources), "sources": sources,
        "contradicted": contradicted_verdicts(result.requirements, sources)}, "results.model_evidence")
