"""Matplotlib figures -> self-contained inline SVG fragments for the report.

Figures are drawn with matplotlib (Agg backend selected, output format SVG), text kept as
``<text>`` with a generic font stack (``'DejaVu Sans', ..., sans-serif``: any viewer has a
sans-serif), and post-processed so that many figures can live in one HTML document:

- the XML declaration, DOCTYPE, ``<metadata>`` and comments are dropped (matplotlib copies
  label text into comments; they are useless in a report);
- namespace declarations are dropped: the HTML parser (browsers, WeasyPrint's html5lib)
  puts an inline ``<svg>`` into the SVG namespace by itself, and the report then contains no
  ``http:`` string at all (``render.py`` restores them for the PDF's data URIs);
- every ``id`` is prefixed with the figure's own prefix (and every ``#id`` reference with it),
  so marker and clip-path ids of different figures cannot collide;
- ``style="..."`` becomes presentation attributes and matplotlib's ``<style>`` rule becomes
  inherited attributes on the root (a rule in an inline SVG would style the whole page);
- id-only ``<g>`` wrappers are flattened (fewer nodes: WeasyPrint draws SVG in Python);
- the fixed ``width``/``height`` in pt are removed so CSS sizes the figure (``width: 100 %``),
  the ``viewBox`` keeps its aspect ratio.

Captions and titles are HTML (escaped by jinja2). The little text from input files that a
figure draws (operating-point labels of the linear analysis) goes through :func:`plain`, and
matplotlib writes all text XML-escaped.
"""

from __future__ import annotations

import functools
import io
import re
import xml.etree.ElementTree as ET

import matplotlib
from matplotlib.figure import Figure

# Figures are made with matplotlib.figure.Figure, not pyplot: no backend is selected or
# switched (importing the report never changes a user's interactive backend), nothing is
# kept in pyplot's global figure registry, and savefig(format="svg") prints with the SVG
# canvas - the same headless path as Agg, without a display.

# one look for every figure of the report
STYLE = {
    "svg.fonttype": "none",  # text as <text> with a generic font fallback (see FONT_STACK): 3x faster in WeasyPrint than glyph paths
    "svg.hashsalt": "govcheck",  # deterministic ids (then prefixed per figure)
    "font.family": "DejaVu Sans",  # shipped with matplotlib itself
    "font.size": 7.5,
    "axes.titlesize": 8.0,
    "axes.labelsize": 7.5,
    "axes.linewidth": 0.6,
    "axes.edgecolor": "#5b6770",
    "axes.labelcolor": "#1f2a33",
    "axes.grid": True,
    "grid.color": "#d9dee3",
    "grid.linewidth": 0.5,
    "xtick.major.size": 0.0,  # the grid marks the ticks; zero-size ticks are not written (a quarter of the SVG nodes)
    "ytick.major.size": 0.0,
    "xtick.major.pad": 3.0,
    "ytick.major.pad": 3.0,
    "xtick.labelsize": 7.0,
    "ytick.labelsize": 7.0,
    "xtick.color": "#3a464f",
    "ytick.color": "#3a464f",
    "legend.fontsize": 6.8,
    "legend.frameon": False,
    "lines.linewidth": 1.0,
    "path.simplify": True,
    "path.simplify_threshold": 0.5,
    "figure.dpi": 100,
}

# report palette (colour-blind safe: Okabe-Ito)
COLORS = {
    "position": "#0072B2",
    "reference": "#555555",
    "error": "#D55E00",
    "command": "#009E73",
    "pressure_a": "#0072B2",
    "pressure_b": "#E69F00",
    "supply": "#777777",
    "band": "#009E73",
    "mark": "#CC79A7",
    "window": "#56B4E9",
    "limit": "#B22222",
    "recorded": "#222222",
    "before": "#E69F00",
    "after": "#0072B2",
}

