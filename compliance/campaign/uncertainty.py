"""Uncertainty bands on the verdicts: the plant file's declared ranges propagated by local sensitivities.

Every parameter a plant file gives a plausible ``range`` (``compliance.model.assumptions``) is moved,
one at a time, to each end of its range, and every run with a judged value is repeated on the
campaign executor and judged again, so that **every row** gets a band. The changes of a row's value
are that parameter's two swings (no linearity assumed between the ends; a response that turns back
inside the range is the one case the ends miss). The band is the interval sum of the swings (each
parameter anywhere in its range, the worst combination):

    low  = v0 + sum_k min(0, d_k+, d_k-)        high = v0 + sum_k max(0, d_k+, d_k-)

When the plant file declares commissioning settings (``[commissioning]``, ``model.assumptions``: the
loop gain, the limiter rates), the plant at each end of each range is first commissioned as on site
(``campaign.commissioning``: each setting made again by its own measurement) and then judged: the band
is the verdict's range over plants that differ in what the file only assumes, each commissioned, and
the settings it took are reported. A parameter is not re-run where it cannot act at all (:func:`can_move`: the load curve's scale off the
curve, the stroke start pressures outside the full strokes, the controller and the valve's opening
curve below saturation in an open-loop full-command stroke): its swing there is zero by structure.

A row whose band straddles its limit is ``uncertain``; the parameters that decide it are the largest
swings towards the limit, in order, until they cover the margin. A requirement the judge failed
stays failed while one row fails across its whole band, and becomes uncertain otherwise; a passed
one becomes uncertain when a row straddles. ``govcheck check --uncertainty N`` replaces the local
band of the deciding row by a Latin-hypercube Monte Carlo over the same ranges
(``compliance.sweep.tolerance.uncertainty_mc``). docs/requirements.md, "Uncertainty".
"""

from __future__ import annotations

from compliance.model.assumptions import SETTINGS
from compliance.processes import map_tasks
from compliance.campaign.judge import judge_row
from compliance.procedures.outcomes import traces_off
from compliance.procedures.registry import run as run_procedure
from compliance.requirements.verdict import Status, evaluate

__all__ = ["apply_band", "can_move", "commissioned_settings", "local_bands", "modelled_verdicts", "ranged_parameters", "row_band", "settle_status",
           "top_assumptions"]


def ranged_parameters(cfg) -> list[tuple[str, dict]]:
    """(dotted key, range) of every parameter the plant file gives a range, in file order."""
    return [(k, a["range"]) for k, a in cfg.assumptions.items() if a.get("range")]


# the valve's opening curve below saturation (physics.valve_opening.path_opening): at a command beyond the
# saturation voltage every path is fully open whatever these are, and at the null (dead zone >= 0) shut
_OPENING_CURVE = ("valve.dead_zone_positive", "valve.dead_zone_negative", "valve.slope_positive", "valve.slope_negative",
                  "valve.saturation_voltage")
# effects through which a full-command stroke passes the opening curve (a spool that moves, flow at the null)
_VALVE_EFFECTS = ("valve_dynamics", "valve_null_flow", "valve_offset")
_STROKE_KINDS = ("full_stroke", "independent_adjustment")


def _open_loop_stroke(cfg, proc) -> bool:
    """A full-command stroke with the PID out of the loop (no set-point rate limiter to drive it closed loop)."""
    return proc.kind in _STROKE_KINDS and not cfg.setpoint_rate_limited


def _beyond_saturation(cfg, proc, key: str) -> bool:
    """An open-loop stroke commands the valve beyond saturation (the top of the range when ``key`` moves it)."""
    from compliance.procedures.scenarios import full_command

    if not _open_loop_stroke(cfg, proc) or any(e in cfg.effects for e in _VALVE_EFFECTS):
        return False
    u_open, u_close = full_command(cfg, proc.settings.get("command", "full"))
    centre = cfg.p("valve.centre_voltage")
    sat = cfg.p("valve.saturation_voltage")
    if key == "valve.saturation_voltage":
        sat = max(sat, ((cfg.assumptions.get(key) or {}).get("range") or {}).get("high", sat))
    return min(abs(u_open - centre), abs(u_close - centre)) >= sat


def can_move(cfg, reqset, key: str, job) -> bool:
    """Whether parameter ``key`` can change run ``job`` at all (a structural screen: no simulation).

    ``load.curve_scale`` acts only at operating points on the load curve; ``air.stroke_start_charge``
    only in full strokes from an end stop; the controller's parameters not in an open-loop stroke
    (the PID is out of the loop), the valve's opening curve not when that stroke commands the valve
    beyond saturation (every path fully open). Everything else may move every run.
    """
    proc = reqset.procedures[job.procedure]
    op = reqset.operating_points[job.operating_point]
    if key == "load.curve_scale":
        return op.load == "curve"
    if key == "air.stroke_start_charge":
        return proc.kind in _STROKE_KINDS and proc.settings.get("start", "end_stop") == "end_stop"
    if key.startswith("controller."):
        return not _open_loop_stroke(cfg, proc)
    if key in _OPENING_CURVE:
        return not _beyond_saturation(cfg, proc, key)
    return True


