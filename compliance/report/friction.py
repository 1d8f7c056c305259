"""HTML report of a friction-bench diagnosis, in the report template: the finding first, then per seal the ranked laws and the figures.

Figures per seal (matplotlib, inline SVG): measured friction against position (hysteresis
loops) with the baseline law and the winner, for the lowest and highest pressure; friction
against time over two strokes; the RMS error per pressure before and after; the held-out table
(each pressure predicted by the law fitted on the others).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from compliance.errors import InputError
from compliance.files.atomic import write_text_atomic


def _svg(fig) -> str:
    buf = io.StringIO()
    fig.savefig(buf, format="svg", bbox_inches="tight")
    text = buf.getvalue()
    return text[text.find("<svg"):]


def seal_figures(seal) -> list[tuple[str, str]]:
    """(caption, inline SVG) of one ``SealDiagnosis``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from compliance.diagnosis.friction_fit import predict

    runs = seal.runs
    base = seal.fits["baseline"]
    win = seal.fits.get(seal.winner) if seal.winner else None
    picks = sorted({0, len(runs) - 1})
    out = []
    fig, axes = plt.subplots(1, len(picks), figsize=(5.2 * len(picks), 3.6), squeeze=False)
    for ax, i in zip(axes[0], picks):
        r = runs[i]
        span = r.time <= min(r.time[-1], r.time[0] + 25.0)
        ax.plot(r.position[span] * 1e3, r.friction[span], color="k", lw=0.6, label="measured")
        ax.plot(r.position[span] * 1e3, predict(r, base)[span], color="tab:blue", lw=0.7, label="baseline law")
        if win is not None:
            ax.plot(r.position[span] * 1e3, predict(r, win)[span], color="tab:orange", lw=0.7, label="with the added physics")
        ax.set_xlabel("position [mm]")
        ax.set_ylabel("friction F - p_g A [N]")
        ax.set_title(f"{r.name} ({r.pressure/1e5:.1f} bar g)", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    out.append(("Hysteresis loops: measured friction against position, lowest and highest pressure", _svg(fig)))
    plt.close(fig)
    fig, axes = plt.subplots(len(picks), 1, figsize=(10.0, 2.6 * len(picks)), squeeze=False)
    for ax, i in zip(axes[:, 0], picks):
        r = runs[i]
        rev = np.flatnonzero(np.diff(np.sign(r.velocity)) != 0)
        t0 = r.time[rev[2]] - 0.5 if rev.size > 4 else r.time[0]
        m = (r.time >= t0) & (r.time <= t0 + 8.0)
        ax.plot(r.time[m], r.friction[m], color="k", lw=0.7, label="measured")
        ax.plot(r.time[m], predict(r, base)[m], color="tab:blue", lw=0.7, label="baseline law")
        if win is not None:
            ax.plot(r.time[m], predict(r, win)[m], color="tab:orange", lw=0.7, label="with the added physics")
        ax.set_ylabel("friction [N]")
        ax.set_title(f"{r.name}", fontsize=9)
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].legend(fontsize=7, ncol=3)
    fig.tight_layout()
    out.append(("Friction against time over a few strokes (reversals: the transitions)", _svg(fig)))
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(5.5, 3.2))
    p = np.array([r.pressure / 1e5 for r in runs])
    w = 0.35 * (np.min(np.diff(p)) if p.size > 1 else 1.0)
    ax.bar(p - w / 2, base.rms_per_run(), width=w, color="tab:blue", label="baseline law")
    if win is not None:
        ax.bar(p + w / 2, win.rms_per_run(), width=w, color="tab:orange", label=seal.winner.replace("+", " +\n"))
    ax.set_xlabel("chamber pressure [bar g]")
    ax.set_ylabel("RMS friction error [N]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    out.append(("RMS friction error per pressure, before and after", _svg(fig)))
    plt.close(fig)
    return out


CHI2_TEXT = ("\u03c7\u00b2/N: mean squared residual per sample in units of the run's noise variance (1 = the law "
             "fits down to the noise).")
DBIC_TEXT = ("\u0394BIC: Bayesian information criterion relative to the best law (lower is better; more parameters "
             "are penalised). A difference above 10 is strong evidence; under 2 the data do not decide.")


def _sha256(path) -> str | None:
    import hashlib

    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _seal_context(seal, sd: dict) -> dict:
    """What the report shows of one seal: finding, parameters with errors (SI units), ranked laws, residual remarks."""
    from compliance.units.formatting import fmt_num, fmt_value, unit_text

    win = next((e for e in sd["effects"] if e["name"] == sd["winner"]), None) if sd["winner"] else None
    params = [{"name": p["name"], "meaning": p.get("meaning") or "",
               "text": f"{fmt_num(p['value'], 3)} \u00b1 {fmt_num(p['stderr'], 2)} {unit_text(p['unit'])}" if p.get("stderr") is not None
               else f"{fmt_num(p['value'], 3)} {unit_text(p['unit'])}"}
              for p in (win or {}).get("parameters") or [] if p.get("value") is not None]
    ranked = [{"name": e["name"], "k": e["k"], "chi2": fmt_num(e.get("chi2_per_residual"), 3),
               "dbic": fmt_num(e.get("delta_bic"), 3), "explained": fmt_value(100 * (e.get("explained_fraction") or 0), "%", 2),
               "params": "; ".join(f"{p['name']} = {fmt_num(p['value'], 3)} {unit_text(p['unit'])}" for p in e["parameters"]
                                   if p.get("value") is not None)} for e in sd["effects"]]
    floor = (sd.get("noise_floor") or {}).get("value")
    runs, remarks, after = [], [], []
    for run, b in sd["fit_before"].items():
        a = (sd.get("fit_after") or {}).get(run)
        runs.append({"run": run, "p": fmt_value(b["pressure_gauge"] / 1e5, "bar", 3), "before": fmt_value(b["rms"], "N", 3),
                     "after": fmt_value(a["rms"], "N", 3) if a else "\u2013"})
        if a:
            after.append((a["rms"], b["pressure_gauge"], run))
    if after and floor:
        worst, best = max(after), min(after)
        if worst[0] > 2.0 * floor:
            remarks.append(f"Residual left: the fitted law still misses by {fmt_value(worst[0], 'N', 3)} RMS at "
                           f"{fmt_value(worst[1] / 1e5, 'bar', 2)} ({worst[2]}), {worst[0] / floor:.0f} \u00d7 the force noise "
                           f"({fmt_value(floor, 'N', 2)}), against {fmt_value(best[0], 'N', 3)} at "
                           f"{fmt_value(best[1] / 1e5, 'bar', 2)}. No candidate explains the rest; it is not noise. "
                           "Use the law within the pressures tested and treat the remainder as model uncertainty.")
    return {"seal": sd["seal"], "verdict": sd["verdict"], "winner": sd["winner"], "runner_up": sd.get("runner_up"),
            "explanation": sd["explanation"], "params": params, "ranked": ranked, "runs": runs, "remarks": remarks,
            "figures": seal_figures(seal), "holdout": _holdout_context(sd.get("holdout"))}


def _holdout_context(h: dict | None) -> dict | None:
    """The held-out table of a seal (friction_holdout.holdout_table), formatted."""
    from compliance.units.formatting import fmt_num, fmt_value

    if not h:
        return None
    rows = [{"run": r["run"], "p": fmt_value(r["pressure_gauge"] / 1e5, "bar", 3), "ins": fmt_value(r["in_sample_rms"], "N", 3),
             "held": fmt_value(r["held_out_rms"], "N", 3), "ratio": fmt_num(r["ratio"], 3),
             "offset": fmt_value(r["held_out_offset"], "N", 2), "ratio0": fmt_num(r["ratio_without_offset"], 3),
             "noise": fmt_value(r["noise_floor"], "N", 2)} for r in h["runs"]]
    note = (f"Law {h['law']}, refitted without the held-out run. Median held-out / in-sample: {h['median_ratio']:.2f} "
            f"(target \u2264 {h['ratio_target']:g}); with each run's own offset removed: {h['median_ratio_without_offset']:.2f}. "
            "The run offset is the held-out run's force zero against the other runs' bias line: a bench finding "
            "(the sensor zero moves between runs), not friction physics.")
    return {"rows": rows, "note": note}


def write_friction_report(diag, html_path) -> Path:
    """Write the HTML report of a ``FrictionDiagnosis`` (atomically; refuses a directory).

    Same template family, CSS and sign-off block as the compliance and validation reports:
    the finding per seal first (verdict, law, fitted parameters with standard errors in SI
    units, next step), then the evidence.
    """
    import datetime as _dt

    from compliance import __version__
    from compliance.report.render import _css, _environment
    from compliance.units.formatting import fmt_date

    path = Path(html_path)
    if path.is_dir():
        raise InputError(f"--report {path}: is a directory; expected an .html file name")
    data = diag.to_dict()
    seals = [_seal_context(seal, sd) for seal, sd in zip(diag.seals, data["seals"])]
    now = fmt_date(_dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))
    ctx = {"recordings": [{"name": Path(f).name, "sha256": _sha256(f)} for f in data["recordings"]],
           "verdict": data["verdict"], "seals": seals, "rendered": now, "govcheck_version": __version__,
           "chi2_text": CHI2_TEXT, "dbic_text": DBIC_TEXT}
    import jinja2

    html_text = _environment().get_template("friction.html.j2").render(**ctx, css=jinja2.utils.markupsafe.Markup(_css()),
                                                                       svg=jinja2.utils.markupsafe.Markup)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, html_text)
    return path
