"""The site acceptance report: a site's measured verdicts, the coverage, the model beside them, the diagnosis.

A commissioning engineer's acceptance report (IEC 60308:2024 / ASME PTC 29-2005 (R2020) test
reports) built from the site results alone (``govcheck accept --json``, schema
``govcheck-site/1``): page 1 gives the measured verdicts, what was not tested, the agreement with
the model and what the diagnosis found; then per requirement its rows; per test the measured trace
with the predicted one, the figures against the guarantees, the conditions as recorded, the
instruments and the departures from the test code; the document control is ``check``'s.
"""

from __future__ import annotations

from compliance.errors import InputError
from compliance.presentation.values import limit_as_written, metric_text
from compliance.report import signoff as S
from compliance.report.render import _check_target, _common, _emit, draw_figures
from compliance.presentation.numbers import fmt_date, fmt_si

__all__ = ["build_site_report", "render_site_report"]

_CASE_METRICS = {"steps": ("dead_time", "time_constant", "time_constant_achieved", "max_positioning_error"),
                 "full_stroke": ("opening_time", "closing_time", "stroke_speed", "max_speed", "start_delay", "time_to_end"),
                 "hold": ("drift", "drift_excursion", "max_positioning_error"), "dead_band": ("dead_band",),
                 "sine": ("tracking_max_error", "tracking_rms_error")}
_UNITS = {"dead_time": "s", "time_constant": "s", "time_constant_achieved": "s", "start_delay": "s", "time_to_end": "s",
          "drift_excursion": "m"}


def _text(value, metric: str, u=None) -> str:
    if value is None:
        return "–"
    unit = _UNITS.get(metric)
    base = metric_text(value, metric) if unit is None else fmt_si(value, unit)
    if not u:
        return base
    return f"{base} ± {metric_text(u, metric, 2) if unit is None else fmt_si(u, unit)}"


def _band(p: dict | None, metric: str) -> str:
    if not p or p.get("value") is None:
        return "–"
    return f"{_text(p['value'], metric)} [{_text(p['low'], metric)} – {_text(p['high'], metric)}]"


def _summary(results: dict) -> list:
    out = []
    for e in results["requirements"]:
        w, p, cov = e.get("worst") or {}, e.get("prediction"), e.get("coverage") or {}
        out.append({"id": e["id"], "title": e["title"], "severity": e["severity"], "status": e["status"],
                    "limit": limit_as_written(e), "measured": _text(w.get("value"), e["metric"], w.get("u")),
                    "where": (w.get("run") or "") + (f" – {w['which']}" if w.get("which") else ""),
                    "tested": f"{len(cov.get('tested', []))} of {cov.get('asked', 0)}" if cov.get("asked") else "–",
                    "predicted": _band(p, e["metric"]), "model": (p or {}).get("status"),
                    "agree": None if not p else p["agree"], "reason": e.get("reason")})
    return out


def _rows(e: dict) -> list:
    out = []
    for r in e["rows"]:
        out.append({"run": r["run"], "case": f"{r['procedure']} @ {r['operating_point']}", "which": r.get("which") or "",
                    "measured": _text(r.get("value"), e["metric"], r.get("u")), "status": r["status"],
                    "predicted": _band(r.get("prediction"), e["metric"]),
                    "agree": None if not r.get("prediction") else r["prediction"].get("agree"),
                    "reason": r.get("reason"), "departures": r.get("departures") or [], "extended": r.get("extended")})
    return out


def _figure_spec(rec: dict, fid: str, diagnosis: dict | None) -> dict:
    tr = rec["trace"]
    series = [("recorded position", tr["time"], tr["position"], "recorded")]
    if tr.get("reference"):
        series.append(("set-point", tr["time"], tr["reference"], "reference"))
    if tr.get("predicted"):
        series.append(("predicted by the model", tr["predicted"]["time"], tr["predicted"]["position"], "before"))
    windows = [tuple(c["marks"]["window"]) for c in rec["cases"] if c.get("marks", {}).get("window")]
    return {"kind": "waveform", "id": fid, "series": series, "scale": 1e3, "ylabel": "position [mm]", "windows": windows}


