"""The effect library (names are a stable interface; equations in compliance/model/assembly.py cite their sources).

Bounds are physical ranges cut where the pinned RK4 step (1 ms for plant A) would go unstable:
the fastest eigenvalue of each effect times the step stays below ~2 (RK4's limit is 2.8), e.g.
a hose node relaxes at R*T*rho0*C*w'/V, so C/V <= 3e-4; the hose conductance is bounded at
1e-7 m^3/(s*Pa) (a hose is less restrictive than the 2.33e-8 valve: an independent bench's
7e-4 m^3 hose has 4.5e-8), so small volumes with large
conductances (C/V > 3e-4) are admissible but diverge at the 1 ms step: the simulator reports
it, the diagnosis scores such a trial as a failed fit; linkage damping/(M/2) and regulator
refill R*T*k/V_r are cut by the same rule. A load
stiffness beyond the pneumatic spring (~1.9e5 N/m) would make the plant statically unstable;
the steepest segment of the sheet's load curve is 1.25e5 N/m.
"""

from __future__ import annotations

from compliance.effects.base import Effect, Lumped, State
from compliance.effects.param import Param

HEAT_TRANSFER = Effect(
    name="heat_transfer",
    meaning="chambers exchange heat with the walls: gas temperature is a state, not the supply temperature",
    short="ht",
    params=(Param("conductance", "W/K", "wall heat-transfer conductance hA per side", 10.0, (0.01, 500.0), True,
                  slot="ha", aliases=("hA",)),),
    states=(State("temperature_a", "TA", 4), State("temperature_b", "TB", 5)),
    signature="pressures relax for a fraction of a second after every stop while the position holds",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the chamber air exchanges heat with the cylinder walls instead of staying at supply temperature (wall conductance hA {v} per side)",
    fit_grid={"conductance": (0.3, 1.0, 3.0, 10.0, 30.0, 100.0)},
    draw={"conductance": (3.0, 60.0, True)},
)

INTERNAL_LEAKAGE = Effect(
    name="internal_leakage",
    meaning="laminar leak across the piston seals from side A to side B",
    short="il",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per pressure difference", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_int",)),),
    states=(),
    signature="command stays off null while holding a load; the pressure difference sags between corrections",
    signals=("valve_command", "pressure_a", "pressure_b"),
    explanation="air leaks across the piston seals from side A to side B (laminar leak {v})",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (5e-11, 5e-10, True)},
)

EXTERNAL_LEAKAGE = Effect(
    name="external_leakage",
    meaning="laminar leak from each chamber to atmosphere (fittings, rod seals)",
    short="el",
    params=(Param("conductance", "kg/(s*Pa)", "leak mass flow per gauge pressure, each side", 1e-10, (1e-13, 1e-8), True,
                  slot="k", aliases=("k_ext",)),),
    states=(),
    signature="both chamber pressures sag towards atmosphere at rest; the valve keeps feeding both sides",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="both chambers leak to atmosphere through fittings or rod seals (laminar leak {v} per side)",
    fit_grid={"conductance": (3e-12, 1e-11, 3e-11, 1e-10, 3e-10, 1e-9)},
    draw={"conductance": (3e-11, 3e-10, True)},
)

VALVE_DYNAMICS = Effect(
    name="valve_dynamics",
    meaning="the valve opening follows the command through a pure delay and a second-order spool response",
    short="vd",
    params=(
        Param("natural_frequency", "rad/s", "spool natural frequency", 60.0, (5.0, 1000.0), True, slot="wn", aliases=("wv",)),
        Param("damping", "", "spool damping ratio", 0.7, (0.1, 3.0), slot="z", aliases=("zv",)),
        Param("delay", "s", "pure delay between command and spool", 0.005, (0.0, 0.05), slot="td", aliases=("td_valve",)),
    ),
    states=(State("spool_position", "SP", 10), State("spool_velocity", "SV", 11)),
    signature="pressures lag the command after every command change; the loop rings more at steps",
    signals=("pressure_a", "pressure_b", "valve_command", "position"),
    input_delay="delay",
    plant_b=True,  # the spool's lag, yes; a non-zero delay, no (input_delay)
    explanation="the servo valve does not open instantly: its spool follows the command with a delay and a second-order lag (natural frequency {v})",
    # a spool near the loop's bandwidth trades frequency, damping and delay: start in each basin
    fit_grid={"natural_frequency": (20.0, 30.0, 45.0, 70.0, 120.0, 250.0), "damping": (0.5, 1.0),
              "delay": (0.0, 0.006, 0.012, 0.02)},
    draw={"natural_frequency": (25.0, 80.0, True), "damping": (0.4, 1.0, False), "delay": (0.002, 0.015, False)},
    # phase lag of e^(-s t_d)/(s^2/w^2 + 2 zeta s/w + 1) at w << w_n: w (t_d + 2 zeta/w_n)
    lumped=Lumped("total_lag", "s", "delay + 2 zeta / w_n: the spool's total lag as the loop sees it",
                  lambda p: p["delay"] + 2.0 * p["damping"] / p["natural_frequency"]),
)