# one width for every figure (A4 text width 170 mm); heights from a small fixed set
WIDTH_IN = 6.7
HEIGHTS_IN = {"trace": 5.4, "trace_compact": 3.2, "trace_short": 2.6, "map": 2.9, "bode": 3.6, "validation": 4.2}

# matplotlib names the one font it measured with; viewers without it fall back to a generic sans
FONT_STACK = "'DejaVu Sans', 'Liberation Sans', Arial, Helvetica, sans-serif"
_GEOMETRY_RE = re.compile(r'\s(?:d|x|y|x1|x2|y1|y2|width|height|transform)="[^"]*"')
_SHORT_RE = re.compile(r"(\d\.\d\d)\d+")
_ID_RE = re.compile(r'\sid="([^"]+)"')
_REF_RE = re.compile(r'(\sid="|href="#|url\(#)([^")]+)')


_XLINK_NS = "http://www.w3.org/1999/xlink"


def styled(fn):
    """Run a figure-building function inside the report's matplotlib style."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with matplotlib.rc_context(STYLE):
            return fn(*args, **kwargs)

    return wrapper


def plain(text) -> str:
    """Text for a matplotlib label, drawn literally (``$`` would start mathtext)."""
    return str(text).replace("$", r"\$")


def new_figure(kind: str, nrows: int = 1, ncols: int = 1, **kw):
    """A figure of the report's fixed width and the height of its ``kind``."""
    fig = Figure(figsize=(WIDTH_IN, HEIGHTS_IN[kind]))
    axes = fig.subplots(nrows, ncols, **kw)
    return fig, axes


def to_svg(fig, prefix: str) -> str:
    """Render ``fig`` to an inline SVG fragment with ids prefixed by ``prefix`` and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    prefix : str
        Unique per figure in the document, made of ``[A-Za-z0-9_-]`` (not user text).

    Returns
    -------
    str
        ``<svg ...>...</svg>`` ready to be embedded as-is in HTML.
    """
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_-]*", prefix):
        raise ValueError(f"bad svg id prefix {prefix!r}")
    buf = io.StringIO()
    # tight: the viewBox is the extent of everything drawn (labels, legends above the axes), so no
    # text can fall outside it whatever the labels' lengths; the CSS scales the figure to the text width
    fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None}, bbox_inches="tight", pad_inches=0.03)
    return clean_svg(buf.getvalue(), prefix)


def clean_svg(text: str, prefix: str) -> str:
    """Post-process matplotlib's SVG text for inline use (see the module docstring)."""
    root = ET.fromstring(text[text.index("<svg"):])  # drops the comments
    _flatten(root)
    s = ET.tostring(root, encoding="unicode")
    head_end = s.index(">")
    head = re.sub(r'\s(width|height)="[^"]*"', "", s[:head_end])
    # the defaults matplotlib set with a <style> rule, as inherited attributes (a rule would also
    # hit the HTML page around an inline SVG, and would beat the presentation attributes)
    s = (head + ' class="figure-svg" preserveAspectRatio="xMidYMid meet" stroke-linejoin="round" stroke-linecap="butt"'
         + s[head_end:])
    s = s.replace('font-family="\'DejaVu Sans\'"', 'font-family="' + FONT_STACK + '"')
    s = re.sub(r' transform="rotate\(-0 [-0-9.e ]+\)"', "", s)  # identity rotations on every label
    # coordinates to 0.01 of a viewBox unit (1/100 pt: invisible), in geometry attributes only -
    # never in text, where "0.125" is a tick label
    s = _GEOMETRY_RE.sub(lambda m: _SHORT_RE.sub(r"\1", m.group(0)), s)
    ids = set(_ID_RE.findall(s))
    s = _REF_RE.sub(lambda m: m.group(1) + (prefix + "-" + m.group(2) if m.group(2) in ids else m.group(2)), s)
    # collapse the path data whitespace matplotlib writes one point per line
    s = re.sub(r" \n(?=[MLCQZz])", " ", s)
    return s.strip()