def modelled_verdicts(entries) -> list[dict]:
    """Requirements whose deciding (worst) row is a simulated value with a verdict (the Monte Carlo bands these)."""
    return [e for e in entries if e.get("source", "simulation") == "simulation" and e.get("worst")
            and e["status"] in (Status.PASS, Status.FAIL, Status.UNCERTAIN) and e["worst"].get("value") is not None]


def _perturbed_run(ctx, item):
    """Worker: one run with one parameter moved (and the settings commissioned for it) -> (samples by request key, error)."""
    cfg, reqset, jobs, settings = ctx
    key, value, j = item
    moved = cfg.replace(params={key: value, **settings.get((key, value), {})}, sources={key: cfg.sources.get(key, "user")})
    job = jobs[j]
    with traces_off():
        out = run_procedure(moved, reqset.procedures[job.procedure], reqset.operating_points[job.operating_point], job.requests)
    return out.samples, out.error


def _commissioned_corner(ctx, item):
    """Worker: the settings commissioning makes on the plant with one parameter at one end of its range -> {key: value}."""
    from compliance.campaign.commissioning import commission

    cfg, reqset = ctx
    key, value = item
    moved = cfg.replace(params={key: value}, sources={key: cfg.sources.get(key, "user")})
    done = commission(moved, reqset, workers=1)
    return {k: done.params[k] for k in _setting_keys(cfg) if done.params[k] != moved.params[k]}


def _setting_keys(cfg) -> list[str]:
    """The parameters of the plant file's declared commissioning settings (``model.assumptions.SETTINGS``)."""
    return [k for n in cfg.commissioning for k in SETTINGS[n].parameters]


def commissioned_settings(cfg, reqset, ranged, *, workers=None, progress=False) -> tuple[dict, dict | None]:
    """The declared commissioning settings made again at each end of each range (``campaign.commissioning``).

    Returns
    -------
    tuple
        ({(key, value): {setting key: value}}, the ``commissioning`` record of the bands or None when
        the plant file declares no commissioning settings).
    """
    if not cfg.commissioning:
        return {}, None
    corners = [(k, rng[end]) for k, rng in ranged for end in ("low", "high")]
    got, _ = map_tasks(_commissioned_corner, (cfg, reqset), corners, workers=workers, progress=progress,
                       label="commissioning") if corners else ([], None)
    settings = {c: (g or {}) for c, g in zip(corners, got)}
    keys = _setting_keys(cfg)
    spans = {}
    for k in keys:
        vals = [cfg.params[k]] + [s[k] for s in settings.values() if k in s]
        spans[k] = [min(vals), max(vals)]
    record = {"settings": list(cfg.commissioning), "parameters": keys, "spans": spans,
              "failed": [{"parameter": k, "value": v} for (k, v), g in zip(corners, got) if g is None],
              "corners": [{"parameter": k, "value": v, "settings": settings[(k, v)]} for k, v in corners]}
    record["text"] = _commissioning_text(record, len(corners))
    return settings, record


def _commissioning_text(record: dict, plants: int) -> str:
    """One sentence: which settings were made again, on how many plants, and the span of what they came to."""
    from compliance.model.parameters import BASE_BY_KEY
    from compliance.presentation.numbers import fmt_si

    spans = [f"{k.split('.', 1)[1]} {fmt_si(lo, BASE_BY_KEY[k].unit)}–{fmt_si(hi, BASE_BY_KEY[k].unit)}"
             for k, (lo, hi) in record["spans"].items() if hi > lo * (1 + 1e-9)]
    text = (f"bands after commissioning: the plant file sets {', '.join(record['settings'])} on site ([commissioning]), so "
            f"at each end of each declared range ({plants} plants) they were made again by their measurement before the "
            "tests were judged" + (f"; they came to {', '.join(spans)}" if spans else ""))
    if record["failed"]:
        text += (f"; commissioning failed on {len(record['failed'])} plant(s), judged with the file's settings: "
                 + ", ".join(f"{f['parameter']} = {f['value']:g}" for f in record["failed"]))
    return text


def _bandable(e: dict, r: dict) -> bool:
    """A simulated row with a value (judged, or measured against an open limit)."""
    return e.get("source", "simulation") == "simulation" and r.get("value") is not None \
        and r.get("status") in (Status.PASS, Status.FAIL, Status.OPEN)


