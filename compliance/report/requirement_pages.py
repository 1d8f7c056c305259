"""One page per requirement (or group of requirements judged on the same runs): the evidence that decides it.

Each page carries what the requirement rests on, the worst case's plot with the limit drawn,
and the table of all cases, with similar cases grouped (same procedure, same value and
status at several operating points -> one row). Steps whose tolerance is at least the step
cannot fail by construction and are marked so; the fraction of each commanded step the
servo actually covered is given, and excluded samples say why they were left out.
"""

from __future__ import annotations

import re

from compliance.metrics import METRICS
from compliance.presentation.values import limit_as_written, metric_text, row_texts, verdict_texts
from compliance.requirements.verdict import Status
from compliance.presentation.numbers import fmt_value

TOLERANCE_METRICS = ("max_positioning_error", "tracking_max_error", "steady_state_error")
SPEED_METRICS = ("max_speed", "max_opening_speed", "max_closing_speed")
STEP_TOLERANCE_METRICS = ("max_positioning_error", "steady_state_error")


_PAPER_WORDS = (("seed 000", "plant-A paper"), ("seed 001", "plant-B paper"), ("seed section", "plant-A paper section"),
                ("seed paper", "source paper"), ("the seed", "the source paper"))
_DOC_REF_RE = re.compile(r"\s*\((?:see )?[^()]*\b[\w./-]+\.(?:md|py|toml)\b[^()]*\)")  # "(reference-plant.md, 'Known tension')"
_MODULE_REF_RE = re.compile(r"\bcompliance\.(\w+)(?:\.\w+)*")
_PAPER_SECTION_RE = re.compile(r"(paper section [\d.]+, [^;)]*?)\bin section (\d[\d.]*)")


def reader_text(text) -> str:
    """Text from our declarations for a reader: internal names of the source papers in words, no file or module names.

    A parenthesis that points at one of our documentation files is dropped (the report cannot
    send its reader to the code base); a module named in a note becomes the stage it belongs to.
    """
    text = "" if text is None else str(text)
    for a, b in _PAPER_WORDS:
        text = text.replace(a, b)
    text = _DOC_REF_RE.sub("", text)
    text = _PAPER_SECTION_RE.sub(r"\1in the paper's section \2", text)  # never read as a section of this report
    return _MODULE_REF_RE.sub(lambda m: f"govcheck's {m.group(1).replace('_', ' ')} analysis", text)


def _step_facts(sample, limit_si, metric: str) -> dict:
    """Coverage of a step (fraction of the commanded step moved) and whether it can fail at all."""
    d = sample.detail
    size, x0, x1 = d.get("size"), d.get("x_start"), d.get("x_final")
    out = {}
    if isinstance(size, (int, float)) and size and isinstance(x0, (int, float)) and isinstance(x1, (int, float)):
        out["covered"] = max(0.0, (x1 - x0) / size)
    if metric in STEP_TOLERANCE_METRICS and isinstance(size, (int, float)) and limit_si:
        out["cannot_fail"] = max(limit_si) >= abs(size) * (1 - 1e-9)
    return out


def _row_cells(e, r) -> dict:
    """A case row: value, margin, status, the per-step details (coverage, exclusions)."""
    metric = e.metric
    steps, cannot = [], []
    for s in r.samples:
        facts = _step_facts(s, r.limit, metric)
        txt = f"{s.label}: {metric_text(s.value, metric)}"
        if "covered" in facts:
            txt += f", moved {100 * facts['covered']:.0f} % of the step"
        short = str(s.reason or "not eligible").split(":")[0]  # the full reason is listed once under the table
        if s.value is None and s.reason:
            txt += f" (not measured: {short})"
        elif not s.eligible:
            txt += f" (excluded: {short})"
        steps.append({"text": txt, "excluded": not s.eligible or s.value is None})
        cannot.append(facts.get("cannot_fail"))
    cannot_fail = bool(cannot) and all(c is True for c in cannot)
    texts = row_texts(r, metric)
    margin = None if r.margin is None else texts["margin"]
    return {"req": e.id, "procedure": r.procedure, "ops": [r.operating_point], "value": texts["value"],
            "which": r.which, "margin": margin, "margin_pct": texts["margin_pct"],
            "status": r.status, "reason": str(r.reason).split(":")[0] if r.reason else None,
            "raw": r.value, "raw_margin": r.margin, "metric": metric, "steps": steps, "cannot_fail": cannot_fail,
            "run": r.run}


