"""Check a rendered report for text that overflows or overprints: every label inside its figure, no collisions.

Two readers of the same document:

- the HTML's inline SVG figures: each ``<text>`` (and ``<tspan>``) gets a box from the font's own
  metrics (DejaVu Sans, the font matplotlib measured with), its anchor, the translations of its
  groups and its rotation; a box outside the ``viewBox`` is a clipped label, two boxes of
  different labels that overlap are a collision ("command [V]speed [mm/s]");
- the PDF: every character's box (pdfplumber) must lie on its page, and characters of different
  words must not overlap (a table cell whose text runs into the next one, a legend over a label).

Used by ``tests/report/test_layout.py`` and by ``reports/examples/regenerate.py`` on every example.
"""

from __future__ import annotations

import functools
import re
import xml.etree.ElementTree as ET

_SVG_RE = re.compile(r"<svg\b.*?</svg>", re.S)
_TRANSLATE_RE = re.compile(r"translate\(\s*([-\d.e]+)[ ,]+([-\d.e]+)\s*\)")
_ROTATE_RE = re.compile(r"rotate\(\s*([-\d.e]+)(?:[ ,]+([-\d.e]+)[ ,]+([-\d.e]+))?\s*\)")
TOLERANCE = 0.6  # [pt] rounding of coordinates and metrics; a clipped label is off by several points
OVERLAP = 0.02  # share of the smaller box two labels may share (beyond a point of touching) before they collide
TOUCH = 1.0  # [pt] overlap in both directions that still counts as touching (ascenders, rounding)