def _tests(results: dict) -> tuple[list, list]:
    tests, specs = [], []
    for k, rec in enumerate(results["site"]["recordings"]):
        fid = f"site-fig-{k + 1}"
        specs.append(_figure_spec(rec, fid, results.get("diagnosis")))
        cases = []
        for c in rec["cases"]:
            figs = [(m.replace("_", " "), _text(c["values"][m]["value"], m, c["values"][m]["u"]),
                     c["values"][m]["reason"] if not c["values"][m]["eligible"] or c["values"][m]["value"] is None else "")
                    for m in _CASE_METRICS.get(c["kind"], ()) if m in c["values"]]
            cases.append({"label": c["label"], "figures": figs, "problem": c.get("problem")})
        inst = rec["instruments"]
        tests.append({"rec": rec, "fid": fid, "cases": cases, "instruments": [
            ("logger rate", f"{inst['rate']:.0f} Hz" + (" (uneven time base, interpolated)" if inst.get("resampled") else "")),
            ("channels", ", ".join(rec["channels"])),
            ("position resolution", fmt_si(inst["position_resolution"], "m") if inst["position_resolution"] else "none found"),
            ("position noise (std)", fmt_si(inst["position_noise"], "m")),
            ("anti-alias filter lag", fmt_si(inst["filter_delay"], "s") if inst["filter_delay"] else "none stated"),
            ("conditioning", f"cubic Savitzky–Golay over {inst['smoothing_window'] * 1e3:.0f} ms, leaves "
                             f"{fmt_si(inst['conditioned_uncertainty'], 'm')} (std)" if inst["smoothing_window"] else "none")]})
    return tests, specs


def build_site_report(results: dict, document: dict | None = None) -> tuple[dict, dict]:
    """The template context and the figures of a site report (nothing written)."""
    if results.get("schema") != "govcheck-site/1":
        raise InputError(f"site report: schema '{results.get('schema')}' is not 'govcheck-site/1'")
    tests, specs = _tests(results)
    svgs = draw_figures(specs, None, 1)
    plant, rs = results["plant"], results["requirement_set"]
    files = [{"what": "Recording", "path": r["path"], "digest": r["digest"]} for r in results["site"]["recordings"]]
    files += [{"what": "Plant configuration (prediction)", "path": plant.get("path") or plant["name"], "digest": plant.get("digest")}]
    files += [{"what": "Requirement file", "path": f.get("path"), "digest": f.get("digest")} for f in rs.get("files") or []]
    res = (document or {}).get("results") or {}
    files.append({"what": "Results file", "path": res.get("path") or "not saved (this run wrote no results file)", "digest": res.get("digest")})
    common = _common(results.get("versions"), results.get("created"), bool(results.get("reproducible")))
    ctx = {**common, "results": results, "site": results["site"], "plant": plant, "rs": rs,
           "summary": results["summary"], "verdict": results["summary"]["status"], "rows": _summary(results),
           "requirements": [{"e": e, "rows": _rows(e)} for e in results["requirements"] if e["rows"]],
           "tests": tests, "diagnosis": results.get("diagnosis"), "created": fmt_date(results.get("created")),
           "identity": plant.get("identity") or {},
           "doc": S.document_block(plant.get("identity") or {}, files, document),
           "departures": sorted({d for r in results["site"]["recordings"] for d in r["departures"]}),
           "not_tested": [(e["id"], e["coverage"]["not_tested"]) for e in results["requirements"]
                          if e.get("coverage", {}).get("not_tested")],
           "command": results.get("command_line")}
    return ctx, svgs


def render_site_report(results: dict, html_path=None, pdf_path=None, *, document: dict | None = None) -> None:
    """Render the site acceptance report of a ``govcheck accept`` results dict to HTML and/or PDF (written atomically)."""
    if not html_path and not pdf_path:
        raise InputError("render_site_report: give html_path and/or pdf_path")
    if html_path:
        _check_target(html_path, "--report")
    if pdf_path:
        _check_target(pdf_path, "--pdf")
    ctx, svgs = build_site_report(results, document)
    _emit("site.html.j2", ctx, svgs, html_path, pdf_path)
