"""Calibration output: before/after per figure, fitted values with ranges and pinning, the saved file."""

from __future__ import annotations

import dataclasses
import math
import os
from types import MappingProxyType

from compliance.model.config import PlantConfig, save_plant
from compliance.papers.calibration import Calibration
from compliance.papers.calibration_objective import cost, within
from compliance.papers.calibration_table import CALIBRATED_SOURCE, CONDITIONS
from compliance.papers.plant_a import TOLERANCES, scaled_miss

_SCALE = {"mm": 1e3}


def _fmt(v, unit: str) -> str:
    if v is None:
        return "-"
    return f"{v * _SCALE.get(unit, 1.0):.3g}"


def _scatter(metric: str, unit: str) -> str:
    kind, width = TOLERANCES[metric]
    return f"{width:.0%}" if kind == "rel" else f"{width * _SCALE.get(unit, 1.0):.2g} {unit}"


def _si(v: float, unit: str) -> str:
    return f"{v:.4g} {unit}".strip()


def calibration_table(cal: Calibration, columns: list[tuple[str, list]] | None = None) -> str:
    """Figures per stage (default: before/after), fitted values, pinning and test conditions, as text.

    ``columns``: (label, rows) per stage, e.g. published / parameters only / with the effect.
    """
    columns = columns or [("before", cal.rows_before), ("after", cal.rows_after)]
    lines = [
        "Calibration to seed 000 figures 9-12 and section 5.2 (only what the paper leaves unstated moves)",
        "  objective: sum over the paper's figures of (simulated - paper)^2 / scatter^2; "
        "scatter: settling 35 %, steady error 0.3 mm, stroke times 5 %, peak speed 30 %",
    ]
    for label, rows in columns:
        k, n = within(rows)
        lines.append(f"  {label:>12s}: cost {cost(rows):6.1f}, {k} of {n} figures within the scatter")
    head = "".join(f" {label[:10]:>10s}" for label, _ in columns)
    lines += ["", f"{'test':42s} {'metric':17s} {'paper':>7s}{head} {'scatter':>8s}  in"]
    for i, b in enumerate(columns[0][1]):
        if b.paper is None:
            continue
        last = columns[-1][1][i]
        r = scaled_miss(last)
        ok = "yes" if r is not None and abs(r) <= 1.0 else "NO"
        vals = "".join(f" {_fmt(rows[i].simulated, b.unit):>10s}" for _, rows in columns)
        lines.append(f"{b.test:42s} {b.metric:17s} {_fmt(b.paper, b.unit):>7s}{vals} {_scatter(b.metric, b.unit):>8s}  {ok}")
    lines += ["", "Fitted values (plausible range; the values the figures allow: local profile, cost within +1)"]
    prof = {p.path: p for p in cal.profiles}
    for u in cal.table:
        start = math.nan if u.effect and u.effect not in cal.start.effects else u.value_in(cal.start)
        got = cal.values[u.path]
        p = prof.get(u.path)
        pin = f"allowed {_si(p.allowed[0], '')}..{_si(p.allowed[1], u.unit)} ({p.verdict})" if p else ""
        start_txt = "off" if math.isnan(start) else _si(start, "")
        lines.append(f"  {u.path:44s} {start_txt:>10s} -> {_si(got, u.unit):16s} range "
                     f"{_si(u.low, '')}..{_si(u.high, u.unit)}; {pin}")
        if p:
            lines.append(f"  {'':44s} profile (cost above optimum at offsets -30,-10,-3,0,+3,+10,+30 % of range): {p.deltas()}")
        lines.append(f"  {'':44s} why open: {u.reason}")
    lines += ["", "Test conditions (chosen by the fit)"]
    for c in CONDITIONS:
        lines.append(f"  {c.name} = {cal.conditions[c.name]}  ({' | '.join(c.choices)}): {c.reason}")
    lines.append(f"\n{cal.evaluations} configurations evaluated on {cal.workers} process(es)")
    return "\n".join(lines)


def calibrated_config(cal: Calibration) -> PlantConfig:
    """The calibrated configuration with its provenance: parent, objective, test conditions."""
    prov = dict(cal.start.provenance)
    prov.update({
        "calibrated_from": f"{cal.start.name} (sha256 {cal.start.digest[:16] or 'in memory'})",
        "calibrated_to": "seed 000 figs. 9-12 settling times and steady errors, section 5.2 stroke times and peak speed",
        "calibration_objective": f"sum of (miss/scatter)^2: {cal.cost_before:.2f} before, {cal.cost_after:.2f} after",
        "calibration_command": "govcheck reproduce plant-a --calibrate",
    })
    for c in CONDITIONS:
        prov[f"condition_{c.name}"] = f"{cal.conditions[c.name]} (calibrated test condition: {c.reason})"
    for eff in cal.best.effects:
        if any(u.effect == eff for u in cal.table):
            prov[f"effect_{eff}"] = CALIBRATED_SOURCE
    name = cal.start.name if cal.start.name.endswith("-calibrated") else f"{cal.start.name}-calibrated"
    desc = (f"{cal.start.description} -- calibrated: the values seed 000 leaves unstated fitted to its reported "
            f"figures (docs/calibration.md)")
    return dataclasses.replace(cal.best, name=name, description=desc, provenance=MappingProxyType(prov))


def save_calibrated(cal: Calibration, path: str | os.PathLike) -> str:
    """Write the calibrated configuration (atomic; replaces an earlier calibration at ``path``)."""
    return str(save_plant(calibrated_config(cal), path, overwrite=True))