@functools.lru_cache(maxsize=4096)
def _extent(text: str, size: float, bold: bool) -> tuple[float, float, float]:
    """Width, height and descent [pt] of ``text`` at ``size`` pt in DejaVu Sans."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    prop = FontProperties(family="DejaVu Sans", size=size, weight="bold" if bold else "normal")
    return text_to_path.get_text_width_height_descent(text, prop, ismath=False)


def _num(v, default=0.0) -> float:
    try:
        return float(str(v).replace("px", "").replace("pt", ""))
    except (TypeError, ValueError):
        return default


def _box(el, inherited: dict, dx: float, dy: float, text: str):
    """Axis-aligned box (x0, y0, x1, y1) of one text run in viewBox units.

    The element's ``transform`` is ``rotate(a cx cy)`` or ``translate(tx ty) rotate(a)`` (what
    matplotlib writes): corners are rotated, then translated, then moved by the groups' offsets.
    """
    import math

    attrs = {**inherited, **el.attrib}
    size = _num(attrs.get("font-size"), 10.0)
    w, h, d = _extent(text, size, str(attrs.get("font-weight", "")) in ("bold", "700"))
    x, y = _num(attrs.get("x")), _num(attrs.get("y"))
    shift = {"middle": 0.5, "end": 1.0}.get(attrs.get("text-anchor"), 0.0)
    corners = [(x - shift * w, y - (h - d)), (x + (1 - shift) * w, y - (h - d)), (x - shift * w, y + d), (x + (1 - shift) * w, y + d)]
    transform = attrs.get("transform", "") or ""
    rot = _ROTATE_RE.search(transform)
    if rot:
        a = math.radians(float(rot.group(1)))
        cx, cy = (float(rot.group(2)), float(rot.group(3))) if rot.group(2) else (0.0, 0.0)
        corners = [(cx + (px - cx) * math.cos(a) - (py - cy) * math.sin(a),
                    cy + (px - cx) * math.sin(a) + (py - cy) * math.cos(a)) for px, py in corners]
    tr = _TRANSLATE_RE.search(transform)
    tx, ty = (float(tr.group(1)), float(tr.group(2))) if tr else (0.0, 0.0)
    xs, ys = [c[0] + tx + dx for c in corners], [c[1] + ty + dy for c in corners]
    return (min(xs), min(ys), max(xs), max(ys))


def svg_text_boxes(svg: str) -> tuple[tuple[float, float, float, float], list[tuple[str, tuple]]]:
    """The ``viewBox`` of an SVG and ``(label, box)`` for each text run in it."""
    plain = re.sub(r"\sxmlns(:\w+)?=\"[^\"]*\"", "", svg)
    plain = re.sub(r"<(/?)[A-Za-z]+:", r"<\1", plain)  # prefixed elements (metadata) and attributes (xlink:href)
    plain = re.sub(r"\s[A-Za-z]+:([A-Za-z-]+)=", r" \1=", plain)
    root = ET.fromstring(plain)
    vb = tuple(float(v) for v in root.attrib.get("viewBox", "0 0 0 0").replace(",", " ").split())
    out: list = []

    def walk(el, inherited, dx, dy, group):
        tag = el.tag.rsplit("}", 1)[-1]
        m = _TRANSLATE_RE.search(el.attrib.get("transform", "") or "") if tag == "g" else None
        if m:
            dx, dy = dx + float(m.group(1)), dy + float(m.group(2))
        inh = {**inherited, **{k: v for k, v in el.attrib.items() if k.startswith("font") or k == "text-anchor"}}
        if tag == "text":
            spans = [c for c in el if c.tag.rsplit("}", 1)[-1] == "tspan"]
            label = "".join(el.itertext()).strip()
            for sp in spans or [el]:
                t = (sp.text or "").strip()
                if t:
                    out.append((f"{group}:{label}", _box(sp, {**inh, **{k: v for k, v in el.attrib.items() if k != "transform"}}
                                                           if sp is not el else inh, dx, dy, t)))
            return
        for i, ch in enumerate(el):
            walk(ch, inh, dx, dy, group if tag != "text" else group)

    for k, ch in enumerate(root):
        walk(ch, {}, 0.0, 0.0, str(k))
    return vb, out


def _overlap(a, b, touch: float = 0.0) -> float:
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    if w <= touch or h <= touch:
        return 0.0
    small = min((a[2] - a[0]) * (a[3] - a[1]), (b[2] - b[0]) * (b[3] - b[1])) or 1.0
    return w * h / small


def svg_problems(svg: str, name: str = "figure") -> list[str]:
    """Labels outside the viewBox and labels that collide, in one figure."""
    vb, boxes = svg_text_boxes(svg)
    if len(vb) != 4:
        return [f"{name}: no viewBox"]
    x0, y0, x1, y1 = vb[0], vb[1], vb[0] + vb[2], vb[1] + vb[3]
    out = []
    for label, b in boxes:
        if b[0] < x0 - TOLERANCE or b[1] < y0 - TOLERANCE or b[2] > x1 + TOLERANCE or b[3] > y1 + TOLERANCE:
            out.append(f"{name}: '{label.split(':', 1)[1]}' outside the viewBox ({b[0]:.1f} {b[1]:.1f} {b[2]:.1f} {b[3]:.1f} "
                       f"vs {x0:g} {y0:g} {x1:g} {y1:g})")
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            (la, a), (lb, b) = boxes[i], boxes[j]
            if la != lb and _overlap(a, b, TOUCH) > OVERLAP:
                out.append(f"{name}: '{la.split(':', 1)[1]}' collides with '{lb.split(':', 1)[1]}'")
    return out


def html_problems(html: str) -> list[str]:
    """Layout problems of every inline SVG figure of an HTML report (the DRAFT watermark has no text)."""
    out = []
    for k, m in enumerate(_SVG_RE.finditer(html)):
        fid = re.search(r'id="(fig-\d+)', html[max(0, m.start() - 200):m.start()])
        out += svg_problems(m.group(0), fid.group(1) if fid else f"svg #{k + 1}")
    return out


def pdf_problems(path) -> list[str]:
    """Characters off their page, or overprinting characters of other words, in a PDF."""
    import pdfplumber

    out = []
    with pdfplumber.open(str(path)) as pdf:
        for n, page in enumerate(pdf.pages, 1):
            chars = [c for c in page.chars if c["text"].strip()]
            for c in chars:
                if c["x0"] < -TOLERANCE or c["top"] < -TOLERANCE or c["x1"] > page.width + TOLERANCE \
                        or c["bottom"] > page.height + TOLERANCE:
                    out.append(f"page {n}: '{c['text']}' off the page")
            out += [f"page {n}: {p}" for p in _overprints(chars)]
    return out


BODY_PAGES_MAX = 28  # the plant-A body (sign-off page to the signatures of section 7): a document a signer reads in one sitting (our own limit; 28 since the in-service strokes judge start delay, time to the end stop and cushion beside the stroke times, and the constant-load variants have their page)


def body_pages(path) -> dict:
    """Pages of a compliance report PDF: ``{"body", "appendix", "total"}``.

    The body ends before the page whose text has the heading "Appendix" on a line of its own
    (a report without an appendix is all body).
    """
    import pdfplumber

    with pdfplumber.open(str(path)) as pdf:
        texts = [p.extract_text() or "" for p in pdf.pages]
    body = next((i for i, t in enumerate(texts) if re.search(r"^\s*Appendix\s*$", t, re.M)), len(texts))
    return {"body": body, "appendix": len(texts) - body, "total": len(texts)}


def sign_off_fits(path) -> bool:
    """Whether a compliance report's sign-off page (page 1, ending with the signature blocks) fits one page."""
    import pdfplumber

    with pdfplumber.open(str(path)) as pdf:
        if len(pdf.pages) < 2:
            return True
        first, second = (pdf.pages[i].extract_text() or "" for i in (0, 1))
    return "Accepted for the plant owner" in first and "Accepted for the plant owner" not in second


