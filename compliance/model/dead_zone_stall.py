"""The error band in which a PID with the smoothed dead-zone inverse leaves the valve shut."""

from __future__ import annotations

from compliance.model.config import PlantConfig


def stall_error(cfg: PlantConfig, direction: str = "opening") -> float:
    """Error below which the compensated valve stays shut [m] (reference-plant.md, 'Known tension').

    The smoothed branch of seed 000 eq. (3) maps u_d in [0, lc) to u_c = (zmd' + lc/md')/lc * u_d
    (primes: the compensator's own estimates); the valve opens once u_c reaches its real dead zone
    zmd, i.e. at u_d = zmd*lc/(zmd' + lc/md'), so at |e| = that / K_P (derivative and integral
    terms are ~0 at rest). With zme, me for the closing direction; without smoothing (lc = 0) the
    mismatch of the valve and compensator dead zones divided by K_P. Paper values: 0.86 mm.
    """
    p = cfg.params
    if cfg.options["controller.type"] != "pid" or p["controller.kp"] <= 0.0:
        return 0.0
    side = "positive" if direction == "opening" else "negative"
    lc, kp = p["controller.compensation_width"], p["controller.kp"]
    dz_v, dz_c = p[f"valve.dead_zone_{side}"], p[f"controller.compensation_dead_zone_{side}"]
    md = p[f"controller.compensation_slope_{side}"]
    if lc <= 0.0:
        return max(dz_v - dz_c, 0.0) * md / kp
    return dz_v * lc / ((dz_c + lc / md) * kp)