SUPPLY_DROOP = Effect(
    name="supply_droop",
    meaning="supply pressure sags under flow: finite reservoir refilled through a regulator",
    short="sd",
    params=(
        Param("reservoir_volume", "m^3", "reservoir plus supply line volume", 0.02, (1e-3, 0.5), True, slot="vol",
              aliases=("Vr",)),
        Param("regulator_conductance", "kg/(s*Pa)", "regulator refill flow per pressure deficit", 1e-7, (1e-10, 1e-5), True,
              slot="cond"),
    ),
    states=(State("supply_pressure", "PSUP", 12),),
    signature="supply pressure dips during fast moves; the filling side's pressure rises more slowly than modelled",
    signals=("supply_pressure", "pressure_a", "pressure_b"),
    explanation="the supply pressure sags while the valve draws air: the reservoir is finite and the regulator refills it slowly (reservoir {v})",
    fit_grid={"reservoir_volume": (0.003, 0.02, 0.1), "regulator_conductance": (1e-8, 1e-7, 1e-6)},
    draw={"reservoir_volume": (0.003, 0.03, True), "regulator_conductance": (1e-8, 1e-7, True)},
)

PRESSURE_DEPENDENT_FRICTION = Effect(
    name="pressure_dependent_friction",
    meaning="seal friction rises with the pressure behind the seals: F_C and F_S scale by 1 + k (mean gauge pressure)",
    short="pf",
    # a lip seal's friction is its contact pressure times area; the pressure behind the lip adds to the
    # contact pressure, so both levels scale with it (Belforte et al. 2003) and the Stribeck shape is kept;
    # 5e-6 /Pa (0.5 per bar) nearly triples the friction at the mean gauge pressure of an 8 bar supply
    params=(Param("coefficient", "1/Pa", "relative rise of Coulomb and static friction per Pa of mean chamber gauge pressure",
                  5e-7, (0.0, 5e-6), slot="coef", aliases=("kp_fric",)),),
    states=(),
    signature="larger stick-slip and steady error at high chamber pressures; breakaway needs more pressure difference",
    signals=("position", "valve_command", "pressure_a", "pressure_b"),
    explanation="the seal friction grows with the chamber pressure (friction levels x (1 + k p_gauge), k = {v})",
    fit_grid={"coefficient": (2e-7, 6e-7, 1.5e-6, 3e-6)},
    draw={"coefficient": (6e-7, 3e-6, True)},
)

VALVE_OFFSET = Effect(
    name="valve_offset",
    meaning="null shift of the servo valve: the valve sees the command plus an offset",
    short="vo",
    params=(Param("offset", "V", "voltage added to the command at the valve", 0.0, (-1.5, 1.5), slot="off", aliases=("u0",)),),
    states=(),
    signature="asymmetric response up vs down; the holding command sits off the compensated null",
    signals=("valve_command", "position"),
    explanation="the servo valve's null is shifted: the valve sees the command plus an offset of {v}",
    fit_grid={"offset": (-0.4, -0.2, -0.1, 0.1, 0.2, 0.4)},
    draw={"offset": (0.05, 0.4, True)},
    draw_signed=True,
)

POSITION_DEPENDENT_LOAD = Effect(
    name="position_dependent_load",
    meaning="the load changes along the stroke (gate hydraulic torque stiffness)",
    short="pl",
    params=(Param("stiffness", "N/m", "added closing force per metre of opening (the core: about mid-stroke; the diagnosis: about the test's start)", 0.0, (-1.5e5, 1.5e5), slot="k",
                  aliases=("kL",)),),
    states=(),
    signature="holding pressure difference changes with position more than the nominal load says",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the load changes along the stroke more than the nominal load says (stiffness {v})",
    fit_grid={"stiffness": (-1e5, -3e4, -1e4, 1e4, 3e4, 1e5)},
    draw={"stiffness": (2e4, 1e5, True)},
    draw_signed=True,
)

