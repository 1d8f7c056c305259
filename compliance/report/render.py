"""Render compliance and validation reports: one self-contained HTML file and its PDF.

The HTML is rendered with jinja2 (autoescaping on: every name from a user file is escaped),
CSS inlined, figures inline SVG; it references nothing outside itself. The PDF is the same
document laid out by WeasyPrint (A4, running header with the plant name, page numbers, table
of contents with page numbers); there the figures are the same SVG passed as data URIs, which
WeasyPrint draws without running its HTML cascade over every SVG node (~20x faster).

Writing is atomic: everything is rendered in memory first, then each file is written to a
temporary file in its target folder and moved over the target with ``os.replace``; a failed
render leaves no partial file and any previous report intact.
"""

from __future__ import annotations

import base64
import datetime as _dt
import platform
import threading
import time
from importlib import resources
from pathlib import Path

import jinja2

from compliance.version import __version__
from compliance.errors import InputError
from compliance.files.atomic import write_bytes_atomic
from compliance.files.display import display_path
from compliance.files.reproducible import fixed_created, is_reproducible
from compliance.report import acceptance as A
from compliance.report import content as C
from compliance.report import signoff as S
from compliance.report.analysis_sections import linear_section, validation_section
from compliance.report.requirement_pages import requirement_pages
from compliance.results.validation import ValidationRecord
from compliance.presentation.numbers import fmt_date, fmt_margin_pct, fmt_num, fmt_si, status_word, unit_text

TEMPLATES = resources.files("compliance.report") / "templates"
VALIDATION_SCHEMA = "govcheck.validation/1"
_DRAW_LOCK = threading.Lock()


# --------------------------------------------------------------------------- figures
def _draw(spec: dict, valve: dict | None = None) -> str:
    from compliance.report import figures, figures_linear

    k = spec["kind"]
    if k == "trace" and spec["trace"].kind == "path3d":
        from compliance.report.figures_tracking import path_figure  # plant B's 3-D path overlay and per-axis errors

        return path_figure(spec["trace"], spec["id"])
    if k == "trace":
        return figures.trace_figure(spec["trace"], spec["marks"], spec["run_kind"], spec["id"],
                                    tolerance=spec.get("tolerance"), valve=valve, speed_limit=spec.get("speed_limit"),
                                    compact=spec.get("compact", False), tau_window=spec.get("tau_window"))
    if k in ("strokes", "dead_band"):
        from compliance.report import figures_judged

        if k == "strokes":
            return figures_judged.stroke_pair_figure(spec["traces"], spec["marks"], spec["id"])
        return figures_judged.dead_band_figure(spec["trace"], spec["id"], spec.get("limit"))
    if k == "map":
        return figures_linear.map_figure(spec["omap"], spec["name"], spec["id"])
    if k == "bode":
        return figures_linear.bode_figure(spec["analyses"], spec["id"])
    if k == "poles":
        return figures_linear.pole_figure(spec["analyses"], spec["id"])
    if k == "waveform":
        sc = spec.get("scale", 1.0)
        series = [(lab, t, [float("nan") if v is None else v * sc for v in y], role)
                  for lab, t, y, role in spec["series"] if t is not None and y is not None]
        return figures.waveform_figure(series, spec["id"], ylabel=spec["ylabel"], windows=spec.get("windows") or (),
                                       smooth=spec.get("smooth", False))
    raise ValueError(f"unknown figure kind {k!r}")


def _draw_chunk(context, indices):
    specs, valve = context
    with _DRAW_LOCK:  # matplotlib is not thread-safe: a Dask worker with several threads draws one figure at a time
        return [(i, _draw(specs[i], valve)) for i in indices]