def _deciding(swings: dict, margin: float, toward_limit_sign: float) -> list[str]:
    """Parameters whose swings towards the limit, largest first, cover ``margin``."""
    order = sorted(((max(max(0.0, toward_limit_sign * d) for d in s), k) for k, s in swings.items()), reverse=True)
    out, covered = [], 0.0
    for amount, k in order:
        if amount <= 0.0:
            break
        out.append(k)
        covered += amount
        if covered >= abs(margin):
            break
    return out


def _margin_points(comparator: str, lim: tuple, low: float, high: float, v0: float) -> list[float]:
    """Values at which the margin over [low, high] is extreme: the ends, the point value and, for ``within``,
    the middle of the limits clipped into the band (the margin to the nearer edge peaks there)."""
    pts = [low, high, v0]
    if comparator == "within":
        pts.append(min(max(0.5 * (lim[0] + lim[1]), low), high))
    return pts


def _toward_limit(comparator: str, lim: tuple, v0: float, status) -> float:
    """+1 when a larger value moves a row towards its verdict's other side, else -1."""
    if comparator in ("<=", "<"):
        return 1.0 if status == Status.PASS else -1.0
    if comparator in (">=", ">"):
        return -1.0 if status == Status.PASS else 1.0
    mid = 0.5 * (lim[0] + lim[1])
    return (1.0 if v0 >= mid else -1.0) * (1.0 if status == Status.PASS else -1.0)


def row_band(comparator: str, row: dict, low: float, high: float, swings: dict, method: str,
             unmeasured: list | None = None) -> dict:
    """The band of one row's value and margin (``low``/``high`` SI), and whether it straddles the row's limit."""
    band = {"low": low, "high": high, "method": method, "margin_low_pct": None, "margin_high_pct": None,
            "straddles": False, "deciding": [], "swings": {k: list(s) for k, s in swings.items()},
            "unmeasured": list(unmeasured or [])}
    lim = tuple(row.get("limit") or ())
    if not lim or row.get("status") not in (Status.PASS, Status.FAIL, Status.UNCERTAIN):
        return band
    v0 = row["value"]
    judged = [evaluate(v, comparator, lim) for v in _margin_points(comparator, lim, low, high, v0)]
    pcts = [x.margin_pct for x in judged]
    if all(p is not None for p in pcts):
        band["margin_low_pct"], band["margin_high_pct"] = min(pcts), max(pcts)
    band["straddles"] = len({x.status for x in judged}) > 1
    if band["straddles"]:
        status = evaluate(v0, comparator, lim).status
        band["deciding"] = _deciding(swings, row.get("margin") or 0.0, _toward_limit(comparator, lim, v0, status))
    return band


def apply_band(e: dict, low: float, high: float, swings: dict, method: str) -> None:
    """Put a band on requirement entry ``e``'s deciding (worst) row and settle its status (see the module docstring)."""
    w = e["worst"]
    band = row_band(e["comparator"], {**w, "limit": w.get("limit") or e["limit"]}, low, high, swings, method)
    for r in e["rows"]:
        if r["run"] == w["run"] and r.get("which") == w.get("which"):
            r["band"] = band
    w["band"] = band
    settle_status(e)


def settle_status(e: dict) -> None:
    """Rows whose band straddles become uncertain; the requirement's status and deciding row follow them."""
    for r in e["rows"]:
        band = r.get("band") or {}
        if band.get("straddles") and r.get("status") in (Status.PASS, Status.FAIL):
            r["status"] = Status.UNCERTAIN
    w = e.get("worst") or {}
    row_of_worst = next((r for r in e["rows"] if r["run"] == w.get("run") and r.get("which") == w.get("which")), None)
    if row_of_worst is not None:
        w["status"], w["band"] = row_of_worst["status"], row_of_worst.get("band")
    sure_fails = [r for r in e["rows"] if r.get("status") == Status.FAIL]
    if e["status"] == Status.FAIL and not sure_fails:
        e["status"] = Status.UNCERTAIN
    elif e["status"] == Status.FAIL and w.get("status") == Status.UNCERTAIN:
        # the deciding row is the worst failure that holds across its band
        sure = min(sure_fails, key=lambda r: r["margin_pct"] if r.get("margin_pct") is not None else (r.get("margin") or 0.0))
        for k in list(w):
            if k in sure:
                w[k] = sure[k]
    elif e["status"] == Status.PASS and any(r.get("status") == Status.UNCERTAIN for r in e["rows"]):
        e["status"] = Status.UNCERTAIN
    if e["status"] == Status.UNCERTAIN and w.get("status") != Status.UNCERTAIN:
        # the deciding row of an uncertain requirement is its uncertain row nearest the limit
        near = min((r for r in e["rows"] if r.get("status") == Status.UNCERTAIN),
                   key=lambda r: abs(r["margin_pct"]) if r.get("margin_pct") is not None else abs(r.get("margin") or 0.0))
        for k in list(w):
            if k in near:
                w[k] = near[k]
    e["band"] = w.get("band")


