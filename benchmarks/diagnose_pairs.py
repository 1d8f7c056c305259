"""Two-effect generated cases with structural variety (issue 13): how often both effects are named.

Each case switches two declared effects on in the generating bench and adds one structural
difference from the fitted model (finer integration step, another friction form, no supply
column, an operating point anywhere on the stroke; ``compliance.diagnosis.scoring.two_effect_cases``). Target:
both effects named in >= 80 % of the cases.

Run: .venv/bin/python benchmarks/diagnose_pairs.py [--cases 6] [--seed 1] [--jobs 2] [--only 9,21] [--json out.json]
Not part of the timed test suite (each case is a full diagnosis, 20-100 s on 2 shared cores).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=6)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--only", help="comma-separated case numbers to run alone (e.g. 9,21), each as in the full run")
    ap.add_argument("--json", dest="json_out")
    args = ap.parse_args()
    from compliance.model.config import load_plant
    from compliance.diagnosis.scoring.two_effect_cases import run_pairs

    out = run_pairs(load_plant("plant-a"), cases=args.cases, seed=args.seed, jobs=args.jobs,
                    only=[int(i) for i in args.only.split(",")] if args.only else None)
    print(f"\nboth effects named: {out['both_named']}/{out['cases']} ({100*out['rate']:.0f} %; target >= 80 %) "
          f"in {out['seconds']:.0f} s, CPU {out['cpu_seconds']:.0f} s ({out['cpu_seconds']/max(out['cases'], 1):.0f} s per case)")
    other = out["cases"] - out["identifiable"]
    print(f"identifiable (the true pair removes >= half the excess in the fitted model): both named in "
          f"{out['both_named_identifiable']}/{out['identifiable']}; not identifiable: honest incomplete verdict in "
          f"{out['honest_not_identifiable']}/{other}")
    errs = [e for r in out["rows"] if r["both_named"] for e in r["main_errors"].values()]
    if errs:
        print(f"main parameters within 25 %: {sum(e <= 0.25 for e in errs)}/{len(errs)}")
    if args.json_out:
        Path(args.json_out).write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
