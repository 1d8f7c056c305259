"""The "What would make it pass" / "Tolerance yield" report section as a standalone HTML page.

The compliance report includes ``report/templates/_remedies.html.j2`` for a results file that
carries ``remedies`` or ``tolerance_yield``; a sweep also writes the section on its own
(``summary.html``) so the answer can be read without rendering a whole report.
"""

from __future__ import annotations

from importlib import resources

import jinja2

__all__ = ["section_html"]

TEMPLATES = resources.files("compliance.report") / "templates"


def section_html(title: str, remedies: dict | None = None, tolerance_yield: dict | None = None) -> str:
    """A self-contained HTML page with the report's stylesheet and the remedies/yield partial."""
    from compliance.units.formatting import fmt_margin_pct, fmt_si

    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(TEMPLATES)), autoescape=True,
                             trim_blocks=True, lstrip_blocks=True)
    env.filters["si"] = lambda v, u: fmt_si(v, u or "")  # as the report's environment: SI prefixes, typeset units
    env.filters["margin"] = lambda v: fmt_margin_pct(v) or "\u2013"  # capped, with a minus sign, as in the report
    body = env.get_template("_remedies.html.j2").render(remedies=remedies, tolerance_yield=tolerance_yield)
    css = (TEMPLATES / "style.css").read_text(encoding="utf-8")
    page = env.from_string('<!doctype html>\n<html lang="en"><head><meta charset="utf-8"><title>{{ title }}</title>'
                           "<style>{{ css }}</style></head><body><main><h1>{{ title }}</h1>{{ body }}</main></body></html>\n")
    return page.render(title=title, css=jinja2.utils.markupsafe.Markup(css), body=jinja2.utils.markupsafe.Markup(body))
