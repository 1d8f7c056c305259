"""The sweep's results: one table row per candidate, the Pareto front, the best candidate, the files.

Table columns (Parquet and CSV): ``candidate``; one column per adjusted (or drawn) parameter
path in SI; per requirement ``ID.value``, ``ID.margin``, ``ID.margin_pct``, ``ID.status``;
``status`` (pass / fail / incomplete / invalid / failed), ``failing`` (mandatory requirements
not passing, ``sweep.candidates.ranking``), ``shortfall`` (worst mandatory
margin short of passing, in fractions of its limit; 0 passes), ``total_shortfall`` (their
sum), ``change`` (distance from the
base settings in normalised units) and ``error``.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pandas as pd

from compliance.files.atomic import write_bytes_atomic, write_text_atomic
from compliance.requirements.verdict import Severity, Status
from compliance.sweep.candidates.evaluate import judged
from compliance.sweep.candidates.ranking import rank_key
from compliance.sweep.candidates.runner import shortfall, total_shortfall

__all__ = ["best_index", "change", "pareto_front", "table", "tightest", "write_table"]


def change(adjust, base: dict, values: dict) -> float:
    """Normalised distance of ``values`` from ``base``: sqrt(sum(((v - v0) / span)^2))."""
    s = 0.0
    for a in adjust:
        p = a.param.path
        if p in values:
            s += ((values[p] - base[p]) / a.span) ** 2
    return math.sqrt(s)


def table(candidates: list[dict], rows: list[dict], req_ids: list[str], adjust=(), base=None) -> pd.DataFrame:
    """One row per candidate: settings, every requirement's value/margin/status, verdict."""
    recs = []
    for i, (values, row) in enumerate(zip(candidates, rows)):
        rec = {"candidate": i, **{k: float(v) for k, v in values.items()}}
        for rid in req_ids:
            r = row["requirements"].get(rid, {})
            rec[f"{rid}.value"] = r.get("value")
            rec[f"{rid}.margin"] = r.get("margin")
            rec[f"{rid}.margin_pct"] = r.get("margin_pct")
            rec[f"{rid}.status"] = r.get("status", None if judged(row) else row["status"])
        rec["status"] = row["status"]
        rec["shortfall"] = shortfall(row)
        rec["total_shortfall"] = total_shortfall(row)
        rec["failing"] = float(rank_key(row, 0.0)[0])
        rec["change"] = change(adjust, base, values) if base is not None else float("nan")
        rec["error"] = row.get("error")
        recs.append(rec)
    df = pd.DataFrame.from_records(recs)
    for c in df.columns:
        if c.endswith((".value", ".margin", ".margin_pct")):
            df[c] = pd.to_numeric(df[c], errors="coerce")
    return df


def tightest(df: pd.DataFrame, rows: list[dict], k: int = 2) -> list[str]:
    """The ``k`` mandatory requirements with the lowest median margin % over the candidates."""
    sev = {}
    for row in rows:
        for rid, r in row["requirements"].items():
            sev.setdefault(rid, r["severity"])
    scored = []
    for rid, s in sev.items():
        col = f"{rid}.margin_pct"
        if s == Severity.MANDATORY and col in df and df[col].notna().any():
            scored.append((float(df[col].median()), rid))
    return [rid for _, rid in sorted(scored)[:k]]


def pareto_front(df: pd.DataFrame, a: str, b: str) -> list[int]:
    """Candidates not dominated in (margin % of ``a``, margin % of ``b``), both maximised.

    Only candidates with both requirements evaluated (pass or fail) take part: a margin of a case
    that was not evaluated is no point of the front.
    """
    cols = [f"{a}.margin_pct", f"{b}.margin_pct"]
    judged = np.ones(len(df), dtype=bool)
    for r in (a, b):
        if f"{r}.status" in df:
            judged &= df[f"{r}.status"].isin((Status.PASS, Status.FAIL)).to_numpy()
    ok = df.loc[judged, cols].dropna()
    pts = ok.to_numpy()
    idx = ok.index.to_numpy()
    front = []
    for j, p in enumerate(pts):
        dominated = np.any(np.all(pts >= p, axis=1) & np.any(pts > p, axis=1))
        if not dominated:
            front.append(int(df.loc[idx[j], "candidate"]))
    return sorted(front, key=lambda c: -float(df.loc[df["candidate"] == c, f"{a}.margin_pct"].iloc[0]))


def best_index(df: pd.DataFrame) -> int | None:
    """A passing candidate with the smallest change, else the closest to passing.

    Ranked as the remedies search ranks (``sweep.candidates.ranking``): fewest failing mandatory
    requirements, then the smallest sum of shortfalls, then the smallest change.
    """
    if df.empty:
        return None
    ranked = df.sort_values(["failing", "total_shortfall", "change", "candidate"])
    top = ranked.iloc[0]
    return None if not math.isfinite(top["failing"]) else int(top["candidate"])


def write_table(df: pd.DataFrame, folder) -> dict:
    """Write ``results.parquet`` and ``results.csv`` atomically; returns their paths."""
    from pathlib import Path

    folder = Path(folder)
    buf = io.BytesIO()
    df.to_parquet(buf, index=False)
    write_bytes_atomic(folder / "results.parquet", buf.getvalue())
    write_text_atomic(folder / "results.csv", df.to_csv(index=False, float_format="%.6g"))
    return {"parquet": str(folder / "results.parquet"), "csv": str(folder / "results.csv")}