def draw_figures(specs: list[dict], valve: dict | None = None, workers: int | None = None,
                 scheduler: str | None = None) -> dict:
    """Draw every figure spec -> ``{id: svg}``; in parallel on the one executor when it pays (or on Dask)."""
    from compliance.processes import available_cores, map_tasks

    n = len(specs)
    workers = max(1, min(available_cores() if workers is None else workers, n // 4))  # a worker pays off from ~4 figures (fork + import ~0.2 s)
    chunks = [list(range(w, n, workers)) for w in range(workers)] if n else []  # interleaved: similar costs per worker
    parts, stats = map_tasks(_draw_chunk, (specs, valve), chunks, workers=workers, scheduler=scheduler, progress=False,
                             label="figures", retries=0)
    stats.raise_if_failed()
    return {specs[i]["id"]: svg for part in parts for i, svg in part}


def _svg_data_uri(svg: str) -> str:
    """A standalone SVG document as a data URI (namespaces restored) for WeasyPrint."""
    doc = svg.replace("<svg", '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink"', 1)
    return "data:image/svg+xml;base64," + base64.b64encode(doc.encode("utf-8")).decode("ascii")


# --------------------------------------------------------------------------- templates
def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATES)),
        autoescape=True,  # every template, whatever its extension: user strings never become markup
        # lenient: an optional key a producer left out renders as nothing, never a crash
        undefined=jinja2.ChainableUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters.update(status_class=C.status_class, status_word=status_word, num=fmt_num, unit=unit_text,
                       setting=C.setting_text, words=C.reader_text, si=lambda v, u: fmt_si(v, u or ""),
                       margin=lambda v: fmt_margin_pct(v) or "\u2013")
    return env


def _css() -> str:
    return (TEMPLATES / "style.css").read_text(encoding="utf-8")


def _render(template: str, ctx: dict, svgs: dict, for_pdf: bool) -> str:
    env = _environment()

    def figure(fid):
        svg = svgs.get(fid)
        if svg is None:
            return jinja2.utils.markupsafe.Markup('<p class="missing">figure not available</p>')
        if for_pdf:
            return jinja2.utils.markupsafe.Markup(f'<img class="figure-img" alt="" src="{_svg_data_uri(svg)}">')
        return jinja2.utils.markupsafe.Markup(svg)  # our own SVG, user text never inside (see svg.py)

    from compliance.report.svg import draft_mark_svg

    Markup = jinja2.utils.markupsafe.Markup
    draft = {"svg": Markup(draft_mark_svg()), "uri": Markup(_svg_data_uri(draft_mark_svg()))}
    return env.get_template(template).render(**ctx, css=Markup(_css()), figure=figure, for_pdf=for_pdf, draft=draft)


def _pdf_bytes(html: str) -> bytes:
    import logging

    import weasyprint
    from weasyprint.urls import URLFetcher

    logging.getLogger("weasyprint").setLevel(logging.ERROR)  # font-subsetting chatter
    # data: URIs only (the figures): the document is self-contained by construction, and a
    # stray reference fails the render instead of reaching the network or the disk
    fetcher = URLFetcher(allowed_protocols=("data",), fail_on_errors=True)
    return weasyprint.HTML(string=html, base_url=None, url_fetcher=fetcher).write_pdf()


# --------------------------------------------------------------------------- writing
def _check_target(path, flag: str) -> Path:
    p = Path(path)
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(f"{flag} {p}: folder '{folder}' does not exist")
    if p.is_dir():
        raise InputError(f"{flag} {p}: is a folder; expected a file name")
    return p


def _emit(template: str, ctx: dict, svgs: dict, html_path, pdf_path) -> dict:
    """Render HTML and PDF fully in memory, then write both atomically; returns timings [s]."""
    t0 = time.perf_counter()
    html = _render(template, ctx, svgs, for_pdf=False) if html_path else None
    t1 = time.perf_counter()
    pdf = _pdf_bytes(_render(template, ctx, svgs, for_pdf=True)) if pdf_path else None
    t2 = time.perf_counter()
    if html is not None:
        write_bytes_atomic(html_path, html.encode("utf-8"))
    if pdf is not None:
        write_bytes_atomic(pdf_path, pdf)
    return {"html": t1 - t0, "pdf": t2 - t1}


def _now(created: str | None = None, reproducible: bool = False) -> str:
    """When the report was rendered; the results' fixed ``created`` for a reproducible run."""
    if reproducible or is_reproducible():
        return created or fixed_created()
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _common(versions, created: str | None = None, reproducible: bool = False) -> dict:
    v = dict(versions or {})
    v.setdefault("govcheck", __version__)
    v.setdefault("python", platform.python_version())
    import matplotlib
    import weasyprint

    v.setdefault("matplotlib (report)", matplotlib.__version__)
    v.setdefault("weasyprint (report)", weasyprint.__version__)
    v.setdefault("jinja2 (report)", jinja2.__version__)
    return {"versions": v, "rendered": fmt_date(_now(created, reproducible)), "govcheck_version": __version__}


# --------------------------------------------------------------------------- API
APPENDIX_LEVELS = ("none", "summary", "full")


