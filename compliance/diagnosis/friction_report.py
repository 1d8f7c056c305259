"""HTML report of a friction-bench diagnosis: per seal, the explanation, the ranked laws and the figures.

Figures per seal (matplotlib, inline SVG): measured friction against position (hysteresis
loops) with the baseline law and the winner, for the lowest and highest pressure; friction
against time over two strokes; the RMS error per pressure before and after.
"""

from __future__ import annotations

import html
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


def write_friction_report(diag, html_path) -> Path:
    """Write the HTML report of a ``FrictionDiagnosis`` (atomically; refuses a directory)."""
    path = Path(html_path)
    if path.is_dir():
        raise InputError(f"--report {path}: is a directory; expected an .html file name")
    data = diag.to_dict()
    parts = ["<!doctype html><html><head><meta charset='utf-8'><title>govcheck friction diagnosis</title>",
             "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
             "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #ccc;padding:3px 7px;text-align:right}"
             "th{background:#f3f3f3}td:first-child{text-align:left}.v{font-weight:bold}</style></head><body>",
             "<h1>Friction diagnosis</h1>",
             f"<p>Recordings: {', '.join(html.escape(Path(f).name) for f in data['recordings'])}</p>"]
    for seal, sd in zip(diag.seals, data["seals"]):
        parts.append(f"<h2>Seal {html.escape(sd['seal'])}: <span class='v'>{sd['verdict']}</span>"
                     + (f" ({html.escape(sd['winner'])})" if sd["winner"] else "") + "</h2>")
        parts.append(f"<p>{html.escape(sd['explanation'])}</p>")
        parts.append("<table><tr><th>candidate law</th><th>k</th><th>chi2/N</th><th>dBIC</th><th>explained</th><th>parameters</th></tr>")
        for e in sd["effects"]:
            ps = ", ".join(f"{p['name']} = {p['value']:.4g} {p['unit']}" for p in e["parameters"] if p["value"] is not None)
            parts.append(f"<tr><td>{html.escape(e['name'])}</td><td>{e['k']}</td><td>{e['chi2_per_residual']:.1f}</td>"
                         f"<td>{e['delta_bic']:.0f}</td><td>{100*(e['explained_fraction'] or 0):.0f} %</td>"
                         f"<td style='text-align:left'>{html.escape(ps)}</td></tr>")
        parts.append("</table><h3>Per pressure</h3><table><tr><th>run</th><th>p [bar g]</th><th>RMS before [N]</th><th>RMS after [N]</th></tr>")
        for run, b in sd["fit_before"].items():
            a = (sd["fit_after"] or {}).get(run)
            parts.append(f"<tr><td>{html.escape(run)}</td><td>{b['pressure_gauge']/1e5:.2f}</td><td>{b['rms']:.3f}</td>"
                         f"<td>{a['rms']:.3f}</td></tr>" if a else
                         f"<tr><td>{html.escape(run)}</td><td>{b['pressure_gauge']/1e5:.2f}</td><td>{b['rms']:.3f}</td><td>-</td></tr>")
        parts.append("</table>")
        for caption, svg in seal_figures(seal):
            parts.append(f"<figure>{svg}<figcaption>{html.escape(caption)}</figcaption></figure>")
    parts.append("</body></html>")
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, "\n".join(parts))
    return path