def _row_swings(got: dict, ranged, req, e: dict, r: dict, j: int, movable) -> tuple[dict, list]:
    """Swings of one row's value per ranged parameter (top end, bottom end), and the parameters whose moved run gave no value."""
    swings, unmeasured = {}, []
    lim = tuple(r["limit"]) if r.get("limit") else None
    for k, rng in ranged:
        if not movable(k):
            continue  # cannot act on this run: zero swing by structure
        ends = []
        for v in (rng["high"], rng["low"]):
            samples, error = got[(k, v, j)]
            moved = judge_row(req, r["procedure"], r["operating_point"], lim, samples.get(e["request_key"]), error)
            ends.append(None if moved["value"] is None else moved["value"] - r["value"])
        if None in ends:
            unmeasured.append(k)
        else:
            swings[k] = tuple(ends)
    return swings, unmeasured


def local_bands(cfg, reqset, jobs, entries, *, workers=None, progress=False) -> dict:
    """Local-sensitivity bands on every simulated row with a value (see the module docstring); entries are updated in place.

    Parameters
    ----------
    cfg : PlantConfig
    reqset : RequirementSet
    jobs : list of Job
        The campaign's planned runs.
    entries : list of dict
        The judge's requirement entries.
    workers : int, optional
        Local pool size.

    Returns
    -------
    dict
        ``{"method": "local", "parameters": [...], "runs": N, "screened": M, "top_assumptions": [...]}``:
        ``runs`` re-simulated, ``screened`` (parameter end, run) pairs not run because the parameter cannot act there.
    """
    ranged = ranged_parameters(cfg)
    index = {j.key: i for i, j in enumerate(jobs)}
    need = sorted({index[r["run"]] for e in entries for r in e["rows"] if _bandable(e, r) and r["run"] in index})
    settings, commissioned = commissioned_settings(cfg, reqset, ranged, workers=workers, progress=progress)
    # a setting commissioning changed acts on every run, whatever the moved parameter itself could reach
    recommissioned = {k for (k, _), s in settings.items() if s}
    movable = {(k, j): k in recommissioned or can_move(cfg, reqset, k, jobs[j]) for k, _ in ranged for j in need}
    # one moved plant's runs at one operating point together: its steps share their full-command strokes (a worker memo)
    need.sort(key=lambda j: (jobs[j].operating_point, jobs[j].procedure))
    items = [(k, rng[end], j) for k, rng in ranged for end in ("low", "high") for j in need if movable[(k, j)]]
    results, _ = map_tasks(_perturbed_run, (cfg, reqset, list(jobs), settings), items, workers=workers, progress=progress,
                           label="uncertainty") if items else ([], None)
    got = dict(zip(items, results))
    by_id = {r.id: r for r in reqset.requirements}
    for e in entries:
        rows = [r for r in e["rows"] if _bandable(e, r) and r["run"] in index]
        for r in rows:
            j = index[r["run"]]
            swings, unmeasured = _row_swings(got, ranged, by_id[e["id"]], e, r, j, lambda k: movable[(k, j)])
            low = r["value"] + sum(min(0.0, *s) for s in swings.values())
            high = r["value"] + sum(max(0.0, *s) for s in swings.values())
            r["band"] = row_band(e["comparator"], r, low, high, swings, "local", unmeasured)
        if rows:
            settle_status(e)
    out = {"method": "local", "parameters": [{"parameter": k, **rng} for k, rng in ranged], "runs": len(items),
           "screened": 2 * sum(1 for v in movable.values() if not v),
           "top_assumptions": top_assumptions(entries, cfg)}
    if commissioned is not None:
        out["commissioning"] = commissioned
    return out


def top_assumptions(entries, cfg, n: int = 3) -> list[dict]:
    """The ``n`` ranged parameters that matter most: the largest swing relative to a verdict's margin."""
    score: dict[str, tuple[float, str]] = {}
    for e in entries:
        band = e.get("band")
        w = e.get("worst") or {}
        if not band or w.get("margin") is None:
            continue
        m = max(abs(w["margin"]), 1e-12)
        for k, s in band["swings"].items():
            r = max(abs(d) for d in s) / m
            if r > score.get(k, (0.0, ""))[0]:
                score[k] = (r, f"moves {e['id']} by up to {max(abs(d) for d in s) / m:.0%} of its margin")
    top = sorted(score.items(), key=lambda kv: -kv[1][0])[:n]
    return [{"parameter": k, "score": r, "why": why, "range": (cfg.assumptions.get(k) or {}).get("range")} for k, (r, why) in top]