def build_report(results, workers: int | None = None, appendix: str = "summary",
                 document: dict | None = None, scheduler: str | None = None) -> tuple[dict, dict]:
    """Check the results and build the template context and the figures (no file written).

    ``results``: a :class:`~compliance.results.CheckResult` (a results dict is read into one here).
    ``appendix``: ``none`` (sign-off page, requirement pages, linear and validation sections),
    ``summary`` (+ configuration, requirement file, command, versions) or ``full`` (+ every run
    with its figures). ``document``: see :func:`compliance.report.signoff.document_control`.
    """
    if appendix not in APPENDIX_LEVELS:
        raise InputError(f"--appendix {appendix}: expected one of {', '.join(APPENDIX_LEVELS)}")
    res = C.as_result(results)
    pages, specs = requirement_pages(res, 1)
    sections, run_specs = C.procedure_sections(res, len(specs) + 1) if appendix == "full" else ([], [])
    specs += run_specs
    lin_ctx, lin_specs = linear_section(res.linear_section, len(specs) + 1, res)
    validation = ValidationRecord.from_dict(res.validation, "results.validation") if res.validation else None
    val_ctx, val_specs = validation_section(validation, len(specs) + len(lin_specs) + 1)
    svgs = draw_figures(specs + lin_specs + val_specs, C.valve_marks(res), workers, scheduler)
    plant = res.plant
    ctx = {
        **_common(res.versions, res.created, bool(res.reproducible)),
        "plant": plant,
        "identity": plant.identity,
        "rs": res.requirement_set,
        "summary": res.summary,
        "verdict": res.summary.status,
        "qualified": S.qualified_verdict(res),
        "created": fmt_date(res.created),
        "rows": C.summary_rows(res),
        "basis": S.basis(res),
        "failures": S.failures(res),
        # page 1 beyond the verdict word: what is not met, the model's evidence, stability, the requirement set
        "not_met": S.mandatory_not_met(res, S.remedy_lines(res.remedies)),
        "advisory": S.advisory_failures(res),
        "evidence": S.evidence_block(res),
        "stability": res.stability,
        "findings": S.findings_lines(res),
        "results_findings": S.finding_groups(res.findings),
        "not_evaluated": S.not_evaluated(res),
        "assumptions": S.assumptions(res),
        "doc": S.document_control(res, document),
        "scope": A.scope(res),
        "conditions": A.conditions(res),
        "method": A.method_rows(res),
        "not_tested": A.not_tested(res),
        "code_deviations": A.code_deviations(res),
        "conclusions": A.conclusions(res),
        "parties": A.parties(plant.identity),
        "remedies": res.remedies,
        "pages": pages,
        "appendix": appendix,
        "sections": sections,
        "linear": lin_ctx,
        "validation": val_ctx,
        **dict(zip(("evidence_sources", "evidence_contradicted"), A.evidence_sections(res))),
        "parameters": C.parameter_rows(res),
        "options": sorted(plant.options.items()),
        "effects": plant.effects,
        "load_curve": plant.load_curve,
        "provenance": sorted(plant.provenance.items()),
        "command": C.command_text(res),
        "timing": res.timing,
    }
    return ctx, svgs


def render_report(results, html_path=None, pdf_path=None, *, workers: int | None = None,
                  appendix: str = "summary", document: dict | None = None, scheduler: str | None = None) -> None:
    """Render the compliance report of a ``govcheck check`` results dict.

    Parameters
    ----------
    results : CheckResult or dict
        The result of ``compliance.check`` (or its JSON object, schema ``govcheck-results/1``,
        docs/results-schema.md), optionally with ``linear`` (``govcheck linear --json``) and
        ``validation`` (``compliance.validation.validate.validate``) sections.
    html_path, pdf_path : path, optional
        Where to write the HTML and the PDF; at least one.
    workers : int, optional
        Processes drawing figures (default: the available cores).
    scheduler : str, optional
        Draw the figures on Dask instead (``local:N`` or ``tcp://host:port``).
    appendix : {"none", "summary", "full"}
        What follows the body: nothing; the configuration, requirement file, command and
        versions; or also every run with its figures.
    document : dict, optional
        ``number`` and ``revision`` (override the configuration's ``[identity]``) and
        ``results`` (``{"path", "digest"}`` of the saved results file), for the document control.

    Raises
    ------
    InputError
        Bad results (missing key, wrong schema version) or a target folder that does not exist.
    """
    if not html_path and not pdf_path:
        raise InputError("render_report: give html_path and/or pdf_path")
    if html_path:
        _check_target(html_path, "--report")
    if pdf_path:
        _check_target(pdf_path, "--pdf")
    ctx, svgs = build_report(results, workers, appendix, document, scheduler)
    _emit("report.html.j2", ctx, svgs, html_path, pdf_path)


