"""Regenerate every example under reports/examples/ with the govcheck of this checkout, then check them.

    python reports/examples/regenerate.py                 # everything (about 5 min on 2 cores)
    python reports/examples/regenerate.py --skip-sweep    # without the remedies sweep (the slowest part)
    python reports/examples/regenerate.py --check-only    # only check the examples already there

Each example is made by the documented govcheck command (printed before it runs). Afterwards
every HTML and PDF example is checked for text outside its figure or page and for overprinting
(compliance.report.layout_check; the plant-A body at most 28 pages, the sign-off on page 1), for names of the code base, "seed" and references to missing
sections (compliance.report.text_check), and every file an example points at must exist.
Exit 0 when all is made and clean, 1 when a check fails, 2 when a command fails.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = Path("reports/examples")

COMMANDS = {
    "plant-a": ["check", "models/plant-a.toml", "--requirements", "requirements/shpp-400kw.toml", "--linear",
                "--report", str(OUT / "plant-a-shpp-400kw.html"), "--pdf", str(OUT / "plant-a-shpp-400kw.pdf"), "--quiet"],
    "plant-b": ["check", "models/plant-b.toml", "--requirements", "requirements/tracking-robot.toml",
                "--report", str(OUT / "plant-b-tracking-robot.html"), "--pdf", str(OUT / "plant-b-tracking-robot.pdf"),
                "--quiet"],
    "diagnosis": ["diagnose", "tests/data/practice/practice_valve_dynamics.csv.gz",
                  "--report", str(OUT / "diagnosis-practice-valve-dynamics.html"),
                  "--pdf", str(OUT / "diagnosis-practice-valve-dynamics.pdf"), "--quiet"],
    "friction": ["diagnose", "--column-map", "zillen-friction", "--friction-bore", "25.7 mm",
                 "--report", str(OUT / "diagnosis-zillen-friction.html"), "--pdf", str(OUT / "diagnosis-zillen-friction.pdf"),
                 "--quiet"],
    "sweep": ["sweep", "models/sweeps/plant-a-remedies.toml", "--out", str(OUT / "plant-a-remedies")],
    "site": ["accept", "tests/data/acceptance/site-p2", "--requirements", "requirements/shpp-400kw.toml", "--diagnose",
             "--report", str(OUT / "site-acceptance-p2.html"), "--pdf", str(OUT / "site-acceptance-p2.pdf"), "--quiet"],
}
EXIT_OK = (0, 1)  # a compliance check that fails its requirements still wrote its report


def _run(name: str, args: list[str], friction_runs: list[str]) -> None:
    cmd = [sys.executable, "-m", "compliance", *args]
    if name == "friction":
        cmd[4:4] = friction_runs  # after "diagnose": the recordings first, then the options
    print("govcheck " + " ".join(cmd[3:]), flush=True)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    rc = subprocess.run(cmd, cwd=ROOT, env=env).returncode
    if rc not in EXIT_OK:
        sys.exit(f"{name}: govcheck exited {rc}")


def _pointers_missing() -> list[str]:
    """Files an example or the README points at (links, reports/examples/... paths) that do not exist."""
    missing = []
    sources = [ROOT / "README.md"] + sorted((ROOT / OUT).rglob("*.md")) + sorted((ROOT / OUT).rglob("*.html"))
    for src in sources:
        text = src.read_text(encoding="utf-8", errors="replace")
        for target in set(re.findall(r"reports/examples/[\w./-]+", text)):
            if not (ROOT / target.rstrip(".)")).exists():
                missing.append(f"{src.relative_to(ROOT)} points at {target}, which is missing")
    return missing


def check() -> list[str]:
    """Layout and text problems of every example, and missing pointers."""
    sys.path.insert(0, str(ROOT))
    from compliance.report.layout_check import BODY_PAGES_MAX, body_pages, html_problems, pdf_problems, sign_off_fits
    from compliance.report.text_check import html_text, repository_names, text_problems

    names = repository_names(ROOT)
    problems = []
    for html in sorted((ROOT / OUT).rglob("*.html")):
        raw = html.read_text(encoding="utf-8")
        problems += [f"{html.name}: {p}" for p in html_problems(raw)]
        if html.parent != ROOT / OUT:
            continue  # a sweep's summary lists its own files; the signed reports are at the top
        text, headings = html_text(raw)
        inputs = re.findall(r'<td class="small mono path">([^<]+)</td>', raw)
        inputs += re.findall(r'<span class="mono small">([^<]+)</span>', raw)
        inputs += [p.rsplit("/", 1)[-1] for p in inputs]
        problems += [f"{html.name}: {p}" for p in text_problems(text, headings, repo_names=names, allowed=inputs)]
    for pdf in sorted((ROOT / OUT).rglob("*.pdf")):
        problems += [f"{pdf.name}: {p}" for p in pdf_problems(pdf)]
    plant_a = ROOT / OUT / "plant-a-shpp-400kw.pdf"
    if plant_a.exists() and body_pages(plant_a)["body"] > BODY_PAGES_MAX:
        problems.append(f"{plant_a.name}: the body has {body_pages(plant_a)['body']} pages, more than {BODY_PAGES_MAX}")
    for pdf in (ROOT / OUT / "plant-a-shpp-400kw.pdf", ROOT / OUT / "plant-b-tracking-robot.pdf"):
        if pdf.exists() and not sign_off_fits(pdf):
            problems.append(f"{pdf.name}: the sign-off page runs onto page 2")
    return problems + _pointers_missing()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-sweep", action="store_true", help="leave the remedies sweep as it is")
    ap.add_argument("--check-only", action="store_true", help="make nothing; check the examples already there")
    ap.add_argument("--only", choices=sorted(COMMANDS), action="append", help="make only these examples (repeatable)")
    ap.add_argument("--friction-runs", nargs="+", metavar="CSV",
                    help="seal-friction runs of the Zillen bench (default: the two shipped in tests/data/zillen)")
    args = ap.parse_args(argv)
    friction = args.friction_runs or [str(p.relative_to(ROOT)) for p in sorted((ROOT / "tests/data/zillen").glob("*.csv"))]
    if not args.check_only:
        for name, cmd in COMMANDS.items():
            if (args.only and name not in args.only) or (name == "sweep" and args.skip_sweep):
                continue
            _run(name, cmd, friction)
    problems = check()
    for p in problems:
        print(p)
    print(f"{len(problems)} problem(s) in reports/examples/")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
