"""Judged candidates kept on disk, so an interrupted search resumes where it stopped.

One JSON line per judged candidate in ``FOLDER/candidates.jsonl``: the key (a hash of the base
configuration as TOML, the requirement set and the candidate's settings to 12 significant
digits) and the row. A search run again with the same folder judges only what is not there;
a line cut short by an interruption is ignored. Rows of a task that failed are not kept.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

__all__ = ["CandidateStore"]


class CandidateStore:
    """Rows of judged candidates by key, appended to ``folder/candidates.jsonl``."""

    def __init__(self, folder):
        self.path = Path(folder) / "candidates.jsonl"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.rows: dict[str, dict] = {}
        self._context_keys: dict[int, str] = {}
        if self.path.exists():
            for line in self.path.read_text(encoding="utf-8").splitlines():
                try:
                    rec = json.loads(line)
                    self.rows[rec["key"]] = rec["row"]
                except (ValueError, KeyError, TypeError):
                    continue  # a line cut short by an interruption

    def _context_key(self, ctx) -> str:
        if id(ctx) not in self._context_keys:
            from compliance.model.config import plant_to_toml

            text = plant_to_toml(ctx.cfg) + json.dumps(ctx.reqset.as_dict(), sort_keys=True, default=str)
            self._context_keys[id(ctx)] = hashlib.sha256(text.encode()).hexdigest()
        return self._context_keys[id(ctx)]

    def key(self, ctx, values: dict) -> str:
        """The key of ``values`` judged in ``ctx``."""
        vals = {k: float(f"{float(v):.12g}") for k, v in sorted(values.items())}
        return hashlib.sha256((self._context_key(ctx) + json.dumps(vals)).encode()).hexdigest()

    def get(self, ctx, values: dict):
        """The stored row of ``values`` or None."""
        return self.rows.get(self.key(ctx, values))

    def add(self, ctx, pairs) -> None:
        """Append (values, row) pairs (failed tasks left out)."""
        lines = []
        for values, row in pairs:
            if row.get("status") == "failed":
                continue
            k = self.key(ctx, values)
            self.rows[k] = row
            lines.append(json.dumps({"key": k, "row": row}, default=str))
        if lines:
            with self.path.open("a", encoding="utf-8") as f:
                f.write("\n".join(lines) + "\n")
