"""Index layout of the compiled core's parameter vector and state vector.

numba freezes module-level integers as compile-time constants, so the core indexes plain
float arrays with these names at no cost. ``PARAM_NAMES`` / ``STATE_NAMES`` give the same
layout to Python code (assembly, linearisation, diagnosis).
"""

from __future__ import annotations

# ---- parameter vector ------------------------------------------------------------------------
PARAM_NAMES = (
    # geometry and mass
    "stroke", "area_cap", "area_rod", "dead_volume", "mass", "arrangement", "n_friction",
    # air
    "p_supply", "p_atm", "t_supply", "r_gas", "gamma", "rho0", "t0",
    # valve
    "conductance", "b_crit", "dz_pos", "dz_neg", "slope_pos", "slope_neg", "u_sat", "u_centre",
    "flow_law", "eff_area", "bobrow_coef", "pow_c1", "pow_c2", "pow_exp",
    # flow-control valves (meter-out)
    "fc_on", "fc_open", "fc_close",
    # friction
    "fr_model", "f_static", "f_coulomb", "v_stribeck", "viscous", "v_limit", "sigma0", "sigma1",
    # end stops
    "k_stop", "c_stop",
    # load
    "load_mode", "load_const",
    # controller
    "kp", "ki", "kd", "ts", "filt_hz", "lc", "cdz_pos", "cdz_neg", "cslope_pos", "cslope_neg", "u_lim",
    # effects: flag then parameters
    "ht_on", "ht_ha",
    "il_on", "il_k",
    "el_on", "el_k",
    "vd_on", "vd_wn", "vd_zeta", "vd_delay",
    "sd_on", "sd_vol", "sd_cond",
    "pf_on", "pf_coef",
    "vo_on", "vo_offset",
    "pl_on", "pl_stiff",
    "sl_on", "sl_tau", "sl_delay",
    "ld_on", "ld_vol", "ld_cond",
    "lc_on", "lc_stiff", "lc_damp",
    # piecewise Stribeck friction, seed 001 eq. (8) (appended: earlier indices unchanged)
    "f_breakaway", "kv_low", "v_critical", "kv_high",
    # valve dynamics stage: 0 the spool filters the command (before the dead zone), 1 the lag acts on the opening
    "vd_stage",
)
N_PARAMS = len(PARAM_NAMES)
PI = {n: i for i, n in enumerate(PARAM_NAMES)}

