"""Build and check each merged entry of a requirement file: operating points, procedures, requirements.

After ``extends`` has been merged (``compliance.requirements.loading``), every entry is turned into
its frozen object (``compliance.requirements.requirement_set``) and checked for meaning: quantities with
units, procedure kinds and their settings, metric names, comparators and limits, and that a
requirement names operating points and procedures that exist and can measure its metric.
Messages name the file that set the offending key.
"""

from __future__ import annotations

from compliance.units.amounts import parse_amount, parse_load
from compliance.errors import did_you_mean
from compliance.errors import InputError
from compliance.metrics.catalogue import CHOICE_OPTIONS, METRICS, STEP_OPTION_DEFAULTS
from compliance.procedures.kinds import KINDS, parse_setting
from compliance.requirements.schema import OPEN_LIMIT
from compliance.requirements.requirement_set import LimitHistory, OperatingPoint, Procedure, Requirement
from compliance.requirements.verdict import COMPARATORS, Severity

__all__ = ["SEVERITIES", "SOURCES", "build_operating_point", "build_procedure", "build_requirement", "parse_limit"]

SEVERITIES = tuple(Severity)
SOURCES = ("simulation", "linear")


def _where(origin, section, name, key):
    """``"FILE: section.name.key"`` naming the file that set the key last."""
    f = origin.get((section, name, key), "?")
    return f"{f}: {section}.{name}.{key}"


def build_operating_point(name: str, e: dict, origin) -> OperatingPoint:
    """Operating point ``name`` from its merged table ``e``.

    Parameters
    ----------
    name : str
    e : dict
        Merged keys of ``[operating_points.NAME]``.
    origin : dict
        (section, name, key) -> file that set it, for messages.
    """
    pos = None
    if e.get("initial_position") is not None:
        pos = parse_amount(e["initial_position"], "m", _where(origin, "operating_points", name, "initial_position"))
    load_text = e.get("load", "none")
    load = parse_load(load_text, _where(origin, "operating_points", name, "load"), named=("curve", "nominal"))
    if load is None:
        load_text = "none"
    return OperatingPoint(name, e.get("title") or name, pos, load, load_text, e.get("flow_control"), e.get("note") or "",
                          e.get("setpoint_limiter"))


def build_procedure(name: str, e: dict, origin) -> Procedure:
    """Procedure ``name`` from its merged table: a known kind and its settings, defaults filled in.

    Raises
    ------
    InputError
        Missing or unknown kind, unknown setting, a required setting missing, a bad value.
    """
    where = _where(origin, "procedures", name, "kind")
    kind = e.get("kind")
    if kind is None:
        raise InputError(f"{where}: missing 'kind' (one of {', '.join(KINDS)})")
    if kind not in KINDS:
        raise InputError(f"{where}: '{kind}' is not a procedure kind{did_you_mean(kind, KINDS)} (known: {', '.join(KINDS)})")
    spec = KINDS[kind]
    settings = {}
    for k, v in e.items():
        if k in ("kind", "title", "note"):
            continue
        if k not in spec.settings:
            raise InputError(
                f"{_where(origin, 'procedures', name, k)}: unknown setting for a '{kind}' procedure"
                f"{did_you_mean(k, spec.settings)} (settings: {', '.join(spec.settings)})"
            )
        settings[k] = parse_setting(spec.settings[k], v, _where(origin, "procedures", name, k))
    for k, s in spec.settings.items():
        if k not in settings:
            if s.default is None:
                raise InputError(f"{origin.get(('procedures', name, 'kind'), '?')}: procedures.{name}: missing setting '{k}' ({s.meaning})")
            settings[k] = parse_setting(s, s.default, f"default of {kind}.{k}")
    return Procedure(name, kind, e.get("title") or name, settings, e.get("note") or "")