SENSOR_LAG = Effect(
    name="sensor_lag",
    meaning="the position transducer reports a delayed, low-passed position",
    short="sl",
    params=(
        Param("time_constant", "s", "first-order lag of the transducer", 0.005, (0.0, 0.1), slot="tau", aliases=("tau_s",)),
        Param("delay", "s", "pure delay of the transducer", 0.0, (0.0, 0.05), slot="td", aliases=("td_s",)),
    ),
    states=(),
    loop_states=("sensor_position",),  # the PID loop filters the sampled position exactly (compliance.simulation.pid_loop)
    signature="measured position lags the pressures' force; overshoot and ringing larger than modelled",
    signals=("position", "valve_command"),
    output_lag="time_constant",
    output_delay="delay",
    plant_b=False,  # the state-feedback loop differentiates the raw position; it has no transducer filter
    explanation="the position transducer reports a delayed, low-passed position (time constant {v})",
    fit_grid={"time_constant": (0.002, 0.004, 0.008, 0.015, 0.03, 0.06), "delay": (0.0, 0.002, 0.004, 0.007)},
    draw={"time_constant": (0.003, 0.03, True), "delay": (0.0, 0.004, False)},
    # phase lag of e^(-s t_d)/(1 + s tau) at w << 1/tau: w (t_d + tau)
    lumped=Lumped("total_lag", "s", "delay + time constant: the transducer's total lag as the loop sees it",
                  lambda p: p["time_constant"] + p["delay"]),
)

LINE_DYNAMICS = Effect(
    name="line_dynamics",
    meaning="hoses between valve and cylinders add volume and a flow restriction",
    short="ld",
    params=(
        Param("volume", "m^3", "hose volume per side", 2e-4, (1e-4, 5e-3), True, slot="vol", aliases=("V_line",)),
        Param("conductance", "m^3/(s*Pa)", "sonic conductance of each hose", 3e-8, (1e-9, 1e-7), True, slot="cond",
              aliases=("C_line",)),
    ),
    states=(State("line_pressure_a", "PLA", 13), State("line_pressure_b", "PLB", 14)),
    signature="chamber pressures respond later and smoother than the valve command; the loop is less damped",
    signals=("pressure_a", "pressure_b", "valve_command"),
    explanation="the hoses between valve and cylinders add volume and a restriction (hose volume {v} per side)",
    fit_grid={"volume": (1e-4, 5e-4, 2e-3), "conductance": (1e-8, 3e-8, 1e-7)},
    draw={"volume": (1e-4, 6e-4, True), "conductance": (5e-9, 3e-8, True)},
)

LINKAGE_COMPLIANCE = Effect(
    name="linkage_compliance",
    meaning="the two cylinders are coupled through a flexible linkage; the sensor sits on 2A1",
    short="lk",
    params=(
        Param("stiffness", "N/m", "linkage stiffness between the cylinders", 2e6, (1e4, 5e7), True, slot="k",
              aliases=("k_link",)),
        Param("damping", "N*s/m", "linkage damping", 2000.0, (0.0, 1e4), slot="c", aliases=("c_link",)),
    ),
    # without the effect 2A2 follows 2A1 and plant_rhs keeps these equal to position and velocity
    states=(State("position_2", "X2", 8), State("velocity_2", "V2", 9)),
    signature="a resonance at the linkage frequency rings in command and pressures after steps",
    signals=("valve_command", "pressure_a", "pressure_b", "position"),
    explanation="the two cylinders are coupled through a flexible linkage (stiffness {v})",
    fit_grid={"stiffness": (3e4, 1e5, 4e5, 1.5e6, 6e6), "damping": (300.0, 3000.0)},
    # only a soft, lightly damped link shows in the pressures: with each cylinder carrying half the load a
    # 40 kN/m link moves them < 1 kPa and 0.07 V (the generated cases' visibility needs 3 kPa or 0.08 V)
    draw={"stiffness": (1e4, 3e4, True), "damping": (20.0, 300.0, True)},
)

VALVE_NULL_FLOW = Effect(
    name="valve_null_flow",
    meaning="the servo valve passes flow near its null: its lands leak, so pressure builds inside the nominal dead zone",
    short="nf",
    params=(
        Param("null_opening", "", "relative opening through which each land leaks at null (leakage / underlap)", 0.003,
              (0.0, 0.05), slot="a0"),
        Param("null_width", "V", "command over which a covered land stops leaking (sets the pressure gain at null)", 0.3,
              (0.05, 2.0), True, slot="w"),
    ),
    states=(),
    signature="steady errors well inside the dead-zone stall band; chamber pressures follow the command at null",
    signals=("position", "pressure_a", "pressure_b", "valve_command"),
    # linear treatment: no state; at the trim (valve at null) the leaks' flow-pressure slope enters the state
    # Jacobian through plant_rhs, and the input column is measured beyond the dead-zone edge (linear/trim.flow_columns)
    plant_b=True,  # acts on the command about the valve centre: plant B's 0-10 V valve alike
    explanation="the servo valve leaks across its lands near null, so the loop keeps a pressure gain inside the "
                "nominal dead zone (leak opening {v} of full opening per land)",
    fit_grid={"null_opening": (0.001, 0.003, 0.01), "null_width": (0.1, 0.3, 0.65)},
    draw={"null_opening": (0.001, 0.01, True), "null_width": (0.1, 0.65, True)},
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
    VALVE_NULL_FLOW,
)
