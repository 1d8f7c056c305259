"""HTML report of a friction-bench diagnosis, in the report template: the finding first, then per seal the ranked laws and the figures.

Figures per seal (matplotlib, inline SVG): measured friction against position (hysteresis
loops) with the baseline law and the winner, for the lowest and highest pressure; friction
against time over two strokes; the RMS error per pressure before and after; the held-out table
(each pressure predicted by the law fitted on the others).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from compliance.presentation.quantities import fmt_quantity, to_display
from compliance.report.fit_bounds import at_bound
from compliance.report.svg import styled, to_svg


@styled
def seal_figures(seal, prefix: str = "fric") -> list[tuple[str, str]]:
    """(caption, inline SVG) of one ``SealDiagnosis``, in the report's style (text kept, ids prefixed)."""
    from matplotlib.figure import Figure

    from compliance.diagnosis.friction_bench.fit import predict

    class plt:  # the three figure sizes below, without pyplot's global state
        @staticmethod
        def subplots(nrows=1, ncols=1, figsize=None, squeeze=True):
            fig = Figure(figsize=figsize)
            return fig, fig.subplots(nrows, ncols, squeeze=squeeze)

        @staticmethod
        def close(fig):
            return None

    runs = seal.runs
    base = seal.fits["baseline"]
    win = seal.fits.get(seal.winner) if seal.winner else None
    picks = sorted({0, len(runs) - 1})
    out = []
    fig, axes = plt.subplots(1, len(picks), figsize=(5.2 * len(picks), 3.6), squeeze=False)
    for ax, i in zip(axes[0], picks):
        r = runs[i]
        span = r.time <= min(r.time[-1], r.time[0] + 25.0)
        x_mm = to_display(r.position[span], "m", "mm")
        ax.plot(x_mm, r.friction[span], color="k", lw=0.6, label="measured")
        ax.plot(x_mm, predict(r, base)[span], color="tab:blue", lw=0.7, label="before: baseline law")
        if win is not None:
            ax.plot(x_mm, predict(r, win)[span], color="tab:orange", lw=0.7, label="after: with the added physics")
        ax.set_xlabel("position [mm]")
        ax.set_ylabel("friction F \u2212 p\u00b7A [N]")
        ax.set_title(f"{r.name} ({fmt_quantity(r.pressure, 'Pa', 'kPa', 0)} gauge)", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    out.append(("Hysteresis loops: measured friction against position at the lowest and highest pressure, before "
                "(baseline law) and after (with the added physics)", to_svg(fig, f"{prefix}-1")))
    plt.close(fig)
    fig, axes = plt.subplots(len(picks), 1, figsize=(10.0, 2.6 * len(picks)), squeeze=False)
    for ax, i in zip(axes[:, 0], picks):
        r = runs[i]
        rev = np.flatnonzero(np.diff(np.sign(r.velocity)) != 0)
        t0 = r.time[rev[2]] - 0.5 if rev.size > 4 else r.time[0]
        m = (r.time >= t0) & (r.time <= t0 + 8.0)
        ax.plot(r.time[m], r.friction[m], color="k", lw=0.7, label="measured")
        ax.plot(r.time[m], predict(r, base)[m], color="tab:blue", lw=0.7, label="before: baseline law")
        if win is not None:
            ax.plot(r.time[m], predict(r, win)[m], color="tab:orange", lw=0.7, label="after: with the added physics")
        ax.set_ylabel("friction [N]")
        ax.set_title(f"{r.name}", fontsize=8)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].legend(fontsize=7, ncol=3)
    fig.tight_layout()
    out.append(("Friction against time over a few strokes, before and after (reversals: the transitions)",
                to_svg(fig, f"{prefix}-2")))
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(5.5, 3.2))
    p = to_display(np.array([r.pressure for r in runs]), "Pa", "kPa")
    w = 0.35 * (np.min(np.diff(p)) if p.size > 1 else 1.0)
    ax.bar(p - w / 2, base.rms_per_run(), width=w, color="tab:blue", label="before: baseline law")
    if win is not None:
        ax.bar(p + w / 2, win.rms_per_run(), width=w, color="tab:orange", label="after: " + seal.winner.replace("+", " +\n"))
    ax.set_xlabel("chamber pressure [kPa gauge]")
    ax.set_ylabel("RMS friction error [N]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    out.append(("RMS friction error per pressure, before (baseline law) and after (the winning law)", to_svg(fig, f"{prefix}-3")))
    plt.close(fig)
    return out


CHI2_TEXT = ("\u03c7\u00b2/N: mean squared residual per sample in units of the run's noise variance (1 = the law "
             "fits down to the noise).")
DBIC_TEXT = ("\u0394BIC: Bayesian information criterion relative to the best law (lower is better; more parameters "
             "are penalised). A difference above 10 is strong evidence; under 2 the data do not decide.")


def _param_rows(params: list) -> list[dict]:
    """Fitted parameters with SI prefixes, standard errors and a flag when a value sits on its fit bound."""
    from compliance.diagnosis.friction_bench.fit import FIT_BOUNDS
    from compliance.presentation.numbers import fmt_si

    rows = []
    for p in params:
        if p["value"] is None:
            continue
        b = FIT_BOUNDS.get(p["name"])
        pinned = bool(b) and at_bound(p["value"], *b)
        rows.append({"name": p["name"].replace("_", " "), "meaning": p["meaning"] or "",
                     "text": fmt_si(p["value"], p["unit"], p["stderr"]),
                     "bound": (f"at its fit bound ({fmt_si(b[0] if abs(p['value'] - b[0]) < abs(p['value'] - b[1]) else b[1], p['unit'])}): "
                               "the data do not determine it and its standard error means nothing") if pinned else None})
    return rows


def _seal_context(seal, sd: dict, index: int) -> dict:
    """What the report shows of one seal: finding, parameters with errors (SI prefixes), ranked laws, residual remarks."""
    from compliance.presentation.numbers import fmt_dbic, fmt_num, fmt_si, fmt_value

    win = next((e for e in sd["effects"] if e["name"] == sd["winner"]), None) if sd["winner"] else None
    params = _param_rows((win or {}).get("parameters") or [])
    ranked = [{"name": e["name"].replace("+", " + ").replace("_", " "), "k": e["k"], "chi2": fmt_num(e["chi2_per_residual"], 3),
               "dbic": fmt_dbic(e["delta_bic"]), "explained": fmt_quantity(e["explained_fraction"] or 0, "", "%"),
               "params": "; ".join(f"{p['name'].replace('_', ' ')} {fmt_si(p['value'], p['unit'])}"
                                   for p in e["parameters"] if p["value"] is not None)} for e in sd["effects"]]
    floor = sd["noise_floor"]["value"]
    runs, remarks, after = [], [], []
    for run, b in sd["fit_before"].items():
        a = (sd.get("fit_after") or {}).get(run)
        runs.append({"run": run, "p": fmt_si(b["pressure_gauge"], "Pa") + " gauge", "before": fmt_si(b["rms"], "N"),
                     "after": fmt_si(a["rms"], "N") if a else "\u2013"})
        if a:
            after.append((a["rms"], b["pressure_gauge"], run))
    if after and floor:
        worst, best = max(after), min(after)
        if worst[0] > 2.0 * floor:
            remarks.append(f"Residual left: the fitted law still misses by {fmt_si(worst[0], 'N')} RMS at "
                           f"{fmt_si(worst[1], 'Pa')} gauge ({worst[2]}), {worst[0] / floor:.0f} \u00d7 the force noise "
                           f"({fmt_si(floor, 'N')}), against {fmt_si(best[0], 'N')} at {fmt_si(best[1], 'Pa')} gauge. No "
                           "candidate explains the rest; it is not noise. Use the law within the pressures tested and treat "
                           "the remainder as model uncertainty.")
    pinned = [p["name"] for p in params if p["bound"]]
    if pinned:
        remarks.append("Parameters at their fit bounds (" + ", ".join(pinned) + "): the runs do not determine them; "
                       "record runs that excite them (slower strokes for a Stribeck velocity) before using their values.")
    return {"seal": sd["seal"], "seal_index": index, "verdict": sd["verdict"], "winner": (sd["winner"] or "").replace("+", " + ").replace("_", " "),
            "runner_up": (seal.runner_up or "").replace("+", " + ").replace("_", " "),
            "explanation": sd["explanation"], "params": params, "ranked": ranked, "runs": runs, "remarks": remarks,
            "figures": seal_figures(seal, f"fig-{index}"), "holdout": _holdout_context(seal.holdout)}


def _holdout_context(h: dict | None) -> dict | None:
    """The held-out table of a seal (friction_holdout.holdout_table), formatted."""
    from compliance.presentation.numbers import fmt_num, fmt_value

    if not h:
        return None
    rows = [{"run": r["run"], "p": fmt_quantity(r["pressure_gauge"], "Pa", "bar"), "ins": fmt_value(r["in_sample_rms"], "N", 3),
             "held": fmt_value(r["held_out_rms"], "N", 3), "ratio": fmt_num(r["ratio"], 3),
             "offset": fmt_value(r["held_out_offset"], "N", 2), "ratio0": fmt_num(r["ratio_without_offset"], 3),
             "noise": fmt_value(r["noise_floor"], "N", 2)} for r in h["runs"]]
    law = h["law"].replace("+", " + ")  # a long sum of effects must break at its plus signs
    note = (f"Law {law}, refitted without the held-out run. Median held-out / in-sample: {h['median_ratio']:.2f} "
            f"(target \u2264 {h['ratio_target']:g}); with each run's own offset removed: {h['median_ratio_without_offset']:.2f}. "
            "The run offset is the mean of the held-out run's error against the law fitted on the other runs, their "
            "force bias included (curved in pressure when the pressure-squared bias is kept): a bench finding (a force "
            "zero that moves between runs), not friction physics.")
    return {"rows": rows, "note": note}


BENCH_FIELDS = (("rig", "Test rig"), ("seal", "Seal"), ("bore", "Bore"), ("temperature", "Temperature"),
                ("operator", "Operator"), ("date", "Date of the runs"))


def write_friction_report(diag, html_path, pdf_path=None, *, document: dict | None = None, bench: dict | None = None):
    """Write the HTML (and PDF) report of a ``FrictionDiagnosis``, atomically.

    Same template family, CSS, document control and sign-off block as the compliance and
    validation reports: the finding per seal first (verdict, law, fitted parameters with standard
    errors and SI prefixes, parameters at a fit bound flagged, next step), then the evidence.
    ``document``: ``number`` / ``revision`` (without a number the report is a DRAFT); ``bench``:
    identity of the bench (rig, seal, bore, temperature, operator, date; blanks where not given).
    """
    import datetime as _dt

    from compliance.report.render import _check_target, _common, _emit, file_sha256
    from compliance.report.signoff import document_block
    from compliance.presentation.numbers import fmt_date

    if html_path:
        html_path = _check_target(html_path, "--report")
    if pdf_path:
        _check_target(pdf_path, "--pdf")
    document = document or {}
    data = diag.to_dict()
    seals = [_seal_context(seal, sd, i + 1) for i, (seal, sd) in enumerate(zip(diag.seals, data["seals"]))]
    recordings = [{"what": "Recording", "path": Path(f).name, "digest": file_sha256(f)} for f in data["recordings"]]
    bench = dict(bench or {})
    bench.setdefault("seal", ", ".join(s["seal"] for s in seals))
    ident = {"document_number": document.get("number")} if document.get("number") else {}
    now = fmt_date(_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))
    svgs = {}
    for s in seals:
        named = []
        for caption, svg in s["figures"]:
            fid = f"fig-{len(svgs) + 1}"  # numbered through the document (the SVG's inner ids carry the seal)
            svgs[fid] = svg
            named.append((caption, fid))
        s["figures"] = named
    ctx = {**_common({}), "rendered": now, "verdict": data["verdict"], "seals": seals, "chi2_text": CHI2_TEXT,
           "dbic_text": DBIC_TEXT, "doc": document_block(ident, recordings, document, needs_identity=False),
           "bench": [(label, bench.get(key)) for key, label in BENCH_FIELDS]}
    _emit("friction.html.j2", ctx, svgs, html_path, pdf_path)
    return html_path