def _grouped(rows: list[dict]) -> list[dict]:
    """Merge the cases of one procedure with the same status (NOT EVALUATED: the same reason) at several
    operating points -> one row with the value range, the value at each point and the per-step
    details of its worst point."""
    out, index = [], {}
    for c in rows:
        key = (c["procedure"], c["status"], c["reason"], c["cannot_fail"])
        if key not in index:
            index[key] = dict(c, members=[c])
            out.append(index[key])
            continue
        g = index[key]
        g["ops"] = g["ops"] + c["ops"]
        g["members"].append(c)
    for g in out:
        ms = g.pop("members")
        if len(ms) == 1:
            continue
        if g["status"] == Status.NOT_EVALUATED:
            g["steps"] = [{"text": "first point shown, the others alike:",
                           "excluded": True}] + g["steps"]
            continue
        worst = min(ms, key=lambda c: c["raw_margin"] if c["raw_margin"] is not None else float("inf"))
        vals = [c for c in ms if isinstance(c["raw"], (int, float))]
        if vals and min(c["raw"] for c in vals) != max(c["raw"] for c in vals):
            # each end as its own row prints it (the one formatter's digits: a failing value never reads as its limit)
            lo, hi = min(vals, key=lambda c: c["raw"])["value"], max(vals, key=lambda c: c["raw"])["value"]
            g["value"] = lo if lo == hi else f"{lo.rsplit(' ', 1)[0]}\u2013{hi}"
        g.update(margin=worst["margin"], margin_pct=worst["margin_pct"], which=worst["which"], run=worst["run"])
        per_point = " \u00b7 ".join(f"{c['ops'][0]} {c['value']}" for c in ms)
        g["steps"] = [{"text": f"per point: {per_point}", "excluded": False},
                      {"text": f"worst point {worst['ops'][0]}:", "excluded": False}] + worst["steps"]
    return out


def _pick_trace(run, which: str | None):
    """The trace of ``run`` that the worst case ``which`` was measured on.

    ``which`` names the direction first and, for the independent-adjustment runs, the valve
    changed ("closing time when opening valve x0.5" -> trace "... opening x0.5 closing").
    """
    traces = run.traces
    if not traces:
        return None
    if which:
        words = str(which).split()
        m = re.search(r"when (\w+) valve (x[\d.]+)", str(which))
        if m and words:
            want = f" {m.group(1)} {m.group(2)} {words[0]}"
            for tr in traces:
                if tr.label.endswith(want):
                    return tr
        for tr in traces:
            tail = tr.label.rsplit(" ", 1)[-1]
            if tail and words and tail == words[0]:
                return tr
        for tr in traces:
            tail = tr.label.rsplit(" ", 1)[-1]
            if tail and tail in which:
                return tr
    return traces[0]


def trace_words(label, run) -> str:
    """What a trace shows, from its own label (the caption is made from the data drawn, never from the verdict)."""
    tail = str(label or "")
    head = f"{run.procedure}@{run.operating_point}"
    tail = tail[len(head):].strip() if tail.startswith(head) else ""
    m = tail.split()
    if len(m) == 3 and m[1].startswith("x"):
        return f"{m[2]} stroke with the {m[0]} flow-control valve set to {m[1][1:]} \u00d7 its conductance"
    if len(m) == 2 and m[0] == "base":
        return f"{m[1]} stroke with both flow-control valves as set"
    return f"{tail} stroke" if tail in ("opening", "closing") else tail


