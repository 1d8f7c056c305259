"""A damaged results file is named, not rendered into a crash: text where a number belongs is refused.

The report and the gate compute with the numbers of a results file; a hand-edited file with text
in such a key (``NUMERIC_KEYS``, at any depth; in the linear analysis and the validation also
``LINEAR_NUMERIC_KEYS``) is refused on reading with the key path.
"""

from __future__ import annotations

from compliance.errors import InputError

__all__ = ["LINEAR_NUMERIC_KEYS", "NUMERIC_KEYS", "check_numbers"]

# keys whose values the report computes with: a number, null, or a list of them (text lives in "display" tables)
NUMERIC_KEYS = frozenset({
    "value", "margin", "margin_pct", "wall", "wall_time", "time", "position", "reference", "valve_command",
    "pressure_a", "pressure_b", "supply_pressure", "force", "phase_margin_deg", "gain_margin_db", "time_constant",
    "dead_time", "overshoot", "settling_time", "rise_time", "bandwidth_hz", "natural_frequency_hz", "damping_ratio",
    "gain_crossover_hz", "phase_crossover_hz", "max_error", "rms_error", "steady_error", "peak_speed",
})
# the linear analysis (its map, cross-check and governor parameters) and the validation replay: every key that
# holds numbers, and only numbers, in the results govcheck writes
LINEAR_NUMERIC_KEYS = frozenset({
    "GMAX", "GMIN", "Tg", "Tg_linear", "Tg_nonlinear_samples", "Tg_steps", "UC", "UO", "VELM", "UO_peak", "UC_peak",
    "closed_loop", "closed_loop_discrete", "closed_loop_magnitude_db", "closed_loop_phase_deg", "closed_loop_zeros",
    "dead_time_linear", "dead_time_viscous", "dominant_time_constant", "first_order_time_constant", "frequency_hz",
    "gain_margin_db_continuous", "phase_margin_deg_continuous", "loop_discrete_magnitude_db", "loop_discrete_phase_deg",
    "loop_gain", "loop_magnitude_db", "loop_phase_deg", "natural_frequency_analytic_hz", "plant_minimal",
    "plant_velocity_gain", "pneumatic", "pneumatic_damping_ratio", "pneumatic_stiffness", "positions", "rate_pu_per_s",
    "ratio", "ratio_viscous", "ratio_viscous_no_dead_zone", "state_scales", "stroke_time", "t25", "t75", "t_step",
    "tau_linear", "tau_linear_mean", "tau_nonlinear", "tau_nonlinear_viscous", "time_constant_continuous",
    "unobservable_or_uncontrollable_states", "viscous_damping_ratio_analytic", "x_final", "x_start", "step",
    "fit_percent", "i_end", "i_start", "initial_pressures", "load_force", "max_abs_error", "mean_absolute_error",
    "mean_error", "mean_residual", "nrmse", "peak_abs", "peak_ratio", "rms_residual", "sample_time",
    "sample_time_median", "start", "end", "duration", "velocity_noise", "kp", "ki", "kd",
})
# keys numeric in one table only (a "window" of the validation is a name; the linear map's is its stroke window)
_NUMERIC_IN = {"map": frozenset({"window"})}
# keys that hold a number or one of these words
_NUMBER_OR_WORD = {"load": ("curve", "none", "nominal"), "loads": ("curve", "none", "nominal")}
_TEXT_TABLES = frozenset({"display", "procedure", "operating_point", "settings", "procedures", "operating_points", "units",
                          "notes", "detail", "conventions", "family", "andes", "psse_dyr", "left_out", "sentences",
                          "ieee_pes_tr_2013"})


def check_numbers(data: dict, where: str) -> None:
    """Refuse text where the report computes with a number, naming the key path.

    ``requirements``, ``runs``, ``timing``, ``plant`` and ``site`` are checked on ``NUMERIC_KEYS`` (their rows hold
    free text in other keys); the linear analysis and the validation, whose every key ``LINEAR_NUMERIC_KEYS`` names is
    a number wherever govcheck writes it, on those as well.

    Raises
    ------
    InputError
        The results file is damaged or hand-edited.
    """
    for key in ("requirements", "runs", "timing", "plant", "site"):
        _check_numbers(data.get(key), f"{where}: {key}", NUMERIC_KEYS)
    for key in ("linear", "validation"):
        _check_numbers(data.get(key), f"{where}: {key}", NUMERIC_KEYS | LINEAR_NUMERIC_KEYS)


def _check_numbers(tree, where: str, keys: frozenset, table: str = "") -> None:
    if isinstance(tree, dict):
        for k, v in tree.items():
            if k in _TEXT_TABLES:
                continue
            words = _NUMBER_OR_WORD.get(k)
            numeric = k in keys or k in _NUMERIC_IN.get(table, ())
            if (numeric and not _numbers(v)) or (words and not _numbers(v, words)):
                raise InputError(f"{where}.{k}: {str(v)[:60]!r} where a number (or null) belongs; the results file is "
                                 "damaged or hand-edited: regenerate it with govcheck check --json")
            _check_numbers(v, f"{where}.{k}", keys, k)
    elif isinstance(tree, (list, tuple)) and not _NUMBERS.issuperset(map(type, tree)):
        for i, v in enumerate(tree):
            _check_numbers(v, f"{where}[{i}]", keys, table)


_NUMBERS = frozenset({float, int, type(None)})  # a signal of a trace: checked at C speed


def _numbers(v, words: tuple = ()) -> bool:
    if isinstance(v, (list, tuple)):
        return _NUMBERS.issuperset(map(type, v)) or all(_numbers(x, words) for x in v)
    if isinstance(v, dict):
        return True  # a table of its own: its leaves are checked by name
    return v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) or (isinstance(v, str) and v in words)