def file_sha256(path) -> str | None:
    """sha256 of a recording file when it is still where the result says (else None: not cited)."""
    import hashlib

    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest() if path else None
    except OSError:
        return None


def check_validation(result, where: str = "validation results") -> None:
    """Check a validation result has what its report needs (``InputError`` naming the key)."""
    if not isinstance(result, dict):
        raise InputError(f"{where}: expected a JSON object, got {type(result).__name__}")
    schema = result.get("schema")
    if schema is None:
        raise InputError(f"{where}: key 'schema' is missing (expected '{VALIDATION_SCHEMA}')")
    if schema != VALIDATION_SCHEMA:
        raise InputError(f"{where}: key 'schema' is '{schema}'; expected '{VALIDATION_SCHEMA}'")
    for key in ("recording", "plant", "modes", "summary"):
        if key not in result:
            raise InputError(f"{where}: key '{key}' is missing")
    if not isinstance(result["modes"], dict):
        raise InputError(f"{where}: key 'modes' should be an object of replay modes")


def render_validation_report(result: dict, html_path, pdf_path=None, *, workers: int | None = None,
                             document: dict | None = None, scheduler: str | None = None) -> None:
    """Render the model-validation report of ``govcheck validate`` / ``govcheck diagnose``.

    Parameters
    ----------
    result : dict
        ``compliance.validation.validate.validate`` output (schema ``govcheck.validation/1``), optionally
        with ``diagnosis`` (``after``: a validation result of the model with the physics added;
        ``added``: effects with fitted parameters; ``explanation``: text).
    html_path : path
    pdf_path : path, optional
    workers, scheduler
        Processes drawing figures, or the Dask scheduler that draws them (as :func:`render_report`).
    document : dict, optional
        ``number``, ``revision`` and ``identity`` (the configuration's ``[identity]``) for the
        document control; without identity and number the report is a DRAFT.
    """
    if not html_path and not pdf_path:
        raise InputError("render_validation_report: give html_path and/or pdf_path")
    if html_path:
        _check_target(html_path, "--report")
    if pdf_path:
        _check_target(pdf_path, "--pdf")
    check_validation(result)
    val = ValidationRecord.from_dict(result, "validation results")
    ctx, specs = validation_section(val, 1)
    svgs = draw_figures(specs, None, workers, scheduler)
    plant = dict(val.plant, path=display_path(val.plant.get("path")))  # never an installation's absolute path
    rec = dict(val.recording, path=display_path(val.recording.get("path")))
    ctx["recording"] = rec
    digest = rec.get("digest") or rec.get("sha256") or file_sha256(val.recording.get("path"))
    files = [{"what": "Plant configuration", "path": plant.get("path") or plant.get("name"), "digest": plant.get("digest")},
             {"what": "Recording", "path": rec.get("path"), "digest": digest}]
    document = document or {}
    identity = document.get("identity") or {}
    ctx = {**_common({"govcheck": val.tool.get("version", __version__)}),
           "v": ctx, "plant": plant, "settings": C.readable_settings(val.settings), "conditions": C.readable_settings(val.conditions),
           "windows": val.windows, "created": fmt_date(val.created), "identity": identity,
           "doc": S.document_block(identity, files, document)}
    _emit("validation.html.j2", ctx, svgs, html_path, pdf_path)


def section_page(title: str, remedies: dict | None = None, tolerance_yield: dict | None = None) -> str:
    """The report's "What would make it pass" / "Tolerance yield" section as a self-contained HTML page.

    ``govcheck sweep`` writes it beside its files (``summary.html``, ``yield.html``) so the answer
    can be read without rendering a whole report; same partial and stylesheet as the report.
    """
    env = _environment()
    body = env.get_template("_remedies.html.j2").render(remedies=remedies, tolerance_yield=tolerance_yield)
    page = env.from_string('<!doctype html>\n<html lang="en"><head><meta charset="utf-8"><title>{{ title }}</title>'
                           "<style>{{ css }}</style></head><body><main><h1>{{ title }}</h1>{{ body }}</main></body></html>\n")
    return page.render(title=title, css=jinja2.utils.markupsafe.Markup(_css()), body=jinja2.utils.markupsafe.Markup(body))