def _stroke_partner(run, tr, entries: list):
    """The other direction's stroke when a page judges both opening and closing times on the same run."""
    if not {"opening_time", "closing_time"} <= {e.metric for e in entries}:
        return None
    label = tr.label
    for a, b in (("opening", "closing"), ("closing", "opening")):
        if label.endswith(" " + a):
            want = label[: -len(a)] + b
            return next((t for t in run.traces if t.label == want), None)
    return None


def _speed_excess(trace, limit: float) -> dict | None:
    """How far and how long the speed exceeds ``limit`` [m/s] in a trace (what matters for water hammer)."""
    import numpy as np

    t, x = trace.signal("time"), trace.signal("position")
    if not t or not x or len(t) < 3:
        return None
    t = np.asarray(t, float)
    x = np.asarray([np.nan if v is None else v for v in x], float)
    v = np.abs(np.gradient(x, t))
    over = v > limit
    if not over.any():
        return {"duration": 0.0}
    dt = np.gradient(t)
    idx = np.flatnonzero(over)
    return {"duration": float(np.sum(dt[over])), "start": float(t[idx[0]]), "end": float(t[idx[-1]]),
            "peak": float(np.nanmax(v)), "extra_travel": float(np.sum((v[over] - limit) * dt[over]))}


def _distinct_reasons(reasons) -> list[str]:
    """One example of each kind of reason (reasons that differ only in their numbers are the same kind)."""
    out, seen = [], set()
    for r in sorted(set(reasons)):
        for part in r.split("; "):
            kind = re.sub(r"[\d.]+", "#", part)
            if kind not in seen:
                seen.add(kind)
                out.append(part)
    return out


_RANK = {Status.FAIL: 0, Status.NOT_EVALUATED: 1, Status.OPEN: 2, Status.PASS: 3, Status.DISABLED: 4}


def _page_requirement(e) -> dict:
    """A requirement on its page: what it rests on, its worst value against its limit, its grouped cases."""
    cases = _grouped([_row_cells(e, r) for r in e.rows])
    texts = verdict_texts(e)
    info = METRICS.get(e.metric)
    return {"id": e.id, "title": e.title, "status": e.status, "severity": e.severity, "metric": e.metric,
            "meaning": info.meaning if info else "", "standard": e.standard, "clause": reader_text(e.clause),
            "note": reader_text(e.note), "limit": limit_as_written(e),
            "value": texts["value"], "margin_pct": texts["margin_pct"], "cases": cases,
            "cannot_fail": sum(1 for c in cases if c["cannot_fail"]),
            "not_evaluated": sum(len(c["ops"]) for c in cases if c["status"] == Status.NOT_EVALUATED)}


def _figure(result, lead, entries, reqs, page, specs, start) -> None:
    """The page's plot: the lead requirement's worst case with its limit drawn (spec appended to ``specs``)."""
    w = lead.worst
    run = result.run(w.run) if w is not None else None
    tr = _pick_trace(run, w.which) if run else None
    if tr is None:
        return
    fid = f"fig-{start + len(specs)}"
    if tr.kind == "path3d":
        specs.append({"id": fid, "kind": "trace", "trace": tr, "marks": (), "run_kind": run.kind})
        page["figure"] = {"id": fid, "run": run.id, "procedure": run.procedure, "operating_point": run.operating_point,
                          "which": w.which, "trace": tr.label, "limit_drawn": False}
        return
    lim = lead.rows[0].limit if lead.rows else None
    spec = {"id": fid, "kind": "trace", "trace": tr, "marks": run.marks, "run_kind": run.kind,
            "compact": "short" if len(entries) > 2 or sum(len(r["cases"]) for r in reqs) >= 3 else True,
            "tolerance": max(lim) if lim and lead.metric in TOLERANCE_METRICS else None,
            "speed_limit": max(lim) if lim and lead.metric in SPEED_METRICS else None,
            "tau_window": tuple(lim) if lim and len(lim) == 2 and lead.metric == "time_constant" else None}
    partner = _stroke_partner(run, tr, entries)
    if partner is not None:  # opening and closing times on one page: both strokes drawn
        spec = {"id": fid, "kind": "strokes", "traces": [tr, partner], "marks": run.marks}
    elif lead.metric == "dead_band" and run.kind == "dead_band":  # the loop, with the width allowed
        spec = {"id": fid, "kind": "dead_band", "trace": tr, "limit": max(lim) if lim else None}
    specs.append(spec)
    shown = [trace_words(t.label, run) for t in ([tr, partner] if partner is not None else [tr])]
    page["figure"] = {"id": fid, "run": run.id, "procedure": run.procedure, "operating_point": run.operating_point,
                      "which": " and ".join(x for x in shown if x), "trace": tr.label,
                      "limit_drawn": any(spec.get(k) is not None for k in ("tolerance", "speed_limit", "limit")),
                      "kind": spec["kind"], "tau": spec.get("tau_window") is not None,
                      "band_scaled": spec.get("tolerance") is not None}
    if spec.get("speed_limit"):
        ex = _speed_excess(tr, spec["speed_limit"])
        if ex and ex.get("duration"):
            page["facts"].append(
                f"In this worst case the speed exceeds {metric_text(spec['speed_limit'], lead.metric)} for "
                f"{fmt_value(ex['duration'], 's', 3)} (from {fmt_value(ex['start'], 's', 3)} to {fmt_value(ex['end'], 's', 3)}), "
                f"peaking at {metric_text(w.value, lead.metric)}; the gate travels "
                f"{metric_text(ex['extra_travel'], 'max_positioning_error')} more than it would at the limit speed.")


