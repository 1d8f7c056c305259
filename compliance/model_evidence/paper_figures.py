"""The plant paper's measured figures beside the model's (``govcheck reproduce``), as model evidence.

Every row of :func:`compliance.papers.plant_a.compare` with a measured figure becomes one compared
figure: modelled, measured (a value with the paper's scatter, or a measured range), whether they
agree, and the govcheck metrics the figure is evidence for (``plant_a.BEARS_ON``). A figure a
parameter was derived to give (the stroke times at the set-up load, ``derived_for``) agrees by
construction and is no evidence; a configuration calibrated to the paper's figures agrees with them
by fitting, so they are not independent evidence either.
"""

from __future__ import annotations

from compliance.presentation.measured_figures import measured_text, value_text
from compliance.papers import plant_a

__all__ = ["PAPERS", "paper_source"]

# the papers govcheck holds a measured-results table for (docs/reference-plant.md)
PAPERS = {"plant-a": "the plant paper's measured results, section 5 (docs/reference-plant.md)"}
_SCALE = {"mm": 1e3}  # Row values are SI; these units are shown scaled


def _shown(v, unit: str):
    return None if v is None else v * _SCALE.get(unit, 1.0)


def _derived_metrics(cfg) -> set[str]:
    """Metrics some parameter of the plant file was derived to give (its agreement is by construction)."""
    return {a["derived_for"]["metric"] for a in cfg.assumptions.values() if a.get("derived_for")}


# figures of the paper's overall statement (section 6), never part of a calibration's objective (figure_rows)
_OVERALL = ("max tracking error", "max steady error")


def _figure(row, derived: set[str], fitted: bool) -> dict:
    bears = list(plant_a.BEARS_ON.get(row.metric, ()))
    kind, width = plant_a.TOLERANCES.get(row.metric, (None, None))
    return {
        "test": row.test, "metric": row.metric, "unit": row.unit,
        "modelled": _shown(row.simulated, row.unit), "measured": _shown(row.paper, row.unit),
        "measured_range": None if row.paper_range is None else [_shown(v, row.unit) for v in row.paper_range],
        "scatter": None if kind is None else {"kind": "relative" if kind == "rel" else "absolute",
                                              "width": width if kind == "rel" else _shown(width, row.unit)},
        "agreement": plant_a.agreement(row),
        "by_construction": bool(set(bears) & derived) and row.test == plant_a.STROKE_TEST,
        "independent": not (fitted and row.metric not in _OVERALL),
        "bears_on": bears, "note": row.note,
    }


def paper_source(cfg, name: str) -> dict:
    """The comparison with paper ``name``'s measured figures (keys as in docs/results-schema.md, ``model_evidence``)."""
    comp = plant_a.compare(cfg, explain=False)
    fitted = cfg.provenance.get("calibrated_to")
    figures = [_figure(r, _derived_metrics(cfg), bool(fitted)) for r in comp.rows]
    for f in figures:  # the texts a reader sees (the report reads them, it does not format them again)
        f["display"] = {"modelled": "-" if f["modelled"] is None else value_text(f["modelled"], f["unit"]),
                        "measured": "-" if f["measured"] is None and not f["measured_range"] else measured_text(f)}
    compared = [f for f in figures if f["agreement"] is not None and not f["by_construction"] and f["independent"]]
    return {
        "kind": "paper", "name": name, "title": PAPERS[name], "command": f"govcheck reproduce {cfg.path or cfg.name}",
        "independence": (f"the configuration was calibrated to the figures of figs. 9-12 and section 5.2 ({fitted}): "
                         "agreeing with those is what it was fitted to do, so only the paper's overall figures count "
                         "as evidence") if fitted else "the model was not fitted to these figures",
        "compared": len(compared), "agree": sum(1 for f in compared if f["agreement"] == "agrees"),
        "contradict": sum(1 for f in compared if f["agreement"] == "contradicts"),
        "by_construction": sum(1 for f in figures if f["by_construction"]),
        "figures": figures, "notes": list(comp.notes),
        "by_construction_note": "a parameter of the plant file was derived to give these figures (derived_for): they "
                                "agree by construction and count as no evidence",
    }
