"""Score ``govcheck accept`` on the practice site-acceptance set: every verdict and every figure against the truth.

Usage: python benchmarks/accept_score.py PRACTICE_DIR [--markdown]
       (PRACTICE_DIR holds site-p1/, site-p2/, ... and ANSWERS.json; about 10 s per site, no predictions)

For each site the requirement file (requirements/shpp-400kw.toml) judges the recordings as
``govcheck accept SITE --requirements requirements/shpp-400kw.toml`` does; every requirement the
truth judges is compared under the reading the file states (compliance.acceptance.scoring), and
every figure the truth gives is compared with the measured one and its stated uncertainty. Prints
the verdict table and the figure summary (``--markdown``: the tables of docs/acceptance.md).
Exit 0 when everything agrees, 1 otherwise.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # runnable as documented from a checkout

from compliance.acceptance.run import accept  # noqa: E402
from compliance.acceptance.scoring import score_figures, score_verdicts  # noqa: E402
from compliance.acceptance.site.folder import read_site  # noqa: E402
from compliance.acceptance.site.prepared import prepare  # noqa: E402
from compliance.model.config import load_plant  # noqa: E402
from compliance.requirements.loading import load_requirements  # noqa: E402

REQUIREMENTS = Path(__file__).resolve().parents[1] / "requirements" / "shpp-400kw.toml"
_KINDS = (("time constant", ("time_constant @",)), ("time constant (achieved)", ("time_constant_achieved",)),
          ("positioning error", ("mean_positioning_error",)), ("stroke time 25-75 % x 2", ("opening_time", "closing_time")),
          ("stroke rate", ("stroke_speed",)), ("start delay", ("start_delay",)), ("hold drift (line fit)", ("drift",)),
          ("hold drift (largest)", ("drift_excursion",)), ("dead band", ("dead_band",)), ("tracking error", ("tracking_max_error",)))


def _kind(figure: str) -> str | None:
    for name, keys in _KINDS:
        if any(figure.startswith(k) if k.endswith("@") else figure == k or figure.startswith(k + " ") for k in keys):
            return name
    return None


def score(practice: Path) -> tuple[dict, list]:
    answers = json.loads((practice / "ANSWERS.json").read_text())
    reqset, cfg = load_requirements(REQUIREMENTS), load_plant("plant-a")
    verdicts, figures = {}, []
    for site in sorted(answers["sites"]):
        recordings = read_site(practice / site)
        results = accept(practice / site, reqset, cfg, recordings=recordings, predict=False)
        verdicts[site] = score_verdicts(results, answers["sites"][site])
        figures += score_figures(site, [prepare(r, cfg) for r in recordings], cfg, answers["sites"][site])
    return verdicts, figures


def _fmt(v, u=None) -> str:
    if v is None:
        return "-"
    return f"{v:.4g}" + ("" if u is None else f" ± {u:.2g}")


def verdict_table(verdicts: dict) -> list:
    sites = list(verdicts)
    rows = {}
    for site, vs in verdicts.items():
        for v in vs:
            rows.setdefault(v["id"], {})[site] = v
    out = ["| requirement (truth row) | " + " | ".join(f"{s}: govcheck / truth" for s in sites) + " |",
           "|---|" + "---|" * len(sites)]
    for rid, by_site in rows.items():
        cells = []
        for s in sites:
            v = by_site.get(s)
            cells.append("-" if v is None else f"{v['status'].upper()} / {v['truth'].upper()}{' (marginal)' if v['marginal'] else ''}"
                         f"{'' if v['ok'] else ' **differs**'}")
        truth_row = next(iter(by_site.values()))["truth_row"]
        out.append(f"| {rid}" + (f" ({truth_row})" if truth_row != rid else "") + " | " + " | ".join(cells) + " |")
    return out


def figure_table(figures: list) -> list:
    out = ["| figure | site | compared | within its uncertainty | within the tolerance | uncertainty narrower than the tolerance | "
           "largest error / its uncertainty |", "|---|---|---|---|---|---|---|"]
    groups: dict = {}
    for f in figures:
        groups.setdefault((_kind(f["figure"]) or f["figure"], f["site"]), []).append(f)
    for (kind, site), fs in sorted(groups.items(), key=lambda kv: ([k for k, _ in _KINDS].index(kv[0][0]) if kv[0][0] in dict(_KINDS) else 99, kv[0][1])):
        worst = max(fs, key=lambda f: abs((f["value"] or 0) - f["truth"]) / max(f["u"], 1e-15))
        ratio = abs((worst["value"] or 0) - worst["truth"]) / max(worst["u"], 1e-15)
        out.append(f"| {kind} | {site} | {len(fs)} | {sum(f['within_u'] for f in fs)} | {sum(f['within_tolerance'] for f in fs)} | "
                   f"{sum(f['u_within_tolerance'] for f in fs)} | "
                   f"{ratio:.2f} ({worst['test']}, {worst['figure']}: {_fmt(worst['value'], worst['u'])} vs {_fmt(worst['truth'])}) |")
    return out


def main(argv: list) -> int:
    if not argv or argv[0].startswith("-"):
        print(__doc__)
        return 2
    verdicts, figures = score(Path(argv[0]))
    lines = verdict_table(verdicts) + [""] + figure_table(figures)
    misses = [v for vs in verdicts.values() for v in vs if not v["ok"]] + [f for f in figures if not f["ok"]]
    print("\n".join(lines))
    if "--markdown" not in argv:
        for m in misses:
            print("MISS:", m)
    n_v = sum(len(vs) for vs in verdicts.values())
    print(f"\n{n_v - sum(1 for vs in verdicts.values() for v in vs if not v['ok'])} of {n_v} verdicts as the truth; "
          f"{sum(f['ok'] for f in figures)} of {len(figures)} figures within their uncertainty and the tolerance of the truth")
    return 0 if not misses else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