def requirement_pages(result, start: int = 1) -> tuple[list[dict], list[dict]]:
    """Pages of section 4 and their figure specs (ids from ``fig-{start}``).

    Requirements judged on exactly the same runs share a page (e.g. the opening/closing times
    of IEC 61362 and IEEE 125 on the same strokes); the page's plot is the worst case of its
    most critical requirement (a failure first).
    """
    groups: dict = {}
    for e in result.requirements:
        key = (e.source, tuple(sorted({r.run for r in e.rows})) or (e.id,))
        groups.setdefault(key, []).append(e)
    pages, specs = [], []
    for (source, _), entries in groups.items():
        lead = min(entries, key=lambda e: _RANK.get(e.status, 5))
        reqs = [_page_requirement(e) for e in entries]
        reasons = _distinct_reasons(str(x) for e in entries for r in e.rows for x in
                                    [r.reason] + [s.reason for s in r.samples] if x and ":" in str(x))
        page = {"anchor": "page-" + lead.id, "ids": [e.id for e in entries], "title": lead.title,
                "source": source, "reqs": reqs, "figure": None, "facts": [], "reasons": reasons,
                "cases": [c for r in reqs for c in r["cases"]]}
        _figure(result, lead, entries, reqs, page, specs, start)
        if lead.metric == "time_constant" and source == "simulation" and lead.status == Status.FAIL:
            page["facts"].append(_linear_contrast(result))
        page["facts"] = [f for f in page["facts"] if f]
        pages.append(page)
    return pages, specs


def _linear_contrast(result) -> str | None:
    """Why the linear time constant and HYGOV Tg can pass while the simulated steps fail."""
    lin = [e for e in result.requirements if e.metric == "time_constant" and e.source == "linear"]
    linear = result.linear_section
    tg = linear.governor.parameters.get("Tg") if linear is not None and linear.governor is not None else None
    parts = []
    if lin and lin[0].worst is not None and lin[0].worst.value is not None:
        parts.append(f"the linearised loop gives {metric_text(lin[0].worst.value, 'time_constant')} ({lin[0].id})")
    if tg is not None:
        parts.append(f"the HYGOV fit gives Tg = {fmt_value(tg, 's', 3)}")
    if not parts:
        return None
    return ("Why a smaller time constant appears elsewhere: " + " and ".join(parts) + ". Both are small-signal figures "
            "(the linear model leaves out the valve dead zone, breakaway friction and flow saturation; Tg is the mean of two "
            "5 % steps at one point). This requirement is judged on every simulated step of the nonlinear model; section 5's "
            "cross-check names the cause of the difference at each point.")