def _overprints(chars: list) -> list[str]:
    """Pairs of characters on different text lines or far apart in one line that overlap."""
    grid: dict = {}
    for i, c in enumerate(chars):
        for gx in range(int(c["x0"] // 20), int(c["x1"] // 20) + 1):
            grid.setdefault((gx, int(c["top"] // 20)), []).append(i)
    seen, out = set(), []
    for idx in grid.values():
        for a in range(len(idx)):
            for b in range(a + 1, len(idx)):
                i, j = idx[a], idx[b]
                if (i, j) in seen or abs(i - j) == 1:  # neighbours in the text stream may kern into each other
                    continue
                seen.add((i, j))
                ci, cj = chars[i], chars[j]
                box = lambda c: (c["x0"], c["top"], c["x1"], c["bottom"])  # noqa: E731
                if _overlap(box(ci), box(cj)) > 0.35:
                    out.append(f"'{ci['text']}' at ({ci['x0']:.0f}, {ci['top']:.0f}) overprints '{cj['text']}'")
    return out[:20]


def main(argv=None) -> int:
    """``python -m compliance.report.layout_check REPORT.html|REPORT.pdf ...``: print the problems; exit 1 if any."""
    import argparse
    from pathlib import Path

    ap = argparse.ArgumentParser(description="Clipped or overprinted text in rendered reports (HTML figures, PDF pages); "
                                             "for a PDF also its body and appendix pages.")
    ap.add_argument("reports", nargs="+", type=Path, metavar="REPORT", help="an .html or .pdf report")
    n = 0
    for path in ap.parse_args(argv).reports:
        if path.suffix == ".pdf":
            problems = pdf_problems(path)
            print(f"{path}: " + ", ".join(f"{k} {v}" for k, v in body_pages(path).items()) + " pages")
        else:
            problems = html_problems(path.read_text(encoding="utf-8"))
        n += len(problems)
        print("\n".join(f"{path}: {p}" for p in problems) or f"{path}: clean")
    return 1 if n else 0


if __name__ == "__main__":
    raise SystemExit(main())
