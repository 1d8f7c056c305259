"""Check a report's text for what a signer cannot follow: repository file names, module names, "seed", dead references.

A report stands on its own: it may name its inputs (the configuration, requirement files,
results and recordings it cites with their sha256) but no other file of the code base, no
Python module, no internal name of a source paper ("seed ...") and no section, appendix or
figure that the document does not contain. Used by ``tests/report/test_report_text.py`` and
``reports/examples/regenerate.py``.
"""

from __future__ import annotations

import html.parser
import re
from pathlib import Path

_SECTION_RE = re.compile(r"\bsections?\s+(\d+(?:\.\d+)?)", re.I)
_APPENDIX_RE = re.compile(r"\bappendix\s+([A-Z])\b")
_FIGURE_RE = re.compile(r"\bFigure\s+(\d+)\b")
_MODULE_RE = re.compile(r"\b(?:compliance|govcheck)\.[a-z_]+\b|\b[a-z_]+\.py\b|\b[\w-]+\.j2\b")
_SEED_RE = re.compile(r"\bseeds?\b", re.I)
_EXTENSIONS = (".md", ".py", ".toml", ".csv", ".json", ".gz", ".css", ".j2", ".txt", ".mat", ".cfg", ".parquet")


class _Text(html.parser.HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.parts, self.headings, self._skip, self._heading = [], [], 0, None

    def handle_starttag(self, tag, attrs):
        if tag in ("style", "script", "title"):
            self._skip += 1
        if tag in ("h1", "h2", "h3", "h4"):
            self._heading = []

    def handle_endtag(self, tag):
        if tag in ("style", "script", "title"):
            self._skip -= 1
        if tag in ("h1", "h2", "h3", "h4") and self._heading is not None:
            self.headings.append(" ".join("".join(self._heading).split()))
            self._heading = None

    def handle_data(self, data):
        if not self._skip:
            self.parts.append(data)
            if self._heading is not None:
                self._heading.append(data)


def html_text(html: str) -> tuple[str, list[str]]:
    """Visible text of an HTML report (figure labels included) and its headings."""
    p = _Text()
    p.feed(html)
    return " ".join(" ".join(p.parts).split()), p.headings


def repository_names(root) -> set[str]:
    """File names of the code base that a report must not mention (its documents, modules, data files)."""
    root = Path(root)
    names = set()
    for folder in ("docs", "compliance", "models", "requirements", "tests", "benchmarks", "reports"):
        for f in (root / folder).rglob("*"):
            if f.is_file() and f.suffix in _EXTENSIONS and "__pycache__" not in f.parts:
                if folder == "reports" and f.suffix != ".py":
                    continue  # generated outputs: a report may name its own sibling outputs
                names.add(f.name)
    names.update(n for n in ("README.md", "pyproject.toml") if (root / n).exists())
    return names


def text_problems(text: str, headings: list[str], *, repo_names=(), allowed=()) -> list[str]:
    """Repository file names (other than the ``allowed`` inputs), module names, "seed", dead references.

    ``headings``: the document's headings (``"3.1 Departures from the test code"``, ``"Appendix"``,
    ``"A. Configuration parameters"``); a reference "section 3.1" needs a heading that starts
    with "3.1", "appendix A" a heading that starts with "A.", "Figure 7" a caption "Figure 7:".
    """
    out = []
    clean = text
    for a in sorted({str(x) for x in allowed if x}, key=len, reverse=True):
        clean = clean.replace(a, " ")
    for name in sorted(repo_names):
        if re.search(r"(?<![\w.-])" + re.escape(name) + r"(?![\w-])", clean):
            out.append(f"names a file of the code base: {name}")
    for m in sorted(set(_MODULE_RE.findall(clean))):
        out.append(f"names a module or template: {m}")
    for m in sorted({m.group(0) for m in _SEED_RE.finditer(clean)}):
        ctx = clean[max(0, clean.find(m) - 40):clean.find(m) + 40]
        out.append(f"says '{m}' (an internal name): ...{ctx}...")
    numbers = {h.split()[0].rstrip(".") for h in headings if h and h[0].isdigit()}
    letters = {h[0] for h in headings if re.match(r"[A-Z]\.\s", h)}
    for m in _SECTION_RE.finditer(text):
        n = m.group(1)
        if "paper" in text[max(0, m.start() - 12):m.start()] or text[m.end():m.end() + 20].startswith(" of the"):
            continue  # a section of a cited paper or standard, not of this document
        if n not in numbers:
            out.append(f"refers to section {n}, which the document does not have")
            numbers.add(n)
    for a in sorted(set(_APPENDIX_RE.findall(text))):
        if a not in letters:
            out.append(f"refers to appendix {a}, which the document does not have")
    figures = set(re.findall(r"\bFigure\s+(\d+):", text))
    for f in sorted(set(_FIGURE_RE.findall(text)) - figures):
        out.append(f"refers to Figure {f}, which the document does not have")
    return out