P_STROKE = PI["stroke"]
P_AREA_CAP = PI["area_cap"]
P_AREA_ROD = PI["area_rod"]
P_V0 = PI["dead_volume"]
P_MASS = PI["mass"]
P_ARR = PI["arrangement"]
P_NFR = PI["n_friction"]
P_PS = PI["p_supply"]
P_PATM = PI["p_atm"]
P_TS = PI["t_supply"]
P_R = PI["r_gas"]
P_GAMMA = PI["gamma"]
P_RHO0 = PI["rho0"]
P_T0 = PI["t0"]
P_C = PI["conductance"]
P_B = PI["b_crit"]
P_DZP = PI["dz_pos"]
P_DZN = PI["dz_neg"]
P_SLP = PI["slope_pos"]
P_SLN = PI["slope_neg"]
P_USAT = PI["u_sat"]
P_UCEN = PI["u_centre"]
P_LAW = PI["flow_law"]
P_EFFA = PI["eff_area"]
P_BOB = PI["bobrow_coef"]
P_POW1 = PI["pow_c1"]
P_POW2 = PI["pow_c2"]
P_POWE = PI["pow_exp"]
P_FC_ON = PI["fc_on"]
P_FC_OPEN = PI["fc_open"]
P_FC_CLOSE = PI["fc_close"]
P_FRM = PI["fr_model"]
P_FS = PI["f_static"]
P_FC = PI["f_coulomb"]
P_VS = PI["v_stribeck"]
P_BV = PI["viscous"]
P_VLIM = PI["v_limit"]
P_SIG0 = PI["sigma0"]
P_SIG1 = PI["sigma1"]
P_KSTOP = PI["k_stop"]
P_CSTOP = PI["c_stop"]
P_LOADMODE = PI["load_mode"]
P_LOAD = PI["load_const"]
P_KP = PI["kp"]
P_KI = PI["ki"]
P_KD = PI["kd"]
P_TSAMP = PI["ts"]
P_FILT = PI["filt_hz"]
P_LC = PI["lc"]
P_CDZP = PI["cdz_pos"]
P_CDZN = PI["cdz_neg"]
P_CSLP = PI["cslope_pos"]
P_CSLN = PI["cslope_neg"]
P_ULIM = PI["u_lim"]
P_HT_ON = PI["ht_on"]
P_HT_HA = PI["ht_ha"]
P_IL_ON = PI["il_on"]
P_IL_K = PI["il_k"]
P_EL_ON = PI["el_on"]
P_EL_K = PI["el_k"]
P_VD_ON = PI["vd_on"]
P_VD_WN = PI["vd_wn"]
P_VD_Z = PI["vd_zeta"]
P_VD_TD = PI["vd_delay"]
P_SD_ON = PI["sd_on"]
P_SD_VOL = PI["sd_vol"]
P_SD_COND = PI["sd_cond"]
P_PF_ON = PI["pf_on"]
P_PF_COEF = PI["pf_coef"]
P_VO_ON = PI["vo_on"]
P_VO_OFF = PI["vo_offset"]
P_PL_ON = PI["pl_on"]
P_PL_K = PI["pl_stiff"]
P_SL_ON = PI["sl_on"]
P_SL_TAU = PI["sl_tau"]
P_SL_TD = PI["sl_delay"]
P_LD_ON = PI["ld_on"]
P_LD_VOL = PI["ld_vol"]
P_LD_COND = PI["ld_cond"]
P_LK_ON = PI["lc_on"]
P_LK_K = PI["lc_stiff"]
P_LK_C = PI["lc_damp"]
P_FJ = PI["f_breakaway"]
P_KV1 = PI["kv_low"]
P_VD = PI["v_critical"]
P_KV2 = PI["kv_high"]
P_VD_STAGE = PI["vd_stage"]

# effect name -> (flag index, {param name: index}) — the bridge from declarations to the core
EFFECT_SLOTS = {
    "heat_transfer": (P_HT_ON, {"conductance": P_HT_HA}),
    "internal_leakage": (P_IL_ON, {"conductance": P_IL_K}),
    "external_leakage": (P_EL_ON, {"conductance": P_EL_K}),
    "valve_dynamics": (P_VD_ON, {"natural_frequency": P_VD_WN, "damping": P_VD_Z, "delay": P_VD_TD}),
    "supply_droop": (P_SD_ON, {"reservoir_volume": P_SD_VOL, "regulator_conductance": P_SD_COND}),
    "pressure_dependent_friction": (P_PF_ON, {"coefficient": P_PF_COEF}),
    "valve_offset": (P_VO_ON, {"offset": P_VO_OFF}),
    "position_dependent_load": (P_PL_ON, {"stiffness": P_PL_K}),
    "sensor_lag": (P_SL_ON, {"time_constant": P_SL_TAU, "delay": P_SL_TD}),
    "line_dynamics": (P_LD_ON, {"volume": P_LD_VOL, "conductance": P_LD_COND}),
    "linkage_compliance": (P_LK_ON, {"stiffness": P_LK_K, "damping": P_LK_C}),
}

# ---- state vector ----------------------------------------------------------------------------
STATE_NAMES = (
    "position", "velocity", "pressure_a", "pressure_b", "temperature_a", "temperature_b",
    "bristle_1", "bristle_2", "position_2", "velocity_2", "spool_position", "spool_velocity",
    "supply_pressure", "line_pressure_a", "line_pressure_b",
)
N_STATES = len(STATE_NAMES)
S_X, S_V, S_PA, S_PB, S_TA, S_TB, S_Z1, S_Z2, S_X2, S_V2, S_SP, S_SV, S_PSUP, S_PLA, S_PLB = range(N_STATES)

# ---- auxiliary outputs of the right-hand side ---------------------------------------------------
AUX_NAMES = ("friction_force", "load_force", "flow_a", "flow_b", "opening", "pneumatic_force", "supply_flow")
N_AUX = len(AUX_NAMES)
A_FRIC, A_LOAD, A_QA, A_QB, A_OPEN, A_FP, A_QS = range(N_AUX)