def parse_limit(e: dict, where: str, metric: str, comparator: str):
    """A requirement's limit in the metric's unit: one Amount, a (low, high) pair for ``within``,
    or None when it is open (``"purchaser"``).

    Raises
    ------
    InputError
        Missing limit, a bare number, the wrong unit, a pair where one is expected (or the
        reverse), low above high.
    """
    lim = e.get("limit")
    if lim is None:
        raise InputError(f"{where}: missing 'limit' (a quantity with a unit, a [low, high] pair for 'within', or '{OPEN_LIMIT}')")
    if isinstance(lim, str) and lim.strip().lower() == OPEN_LIMIT:
        return None
    unit = METRICS[metric].si_unit
    if comparator == "within":
        if not isinstance(lim, list) or len(lim) != 2:
            raise InputError(f"{where}: 'within' needs limit = [low, high], e.g. ['0.10 s', '0.25 s']")
        a = (parse_amount(lim[0], unit, where), parse_amount(lim[1], unit, where))
        if a[0].per_stroke == a[1].per_stroke and a[0].value > a[1].value:
            raise InputError(f"{where}: low limit {a[0].text} is above high limit {a[1].text}")
        return a
    if isinstance(lim, list):
        raise InputError(f"{where}: comparator '{comparator}' takes one limit, got a list")
    return (parse_amount(lim, unit, where),)


def build_requirement(rid, e, origin, defined_in, ops, procs, hist) -> Requirement:
    """Requirement ``rid`` from its merged table, checked against the operating points and procedures.

    Parameters
    ----------
    rid : str
    e, origin : dict
        The merged keys of ``[requirements.ID]`` and who set each, as for :func:`build_operating_point`.
    defined_in : str
        File that first declared the requirement.
    ops, procs : dict
        Built operating points and procedures, by name.
    hist : list of (file, dict)
        The entry as each file in the chain left it (for the tighten / loosen check).

    Raises
    ------
    InputError
        A missing or unknown value, a metric the named procedures cannot measure, an
        operating point without the initial position a procedure needs, an unknown option.
    """
    where = _RequirementWhere(rid, origin, defined_in)
    title = where.need(e, "title")
    metric = where.need(e, "metric", list(METRICS))
    comparator = where.need(e, "comparator", list(COMPARATORS))
    severity = Severity(where.choice(e, "severity", Severity.MANDATORY, SEVERITIES))
    source = where.choice(e, "source", "simulation", SOURCES)
    limit = parse_limit(e, where.key("limit"), metric, comparator)
    op_names = tuple(e.get("operating_points") or ())
    if not op_names:
        raise InputError(f"{where.entry}: missing 'operating_points' (a list of names from [operating_points])")
    for n in op_names:
        if n not in ops:
            raise InputError(f"{where.key('operating_points')}: operating point '{n}' is not declared{did_you_mean(n, ops)}")
    proc_names = tuple(e.get("procedures") or ())
    if source == "simulation":
        _check_procedures(where, metric, proc_names, op_names, ops, procs)
    options = _metric_options(where, metric, e.get("options") or {})
    not_applicable = dict(e.get("not_applicable") or {})
    for n in not_applicable:
        if n not in ops:
            raise InputError(f"{where.key('not_applicable')}: operating point '{n}' is not declared{did_you_mean(n, ops)}")
    history = _limit_history(rid, metric, comparator, limit, hist)
    return Requirement(
        id=rid,
        title=title,
        standard=e.get("standard", ""),
        clause=where.need(e, "clause"),
        metric=metric,
        comparator=comparator,
        limit=limit,
        procedures=proc_names,
        operating_points=op_names,
        severity=severity,
        source=source,
        options=options,
        note=e.get("note", ""),
        enabled=bool(e.get("enabled", True)),
        defined_in=defined_in,
        history=history,
        reading=e.get("reading", ""),
        alternative=e.get("alternative", ""),
        own_choice=e.get("own_choice", ""),
        not_applicable=not_applicable,
    )


