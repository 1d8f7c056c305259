"""The effect library (names fixed by issue 6; equations in compliance/model/assembly.py cite their sources).

Bounds are physical ranges cut where the pinned RK4 step (1 ms for plant A) would go unstable:
the fastest eigenvalue of each effect times the step stays below ~2 (RK4's limit is 2.8), e.g.
a hose node relaxes at R*T*rho0*C*w'/V, so C/V <= 3e-4 (conductance <= 3e-8 m^3/(s*Pa) with
volume >= 1e-4 m^3); linkage damping/(M/2) and regulator refill R*T*k/V_r likewise. A load
stiffness beyond the pneumatic spring (~1.9e5 N/m) would make the plant statically unstable;
the steepest segment of the sheet's load curve is 1.25e5 N/m.
"""

from __future__ import annotations

from compliance.effects.base import Effect, Lumped, Param

HEAT_TRANSFER = Effect(
    name="heat_transfer",
    meaning="chambers exchange heat with the walls: gas temperature is a state, not the supply temperature",
    params=(Param("conductance", "W/K", "wall heat-transfer conductance hA per side", 10.0, (0.01, 500.0), True),),
    states=("temperature_a", "temperature_b"),
    signature="pressures relax for a fraction of a second after every stop while the position holds",
    signals=("pressure_a", "pressure_b", "valve_command"),
)

INTERNAL_LEAKAGE = Effect(
    name="internal_leakage",
    meaning="laminar leak across the piston seals from side A to side B",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per pressure difference", 1e-10, (1e-13, 1e-8), True),),
    states=(),
    signature="command stays off null while holding a load; the pressure difference sags between corrections",
    signals=("valve_command", "pressure_a", "pressure_b"),
)

EXTERNAL_LEAKAGE = Effect(
    name="external_leakage",
    meaning="laminar leak from each chamber to atmosphere (fittings, rod seals)",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per gauge pressure, each side", 1e-10, (1e-13, 1e-8), True),),
    states=(),
    signature="both chamber pressures sag towards atmosphere at rest; the valve keeps feeding both sides",
    signals=("pressure_a", "pressure_b", "valve_command"),
)

VALVE_DYNAMICS = Effect(
    name="valve_dynamics",
    meaning="the valve opening follows the command through a pure delay and a second-order spool response",
    params=(
        Param("natural_frequency", "rad/s", "spool natural frequency", 60.0, (5.0, 1000.0), True),
        Param("damping", "", "spool damping ratio", 0.7, (0.1, 3.0)),
        Param("delay", "s", "pure delay between command and spool", 0.005, (0.0, 0.05)),
    ),
    states=("spool_position", "spool_velocity"),
    signature="pressures lag the command after every command change; the loop rings more at steps",
    signals=("pressure_a", "pressure_b", "valve_command", "position"),
    # phase lag of e^(-s t_d)/(s^2/w^2 + 2 zeta s/w + 1) at w << w_n: w (t_d + 2 zeta/w_n)
    lumped=Lumped("total_lag", "s", "delay + 2 zeta / w_n: the spool's total lag as the loop sees it",
                  lambda p: p["delay"] + 2.0 * p["damping"] / p["natural_frequency"]),
)

SUPPLY_DROOP = Effect(
    name="supply_droop",
    meaning="supply pressure sags under flow: finite reservoir refilled through a regulator",
    params=(
        Param("reservoir_volume", "m^3", "reservoir plus supply line volume", 0.02, (1e-3, 0.5), True),
        Param("regulator_conductance", "kg/(s*Pa)", "regulator refill flow per pressure deficit", 1e-7, (1e-10, 1e-5), True),
    ),
    states=("supply_pressure",),
    signature="supply pressure dips during fast moves; the filling side's pressure rises more slowly than modelled",
    signals=("supply_pressure", "pressure_a", "pressure_b"),
)

PRESSURE_DEPENDENT_FRICTION = Effect(
    name="pressure_dependent_friction",
    meaning="seal friction rises with the pressure behind the seals",
    params=(Param("coefficient", "N/Pa", "added Coulomb and static friction per Pa of mean gauge pressure, per cylinder", 2e-4, (0.0, 5e-3)),),
    states=(),
    signature="larger stick-slip and steady error at high chamber pressures; breakaway needs more pressure difference",
    signals=("position", "valve_command", "pressure_a", "pressure_b"),
)

VALVE_OFFSET = Effect(
    name="valve_offset",
    meaning="null shift of the servo valve: the valve sees the command plus an offset",
    params=(Param("offset", "V", "voltage added to the command at the valve", 0.0, (-1.5, 1.5)),),
    states=(),
    signature="asymmetric response up vs down; the holding command sits off the compensated null",
    signals=("valve_command", "position"),
)

POSITION_DEPENDENT_LOAD = Effect(
    name="position_dependent_load",
    meaning="the load changes along the stroke (gate hydraulic torque stiffness)",
    params=(Param("stiffness", "N/m", "added closing force per metre of opening about mid-stroke", 0.0, (-1.5e5, 1.5e5)),),
    states=(),
    signature="holding pressure difference changes with position more than the nominal load says",
    signals=("pressure_a", "pressure_b", "valve_command"),
)

SENSOR_LAG = Effect(
    name="sensor_lag",
    meaning="the position transducer reports a delayed, low-passed position",
    params=(
        Param("time_constant", "s", "first-order lag of the transducer", 0.005, (0.0, 0.1)),
        Param("delay", "s", "pure delay of the transducer", 0.0, (0.0, 0.05)),
    ),
    states=("sensor_position",),
    signature="measured position lags the pressures' force; overshoot and ringing larger than modelled",
    signals=("position", "valve_command"),
    # phase lag of e^(-s t_d)/(1 + s tau) at w << 1/tau: w (t_d + tau)
    lumped=Lumped("total_lag", "s", "delay + time constant: the transducer's total lag as the loop sees it",
                  lambda p: p["time_constant"] + p["delay"]),
)

LINE_DYNAMICS = Effect(
    name="line_dynamics",
    meaning="hoses between valve and cylinders add volume and a flow restriction",
    params=(
        Param("volume", "m^3", "hose volume per side", 2e-4, (1e-4, 5e-3), True),
        Param("conductance", "m^3/(s*Pa)", "sonic conductance of each hose", 3e-8, (1e-9, 3e-8), True),
    ),
    states=("line_pressure_a", "line_pressure_b"),
    signature="chamber pressures respond later and smoother than the valve command; the loop is less damped",
    signals=("pressure_a", "pressure_b", "valve_command"),
)

LINKAGE_COMPLIANCE = Effect(
    name="linkage_compliance",
    meaning="the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1",
    params=(
        Param("stiffness", "N/m", "linkage stiffness between the cylinders", 2e6, (1e4, 5e7), True),
        Param("damping", "N*s/m", "linkage damping", 2000.0, (0.0, 1e4)),
    ),
    states=("position_2", "velocity_2"),
    signature="a resonance at the linkage frequency rings in command and pressures after steps",
    signals=("valve_command", "pressure_a", "pressure_b", "position"),
)

ALL_EFFECTS = (
    HEAT_TRANSFER,
    INTERNAL_LEAKAGE,
    EXTERNAL_LEAKAGE,
    VALVE_DYNAMICS,
    SUPPLY_DROOP,
    PRESSURE_DEPENDENT_FRICTION,
    VALVE_OFFSET,
    POSITION_DEPENDENT_LOAD,
    SENSOR_LAG,
    LINE_DYNAMICS,
    LINKAGE_COMPLIANCE,
)
