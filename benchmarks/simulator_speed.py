"""Simulator speed: real-time factor of a 30 s closed-loop plant-A run, the ratio against an
independent scipy solve_ivp (Radau) implementation of the same equations, measured in the same run,
and the cost of one evaluation of the compiled right-hand side (a compiled loop of 10^6 calls at
plant A's rest state, every effect off: the branches of the whole library are in it).

Run: .venv/bin/python benchmarks/simulator_speed.py
Not part of the timed test suite.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from compliance.model.config import load_plant  # noqa: E402
from compliance.simulation.profiles import Profile, steps  # noqa: E402
from compliance.simulation import Scenario  # noqa: E402
from compliance.plants import simulate  # noqa: E402
from tests.simulation import reference_model as ref  # noqa: E402


def practice_profile(x0: float) -> Profile:
    """2/5/10 % steps then an 8 mm sinusoid, like the practice recordings (30 s)."""
    import numpy as np

    st = steps("2%@2s,-2%@5s,5%@8s,-5%@11s,10%@14s,-10%@17s", x0, 0.16)
    t = np.concatenate([st.times, 20 + np.linspace(0, 10, 2001)])
    v = np.concatenate([st.values, x0 + 8e-3 * np.sin(np.pi / 10 * np.linspace(0, 10, 2001))])
    return Profile(t, v)


def best_of(fn, n=5):
    best = float("inf")
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def rhs_nanoseconds(cfg, x0: float, load: float, n: int = 1_000_000) -> float:
    """Best of 5 of one ``model.assembly.plant_rhs`` evaluation [ns], in a compiled loop at the rest state."""
    from numba import njit

    from compliance.model.assembly import plant_rhs
    from compliance.model.plant_vector import load_curve_arrays, parameter_vector
    from compliance.model.rest_state import initial_state
    from compliance.simulation.rk4 import rk4_workspace

    P = parameter_vector(cfg, load=load)
    y = initial_state(cfg, P, x0, None)
    lx, ly = load_curve_arrays(cfg)
    dy, _, _, _, _, aux = rk4_workspace()

    @njit
    def loop(y, P, lx, ly, dy, aux, n):
        s = 0.0
        for i in range(n):
            plant_rhs(y, P, 5.0 + 1e-9 * i, lx, ly, dy, aux)  # a command that moves: nothing is hoisted out
            s += dy[0]
        return s

    loop(y, P, lx, ly, dy, aux, 10)
    return best_of(lambda: loop(y, P, lx, ly, dy, aux, n)) / n * 1e9


def main() -> None:
    cfg = load_plant("plant-a")
    x0, load = 0.08, 7000.0
    sc30 = Scenario(duration=30.0, initial_position=x0, reference=practice_profile(x0), load=load)
    simulate(cfg, sc30)  # compile / load the cache
    t30 = best_of(lambda: simulate(cfg, sc30))
    print(f"compiled core: 30 s closed loop in {t30 * 1e3:.1f} ms -> real-time factor {30.0 / t30:.0f}x "
          f"(step {cfg.p('simulation.step') * 1e3:.2f} ms RK4, 1 ms controller)")

    # same equations, same 2 % step, 1.5 s: compiled core vs solve_ivp Radau (rtol 1e-6)
    prof = steps("2%@0.1s", 0.136, 0.16)
    c6 = cfg.replace(params={"controller.kd": 6.0})
    sc = Scenario(duration=1.5, initial_position=0.136, reference=prof, load=11400.0)
    t_fast = best_of(lambda: simulate(c6, sc), 10)
    t0 = time.perf_counter()
    ref.run(0.136, 11400.0, 6.0, lambda tt: float(prof.at(tt)), 1.5, rtol=1e-6)
    t_ref = time.perf_counter() - t0
    print(f"2 % step, 1.5 s: compiled {t_fast * 1e3:.2f} ms, solve_ivp Radau {t_ref:.2f} s -> "
          f"{t_ref / t_fast:.0f}x faster than the reference")
    print(f"right-hand side: {rhs_nanoseconds(cfg, x0, load):.0f} ns per evaluation (4 per 1 ms RK4 step)")


if __name__ == "__main__":
    main()