class _RequirementWhere:
    """Locations and required values of one requirement's keys, for messages."""

    def __init__(self, rid: str, origin, defined_in: str):
        self.rid, self.origin = rid, origin
        self.entry = f"{defined_in}: requirements.{rid}"

    def key(self, key: str) -> str:
        """``"FILE: requirements.ID.key"`` naming the file that set the key last."""
        return _where(self.origin, "requirements", self.rid, key)

    def need(self, e: dict, key: str, choices=None):
        """The value of a required key, one of ``choices`` when given."""
        v = e.get(key)
        if v is None:
            raise InputError(f"{self.entry}: missing '{key}'" + (f" (one of {', '.join(choices)})" if choices else ""))
        if choices is not None and v not in choices:
            raise InputError(f"{self.key(key)}: '{v}' is not one of {', '.join(choices)}{did_you_mean(v, choices)}")
        return v

    def choice(self, e: dict, key: str, default: str, choices) -> str:
        """The value of an optional key with a default, one of ``choices``."""
        v = e.get(key, default)
        if v not in choices:
            raise InputError(f"{self.key(key)}: '{v}' is not one of {', '.join(choices)}")
        return v


def _check_procedures(where: _RequirementWhere, metric: str, proc_names, op_names, ops, procs) -> None:
    """The named procedures exist, can measure ``metric`` and find the initial position they need."""
    if not proc_names:
        raise InputError(f"{where.entry}: missing 'procedures' (a list of names from [procedures])")
    info = METRICS[metric]
    for n in proc_names:
        if n not in procs:
            raise InputError(f"{where.key('procedures')}: procedure '{n}' is not declared{did_you_mean(n, procs)}")
        if procs[n].kind not in info.kinds:
            raise InputError(
                f"{where.key('procedures')}: metric '{metric}' cannot be measured by procedure "
                f"'{n}' of kind '{procs[n].kind}' (it needs one of: {', '.join(info.kinds)})"
            )
        if procs[n].kind != "full_stroke" and procs[n].kind != "independent_adjustment":
            for o in op_names:
                if ops[o].initial_position is None:
                    raise InputError(
                        f"{where.key('operating_points')}: operating point '{o}' has no "
                        f"initial_position, which procedure '{n}' ({procs[n].kind}) needs"
                    )


def _metric_options(where: _RequirementWhere, metric: str, given: dict) -> dict:
    """The requirement's metric options (``options = { settling_band = "2 %" }``): amounts, or a reading's name
    (``timing = "full_rate"``, ``travel = "achieved"``: ``metrics.catalogue.CHOICE_OPTIONS``)."""
    info = METRICS[metric]
    options = {}
    for k, v in given.items():
        if k not in info.options:
            raise InputError(
                f"{where.key('options')}.{k}: metric '{metric}' takes no option '{k}'"
                + (f"{did_you_mean(k, info.options)} (options: {', '.join(info.options)})" if info.options else "")
            )
        if k in CHOICE_OPTIONS:
            choices = CHOICE_OPTIONS[k][0]
            if v not in choices:
                raise InputError(f"{where.key('options')}.{k}: '{v}' is not one of {', '.join(choices)}{did_you_mean(str(v), choices)}")
            options[k] = v
            continue
        options[k] = parse_amount(v, STEP_OPTION_DEFAULTS[k][0], f"{where.key('options')}.{k}")
    return options


def _limit_history(rid: str, metric: str, comparator: str, limit, hist) -> tuple[LimitHistory, ...]:
    """The limit as each file of the chain left it (for the tighten / loosen check)."""
    history = []
    for fpath, snap in hist:
        try:
            lim = parse_limit(snap, f"{fpath}: requirements.{rid}.limit", metric, snap.get("comparator", comparator))
        except InputError:
            lim = None if str(snap.get("limit", "")).lower() == OPEN_LIMIT else limit
        history.append(LimitHistory(fpath, snap.get("comparator", comparator), lim, snap.get("severity", Severity.MANDATORY),
                                    bool(snap.get("enabled", True)), bool(snap.get("allow_loosen", False))))
    return tuple(history)