# CSS properties that SVG also accepts as presentation attributes (same name, same value syntax)
_PRESENTATION = frozenset((
    "fill", "fill-opacity", "fill-rule", "stroke", "stroke-width", "stroke-linecap", "stroke-linejoin",
    "stroke-dasharray", "stroke-dashoffset", "stroke-opacity", "stroke-miterlimit", "opacity", "clip-path",
    "font-size", "font-family", "font-weight", "font-style", "text-anchor", "dominant-baseline",
))


def _style_to_attributes(el) -> None:
    """``style="fill: none; stroke: #000"`` -> ``fill="none" stroke="#000"``.

    Same picture in every viewer, and WeasyPrint need not run its CSS tokenizer over ~10^4
    style attributes per report (a third of its SVG drawing time otherwise). Properties that have no
    presentation attribute stay in ``style``.
    """
    style = el.attrib.pop("style", None)
    if not style:
        return
    rest = []
    for decl in style.split(";"):
        if ":" not in decl:
            continue
        k, v = (x.strip() for x in decl.split(":", 1))
        if k in _PRESENTATION and k not in el.attrib:
            el.attrib[k] = v
        elif k:
            rest.append(f"{k}: {v}")
    if rest:
        el.attrib["style"] = "; ".join(rest)


def _flatten(el) -> None:
    """Drop ``<metadata>``, empty ``<defs>`` and id-only ``<g>`` wrappers (children kept).

    matplotlib nests every tick, label and line in id-only groups; a viewer draws the same
    picture without them, and WeasyPrint's SVG renderer is roughly linear in node count.
    """
    el.tag = el.tag.rsplit("}", 1)[-1]  # plain names: the HTML parser puts <svg> in its namespace
    _style_to_attributes(el)
    for k in [k for k in el.attrib if k.startswith("{")]:
        el.attrib[("xlink:" if k.startswith("{" + _XLINK_NS) else "") + k.rsplit("}", 1)[-1]] = el.attrib.pop(k)
    for ch in list(el):
        _flatten(ch)
    new = []
    for ch in list(el):
        tag = ch.tag.rsplit("}", 1)[-1]
        if tag == "style":  # matplotlib's '*{stroke-linejoin: round; stroke-linecap: butt}': see clean_svg
            continue
        if tag == "metadata" or (tag == "defs" and len(ch) == 0):
            continue
        if tag == "g" and set(ch.attrib) <= {"id"}:
            new.extend(list(ch))
        else:
            new.append(ch)
    el[:] = new


def message_axes(ax, text: str) -> None:
    """Mark an axes as intentionally empty with a short grey message."""
    ax.set_xticks([])
    ax.set_yticks([])
    ax.grid(False)
    for sp in ax.spines.values():
        sp.set_color("#c8ced3")
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="#6b7780", fontsize=7.5)


@functools.lru_cache(maxsize=1)
def draft_mark_svg() -> str:
    """The DRAFT watermark as an SVG of outlined glyphs (paths, no text: it never enters the extracted text)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.path import Path as MPath
    from matplotlib.textpath import TextPath

    path = TextPath((0, 0), "DRAFT", size=100, prop=FontProperties(family="DejaVu Sans", weight="bold"))
    ext = path.get_extents()
    parts = []
    for verts, code in path.iter_segments(simplify=False, curves=True):
        pts = " ".join(f"{x - ext.x0:.1f} {ext.y1 - y:.1f}" for x, y in verts.reshape(-1, 2))
        parts.append({MPath.MOVETO: "M", MPath.LINETO: "L", MPath.CURVE3: "Q", MPath.CURVE4: "C",
                      MPath.CLOSEPOLY: "Z"}[code] + ("" if code == MPath.CLOSEPOLY else " " + pts))
    w, h = ext.width, ext.height
    return (f'<svg viewBox="0 0 {w:.0f} {h:.0f}" class="draft-svg"><path d="{" ".join(parts)}" '
            'fill="#b42318" fill-opacity="0.10"/></svg>')
