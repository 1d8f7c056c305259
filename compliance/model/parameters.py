"""The base parameter table, and the one handle on any tunable parameter of a plant.

The table (every key a plant configuration may hold, with SI unit, meaning, validity) is read by
the configuration loader (validation), the simulator assembly (parameter vector), the report
appendix and the diagnosis (which base parameters it may refit). :class:`ParamHandle` is the one
handle the diagnosis candidates, the sweep adjustables and tolerances and the calibration table
share: :func:`param_handle` makes it from any spelling of a parameter path, :func:`apply` sets
values on a configuration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from compliance.effects import EFFECTS
from compliance.effects.param import Param
from compliance.errors import InputError, did_you_mean


def _P(key, unit, meaning, default, low=0.0, high=float("inf"), low_open=False, **kw) -> Param:
    """A base-parameter row: (key, unit, meaning, default, low, high, low_open) as the table reads."""
    return Param(key, unit, meaning, default, (low, high), low_open=low_open, **kw)


BASE_PARAMS: tuple[Param, ...] = (
    _P("cylinder.stroke", "m", "stroke L (x = 0 closed gate, x = L fully open)", None, 0.0, 5.0, True, slot="stroke"),
    _P("cylinder.piston_diameter", "m", "piston bore", None, 0.0, 1.0, True),
    _P("cylinder.rod_diameter", "m", "rod diameter", None, 0.0, 1.0),
    _P("cylinder.dead_volume", "m^3", "dead volume per chamber including pipes", None, 0.0, 1.0, True, fit_bounds=(2e-4, 4e-3), slot="dead_volume"),
    _P("cylinder.moving_mass", "kg", "total moving mass", None, 0.0, 1e5, True, fit_bounds=(5.0, 300.0), slot="mass"),
    _P("air.supply_pressure", "Pa", "regulated supply pressure", None, 0.0, 1e8, True, pressure=True, slot="p_supply"),
    _P("air.atmospheric_pressure", "Pa", "atmospheric pressure", 101300.0, 0.0, 2e5, True, pressure=True, slot="p_atm"),
    _P("air.supply_temperature", "K", "supply air temperature", 293.15, 0.0, 500.0, True, slot="t_supply"),
    _P("air.gas_constant", "J/(kg*K)", "specific gas constant R", 287.0, 0.0, 1e4, True, slot="r_gas"),
    _P("air.heat_capacity_ratio", "", "heat capacity ratio gamma", 1.4, 1.0, 2.0, True, slot="gamma"),
    # a test condition of the full strokes (simulation.scenario.stroke_start_pressures), not of the core
    _P("air.stroke_start_charge", "", "pressure of the side that held the servo at its end stop when a full stroke "
       "starts, as a fraction of the supply above atmosphere (1 = at supply)", 1.0, 0.0, 1.0),
    _P("air.reference_density", "kg/m^3", "density at the conductance rating conditions (NTP)", 1.204, 0.0, 10.0, True, slot="rho0"),
    _P("air.reference_temperature", "K", "temperature at the conductance rating conditions (NTP)", 293.15, 0.0, 500.0, True, slot="t0"),
    _P("valve.sonic_conductance", "m^3/(s*Pa)", "ISO 6358 sonic conductance C of each port path", None, 0.0, 1e-4, True, fit_bounds=(5e-9, 8e-8), slot="conductance"),
    _P("valve.critical_pressure_ratio", "", "ISO 6358 critical pressure ratio b", 0.528, 0.0, 0.999, slot="b_crit"),
    _P("valve.dead_zone_positive", "V", "dead zone zmd for commands opening P->A (U > 0)", 0.0, 0.0, 10.0, fit_bounds=(0.0, 2.0), slot="dz_pos"),
    _P("valve.dead_zone_negative", "V", "dead zone zme for commands opening P->B (U < 0), magnitude", 0.0, 0.0, 10.0, fit_bounds=(0.0, 2.0), slot="dz_neg"),
    _P("valve.slope_positive", "", "dead-zone slope md", 1.0, 0.0, 100.0, True, slot="slope_pos"),
    _P("valve.slope_negative", "", "dead-zone slope me", 1.0, 0.0, 100.0, True, slot="slope_neg"),
    _P("valve.saturation_voltage", "V", "command magnitude at which a path is fully open", None, 0.0, 100.0, True, slot="u_sat"),
    _P("valve.command_limit", "V", "command saturation +/-", 10.0, 0.0, 100.0, True, slot="u_lim"),
    _P("valve.centre_voltage", "V", "command at the valve null (0 for a +/-10 V valve, 5 V for a 0-10 V valve)", 0.0, -100.0, 100.0, slot="u_centre"),
    _P("valve.effective_area", "m^2", "Sanville law: effective area at full opening", 0.0, 0.0, 1.0, slot="eff_area"),
    _P("valve.bobrow_coefficient", "kg/(s*Pa^0.5)", "Bobrow law: C_f*A at full opening", 0.0, 0.0, 1.0, slot="bobrow_coef"),
    _P("valve.power_law_c1", "number", "power law: C_f1 at full opening [kg/(s*Pa^lambda)]", 0.0, 0.0, 1.0, slot="pow_c1"),
    _P("valve.power_law_c2", "kg/(s*Pa)", "power law: linear term C_f2 at full opening", 0.0, 0.0, 1.0, slot="pow_c2"),
    _P("valve.power_law_exponent", "", "power law: exponent lambda", 0.25, 0.0, 1.0, True, slot="pow_exp"),
    _P("flow_control.opening_conductance", "m^3/(s*Pa)", "meter-out throttle 2V3 on side B exhaust (sets the opening time); 0 = wide open", 0.0, 0.0, 1e-4, slot="fc_open"),
    _P("flow_control.closing_conductance", "m^3/(s*Pa)", "meter-out throttle 2V2 on side A exhaust (sets the closing time); 0 = wide open", 0.0, 0.0, 1e-4, slot="fc_close"),
    _P("friction.static_force", "N", "static (breakaway) friction F_S per cylinder", None, 0.0, 1e6, fit_bounds=(0.0, 3000.0), slot="f_static"),
    _P("friction.coulomb_force", "N", "Coulomb friction F_C per cylinder", None, 0.0, 1e6, fit_bounds=(0.0, 3000.0), slot="f_coulomb"),
    _P("friction.stribeck_velocity", "m/s", "Stribeck velocity v_s", None, 0.0, 10.0, True, slot="v_stribeck"),
    _P("friction.viscous_coefficient", "N*s/m", "viscous coefficient b per cylinder", None, 0.0, 1e7, fit_bounds=(0.0, 5000.0), slot="viscous"),
    _P("friction.limit_velocity", "m/s", "limit speed below which the body sticks (variable viscous model)", 0.001, 0.0, 1.0, True, slot="v_limit"),
    # LuGre pre-sliding fit ranges span pneumatic seals (Canudas de Wit et al. 1995: sigma0 ~ 1e5..1e8 N/m)
    _P("friction.bristle_stiffness", "N/m", "LuGre bristle stiffness sigma0", 1e6, 0.0, 1e12, True, fit_bounds=(1e5, 1e8), slot="sigma0"),
    _P("friction.bristle_damping", "N*s/m", "LuGre bristle damping sigma1", 3.873e3, 0.0, 1e9, fit_bounds=(0.0, 1e5), slot="sigma1"),
    _P("end_stop.stiffness", "N/m", "end-stop contact stiffness", 1e8, 0.0, 1e12, True, slot="k_stop"),
    _P("end_stop.damping", "N*s/m", "end-stop contact damping", 5e4, 0.0, 1e10, slot="c_stop"),
    _P("load.nominal_force", "N", "nominal closing load F_Cn", 0.0, -1e7, 1e7),
    # the load curve's forces as the model applies them: drawn forces x this factor (PlantConfig.load_curve_forces)
    _P("load.curve_scale", "", "factor on every force of the load curve [load.curve] (1 = as drawn)", 1.0, 0.0, 10.0),
    _P("controller.kp", "V/m", "proportional gain K_P", 0.0, 0.0, 1e7, slot="kp"),
    _P("controller.ki", "V/(m*s)", "integral gain K_I", 0.0, 0.0, 1e7, slot="ki"),
    _P("controller.kd", "V*s/m", "derivative gain K_D", 0.0, 0.0, 1e7, slot="kd"),
    _P("controller.sample_time", "s", "controller sample time (zero-order hold)", None, 0.0, 1.0, True, slot="ts"),
    _P("controller.filter_cutoff", "Hz", "first-order position filter cut-off (0 = no filter)", 0.0, 0.0, 1e5, slot="filt_hz"),
    _P("controller.compensation_width", "V", "dead-zone compensation smoothing width lc", 0.0, 0.0, 10.0, slot="lc"),
    _P("controller.compensation_dead_zone_positive", "V", "compensator's zmd", 0.0, 0.0, 10.0, slot="cdz_pos"),
    _P("controller.compensation_dead_zone_negative", "V", "compensator's |zme|", 0.0, 0.0, 10.0, slot="cdz_neg"),
    _P("controller.compensation_slope_positive", "", "compensator's md", 1.0, 0.0, 100.0, True, slot="cslope_pos"),
    _P("controller.compensation_slope_negative", "", "compensator's me", 1.0, 0.0, 100.0, True, slot="cslope_neg"),
    # --- set-point rate limiter of the PID governor (IEEE PES TR 2013 gate rate limits; end zone: our form)
    _P("controller.setpoint_opening_rate", "m/s", "set-point rate limit while opening (x rising); 0 = not limited", 0.0, 0.0, 100.0, slot="rl_open"),
    _P("controller.setpoint_closing_rate", "m/s", "set-point rate limit while closing (x falling); 0 = not limited", 0.0, 0.0, 100.0, slot="rl_close"),
    _P("controller.end_zone_rate", "m/s", "slower set-point rate inside the end zone toward the near end stop; 0 = none", 0.0, 0.0, 100.0, slot="rl_end_rate"),
    _P("controller.end_zone_width", "m", "width of the end zone at each end of the stroke", 0.0, 0.0, 5.0, slot="rl_end_width"),
    _P("controller.setpoint_lead_limit", "m", "the limited set-point holds while it leads the gate by more than this; 0 = never holds", 0.0, 0.0, 5.0, slot="rl_lead"),
    _P("simulation.step", "s", "fixed integration step (pinned for determinism)", 1e-4, 0.0, 0.01, True),
    # --- piecewise Stribeck friction, seed 001 eq. (8) (friction.model = "piecewise_stribeck")
    _P("friction.breakaway_force", "N", "seed 001 eq. (8) F_j: friction at rest (piecewise Stribeck model)", 0.0, 0.0, 1e6, slot="f_breakaway"),
    _P("friction.low_speed_coefficient", "N*s/m", "seed 001 eq. (8) k_v1: friction drop per speed below v_d", 0.0, 0.0, 1e7, slot="kv_low"),
    _P("friction.critical_velocity", "m/s", "seed 001 eq. (8) v_d: speed where the friction stops falling", 0.01, 0.0, 10.0, True, slot="v_critical"),
    _P("friction.high_speed_coefficient", "N*s/m", "seed 001 eq. (8) k_v2: viscous slope above v_d", 0.0, 0.0, 1e7, slot="kv_high"),
    # --- state feedback with observers, seed 001 eqs. (10)-(11) (controller.type = "state_feedback")
    _P("controller.closed_loop_bandwidth", "rad/s", "state feedback: magnitude of the three placed closed-loop poles", 0.0, 0.0, 1e5),
    _P("controller.closed_loop_damping", "", "state feedback: damping ratio of the placed complex pole pair", 0.7, 0.0, 1.0, True),
    _P("controller.acceleration_observer_bandwidth", "rad/s", "pole of the reduced-order acceleration observer (seed 001 eq. 10)", 0.0, 0.0, 1e6),
    _P("controller.friction_observer_bandwidth", "rad/s", "pole of the reduced-order friction-force observer (seed 001 eq. 11)", 0.0, 0.0, 1e6),
    _P("controller.velocity_filter_cutoff", "Hz", "first-order filter on the differentiated position (0 = no filter)", 0.0, 0.0, 1e5),
)

BASE_BY_KEY: dict[str, Param] = {p.name: p for p in BASE_PARAMS}


# ----------------------------------------------------------------------- the one parameter handle
EFFECTS_PREFIX = "effects."
# prior width of a refitted parameter: a factor of 2 (log-scaled) or its own size (linear) is one
# standard deviation; the data must pay for moving it further (govcheck's choice)
PRIOR_FACTOR = 2.0


@dataclass(frozen=True)
class ParamHandle:
    """One tunable parameter: where it lives in a plant, its SI unit, bounds and scale, how to set it.

    Attributes
    ----------
    path : str
        The one canonical spelling, the key path of a plant file: ``section.name`` for a base
        parameter (``controller.kp``), ``effects.NAME.PARAM`` for a declared effect's
        (``effects.internal_leakage.conductance``). :func:`param_handle` also accepts ``NAME.PARAM``.
    unit : str
        SI unit (pint syntax; ``""`` dimensionless).
    low, high : float
        Bounds [SI]: the admissible range, or the narrower range a fit or search moves it in
        (:meth:`within`).
    log : bool
        Fitted and searched as log10 of the value (ranges spanning decades).
    meaning : str
        One line for reports.
    kind : str
        ``"base"``, ``"effect"``, or ``"instrument"`` (a recording-side quantity the diagnosis fits
        on the logger, never set on the plant).
    nominal : float or None
        Value a fit starts from and its prior is centred on (the declared default unless set; None:
        a required base parameter without one).
    prior : bool
        A fit adds a residual pulling it towards ``nominal`` (:meth:`prior_residual`).
    pressure : bool
        An absolute pressure: values in files must say ``abs`` or ``gauge``.
    scales : tuple of str
        Base paths this one multiplies together (the diagnosis's ``friction.level``, one factor on
        the static and Coulomb forces); empty: it sets its own path.
    reason : str
        Why the bounds are these, when a table narrows them (the calibration's unstated values).
    """

    path: str
    unit: str
    low: float
    high: float
    log: bool = False
    meaning: str = ""
    kind: str = "base"
    nominal: float | None = None
    prior: bool = False
    pressure: bool = False
    scales: tuple[str, ...] = ()
    reason: str = ""

    @property
    def effect(self) -> str | None:
        """The effect name of an effect parameter (None otherwise)."""
        return self.path.split(".")[1] if self.kind == "effect" else None

    @property
    def name(self) -> str:
        """The parameter's key inside its effect or section (the last part of the path)."""
        return self.path.rsplit(".", 1)[-1]

    @property
    def key(self) -> str:
        """The name the diagnosis reports print: an effect parameter as ``NAME.PARAM``, others as the path."""
        return self.path[len(EFFECTS_PREFIX):] if self.kind == "effect" else self.path

    def within(self, low: float, high: float, log: bool | None = None, reason: str = "") -> ParamHandle:
        """The same parameter moved only inside [low, high] (SI), optionally on another scale, saying why."""
        return replace(self, low=low, high=high, log=self.log if log is None else log, reason=reason)

    def value_in(self, cfg) -> float:
        """SI value in configuration ``cfg`` (an effect that is off gives its declared default; a factor 1)."""
        if self.kind == "effect":
            here = cfg.effects.get(self.effect, {})
            return float(here[self.name] if self.name in here else EFFECTS[self.effect].param(self.name).default)
        if self.scales:
            return 1.0
        if self.kind == "instrument":
            return self.nominal
        return float(cfg.params[self.path])

    def apply(self, cfg, value: float):
        """``cfg`` with this parameter at ``value`` [SI] (:func:`apply`)."""
        return apply(cfg, (self,), (value,))

    def to_unit(self, value: float) -> float:
        """Value [SI] -> search coordinate u in [0, 1] over the bounds (log10 of the value when ``log``)."""
        v = min(max(value, self.low), self.high)
        if self.log:
            return (math.log10(v) - math.log10(self.low)) / (math.log10(self.high) - math.log10(self.low))
        return (v - self.low) / (self.high - self.low)

    def from_unit(self, u: float) -> float:
        """Search coordinate u (clipped to [0, 1]) -> value [SI]."""
        u = min(max(float(u), 0.0), 1.0)
        if self.log:
            return 10.0 ** (math.log10(self.low) + u * (math.log10(self.high) - math.log10(self.low)))
        return self.low + u * (self.high - self.low)

    def prior_residual(self, value: float) -> float:
        """(value - nominal) in prior standard deviations (``PRIOR_FACTOR``; 0 without a prior)."""
        if not self.prior:
            return 0.0
        if self.log:
            return math.log(value / self.nominal) / math.log(PRIOR_FACTOR)
        scale = abs(self.nominal) if self.nominal != 0.0 else (self.high - self.low) / 10.0
        return (value - self.nominal) / scale

    def stderr(self, value: float, sigma_u: float) -> float:
        """Standard error [SI] at ``value`` from the standard error ``sigma_u`` of the search coordinate."""
        if self.log:
            return value * math.log(10.0) * (math.log10(self.high) - math.log10(self.low)) * sigma_u
        return (self.high - self.low) * sigma_u


def _effect_handle(path: str, effect: str, name: str, where: str) -> ParamHandle:
    eff = EFFECTS[effect]
    try:
        prm = eff.param(name)
    except KeyError:
        names = [p.name for p in eff.params]
        raise InputError(f"{where}: effect {eff.name} has no parameter '{name}' "
                         f"(it has {', '.join(names)}){did_you_mean(name, names)}") from None
    return ParamHandle(f"{EFFECTS_PREFIX}{effect}.{name}", prm.unit, prm.bounds[0], prm.bounds[1], prm.log_scale,
                       prm.meaning, "effect", prm.default, pressure=prm.pressure)


def param_handle(path: str, where: str) -> ParamHandle:
    """The handle of a parameter path in any spelling: the one normaliser of parameter paths.

    Parameters
    ----------
    path : str
        ``section.name`` (a base parameter), ``effects.NAME.PARAM`` (canonical for an effect
        parameter) or ``NAME.PARAM`` (the diagnosis's spelling).
    where : str
        The file and field (or option) the path came from, for the message.

    Raises
    ------
    InputError
        An unknown path (with the nearest spelling), or a bare power-law coefficient (no unit).
    """
    parts = path.split(".")
    if path.startswith(EFFECTS_PREFIX):
        if len(parts) != 3 or parts[1] not in EFFECTS:
            name = parts[1] if len(parts) > 1 else ""
            raise InputError(f"{where}: '{path}' is not a declared parameter path (effects.NAME.PARAM with NAME one of "
                             f"{', '.join(sorted(EFFECTS))}){did_you_mean(name, EFFECTS)}")
        return _effect_handle(path, parts[1], parts[2], where)
    if len(parts) == 2 and parts[0] in EFFECTS:
        return _effect_handle(path, parts[0], parts[1], where)
    spec = BASE_BY_KEY.get(path)
    if spec is None:
        known = [*BASE_BY_KEY, *(f"{EFFECTS_PREFIX}{e.name}.{q.name}" for e in EFFECTS.values() for q in e.params)]
        raise InputError(f"{where}: '{path}' is not a known parameter path{did_you_mean(path, known)} "
                         "(docs/physics.md lists the parameters; effect parameters are effects.NAME.PARAM)")
    if spec.unit == "number":
        raise InputError(f"{where}: '{path}' is a bare power-law coefficient; sweep a parameter with a unit")
    return ParamHandle(path, spec.unit, spec.bounds[0], spec.bounds[1], spec.log_scale, spec.meaning, "base",
                       spec.default, pressure=spec.pressure)


def apply(cfg, handles, values, *, source: str | None = None):
    """``cfg`` with ``values`` set, one SI float per handle: the one way values reach a configuration.

    Effects named are switched on (their other parameters as in ``cfg``, else at their defaults);
    a factor (``scales``) multiplies the base values it names; instrument handles are skipped (they
    act on the logger). Nothing to set returns ``cfg`` itself.

    Parameters
    ----------
    cfg : PlantConfig
    handles : sequence of ParamHandle
    values : sequence of float
        SI values, one per handle.
    source : str, optional
        Provenance of every base value set (default: ``PlantConfig.replace``'s ``user``).
    """
    base: dict[str, float] = {}
    effects: dict[str, dict[str, float]] = {}
    for h, v in zip(handles, values):
        if h.kind == "instrument":
            continue
        if h.kind == "effect":
            effects.setdefault(h.effect, {})[h.name] = float(v)
        elif h.scales:
            base.update({k: cfg.p(k) * v for k in h.scales})
        else:
            base[h.path] = float(v)
    if not base and not effects:
        return cfg
    return cfg.replace(params=base, effects=effects, sources={k: source for k in base} if source else None)

# option keys (strings / booleans) and their allowed values
OPTIONS: dict[str, tuple[str, ...]] = {
    "cylinder.arrangement": ("tandem", "single"),
    "friction.model": ("lugre", "variable_viscous", "piecewise_stribeck"),
    "valve.flow_law": ("iso6358", "sanville", "bobrow", "power_law"),
    "valve.dynamics_stage": ("spool", "opening"),
    "controller.type": ("pid", "state_feedback"),
    "flow_control.installed": ("true", "false"),
    "controller.friction_compensation": ("true", "false"),
    "controller.feedforward": ("true", "false"),
}
OPTION_DEFAULTS: dict[str, str] = {
    "cylinder.arrangement": "tandem",
    "friction.model": "lugre",
    "valve.flow_law": "iso6358",
    "valve.dynamics_stage": "spool",
    "controller.type": "pid",
    "flow_control.installed": "false",
    "controller.friction_compensation": "false",
    "controller.feedforward": "false",
}
SOURCES = ("paper", "assumed", "derived", "user")


# parameters read only under one option value (assembly.py: the flow law, the friction law and the
# controller type pick their own parameters; the others are not read at all)
_ONLY_WHEN = (
    (("valve.sonic_conductance", "valve.critical_pressure_ratio", "air.reference_density", "air.reference_temperature",
      "flow_control."), "valve.flow_law", ("iso6358",)),
    (("valve.effective_area",), "valve.flow_law", ("sanville",)),
    (("valve.bobrow_coefficient",), "valve.flow_law", ("bobrow",)),
    (("valve.power_law_",), "valve.flow_law", ("power_law",)),
    (("friction.bristle_",), "friction.model", ("lugre",)),
    (("friction.limit_velocity",), "friction.model", ("variable_viscous", "piecewise_stribeck")),
    (("friction.static_force", "friction.coulomb_force", "friction.stribeck_velocity", "friction.viscous_coefficient"),
     "friction.model", ("lugre", "variable_viscous")),
    (("friction.breakaway_force", "friction.low_speed_coefficient", "friction.critical_velocity",
      "friction.high_speed_coefficient"), "friction.model", ("piecewise_stribeck",)),
    (("controller.closed_loop_", "controller.acceleration_observer", "controller.friction_observer",
      "controller.velocity_filter"), "controller.type", ("state_feedback",)),
    (("controller.kp", "controller.ki", "controller.kd", "controller.filter_cutoff", "controller.compensation_"),
     "controller.type", ("pid",)),
)


def used_by_model(key: str, options: dict) -> bool:
    """Whether the selected model (its flow law, friction law, controller) reads parameter ``key``.

    ``options``: the configuration's option values by key (``valve.flow_law`` ...), as strings.
    """
    for prefixes, option, values in _ONLY_WHEN:
        if any(key == p or (p.endswith(("_", ".")) and key.startswith(p)) for p in prefixes):
            return str(options.get(option, "")) in values
    return True
