"""Simulator speed: the compiled loop against its own right-hand-side limit, against an independent
scipy solve_ivp implementation, and against a previous revision, each measured in the same run.

- Real-time factor of a 30 s closed-loop plant-A run (practice profile), through the public
  ``simulate`` (profile sampling, the compiled loop, the DataFrame the caller gets).
- Cost of one evaluation of the compiled right-hand side ``model.assembly.plant_rhs`` [ns]: a
  compiled loop of as many calls as the 30 s run makes (4 per 1 ms RK4 step), at plant A's rest
  state with every effect off (the branches of the whole library are in it).
- The loop's share of its RHS limit = real-time factor x RHS ns x 4 x 1000 / 10^9: 100 % would be
  a loop that costs nothing but its right-hand-side evaluations. (The RHS figure is the cost of
  independent calls; an RK4 step chains its four, so 100 % is out of reach by construction.)
- A 1.5 s 2 % step, compiled vs solve_ivp (Radau, rtol 1e-6) of the same equations
  (``tests/simulation/reference_model.py``, best of 2 runs).

``--against REV`` (default ``main``; ``none`` skips it) checks the revision out in a temporary git
worktree and measures it the same way, in alternating rounds with this tree (each side in its own
process loading its own numba cache, compiled by an untimed process first), and prints the ratios.
Timings are the best of ``--repeat`` runs in each of ``--rounds`` rounds, in wall time (what a user
waits) and in the thread's CPU time (what the machine's other load does not inflate); the load
average is printed.

Run: .venv/bin/python benchmarks/simulator_speed.py [--against main] [--rounds 3] [--repeat 20]
Not part of the timed test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENV = dict(os.environ)  # before compliance is imported (it sets process-wide defaults)
X0, LOAD = 0.08, 7000.0  # practice run: start position [m], closing load [N]
DURATION = 30.0  # s
EVALS_PER_MS = 4  # RK4 at 1 ms: four right-hand-side evaluations per step


def practice_profile(x0: float):
    """2/5/10 % steps then an 8 mm sinusoid, like the practice recordings (30 s)."""
    import numpy as np

    from compliance.simulation.profiles import Profile, steps

    st = steps("2%@2s,-2%@5s,5%@8s,-5%@11s,10%@14s,-10%@17s", x0, 0.16)
    t = np.concatenate([st.times, 20 + np.linspace(0, 10, 2001)])
    v = np.concatenate([st.values, x0 + 8e-3 * np.sin(np.pi / 10 * np.linspace(0, 10, 2001))])
    return Profile(t, v)


def best_of(fn, n: int) -> tuple[float, float]:
    """(best wall time, best thread CPU time) of ``n`` calls [s]."""
    wall = cpu = float("inf")
    for _ in range(n):
        w0, c0 = time.perf_counter(), time.thread_time()
        fn()
        c1, w1 = time.thread_time(), time.perf_counter()
        wall, cpu = min(wall, w1 - w0), min(cpu, c1 - c0)
    return wall, cpu


def rhs_loop(cfg, x0: float, load: float, n: int):
    """A callable running ``n`` compiled ``plant_rhs`` evaluations at the rest state (compiled here)."""
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
    return lambda: loop(y, P, lx, ly, dy, aux, n)


def measure(repeat: int) -> dict:
    """This process's compliance package, timed: the worker side of one round."""
    import compliance
    from compliance.model.config import load_plant
    from compliance.simulation import Scenario
    try:
        from compliance.plants import simulate  # the configuration's plant kind runs the scenario
    except ImportError:  # a revision measured with --against that predates the plant kinds
        from compliance.simulation import simulate
    from compliance.simulation.profiles import steps

    cfg = load_plant("plant-a")
    sc30 = Scenario(duration=DURATION, initial_position=X0, reference=practice_profile(X0), load=LOAD)
    simulate(cfg, sc30)  # compile / load the cache
    step = Scenario(duration=1.5, initial_position=0.136, reference=steps("2%@0.1s", 0.136, 0.16), load=11400.0)
    c6 = cfg.replace(params={"controller.kd": 6.0})
    simulate(c6, step)
    n_evals = int(round(DURATION * 1000 * EVALS_PER_MS))
    rhs = rhs_loop(cfg, X0, LOAD, n_evals)
    run_wall, run_cpu = best_of(lambda: simulate(cfg, sc30), repeat)
    rhs_wall, rhs_cpu = best_of(rhs, repeat)
    step_wall, step_cpu = best_of(lambda: simulate(c6, step), 2 * repeat)
    return {"code": str(Path(compliance.__file__).resolve().parents[1]), "run_wall": run_wall, "run_cpu": run_cpu, "rhs_wall_ns": rhs_wall / n_evals * 1e9,
            "rhs_cpu_ns": rhs_cpu / n_evals * 1e9, "step_wall": step_wall, "step_cpu": step_cpu}


def _side(code: Path, repeat: int) -> dict:
    """One round of one side: a fresh process running ``measure`` on the package in ``code``."""
    env = dict(ENV, PYTHONPATH=str(code))
    env.pop("NUMBA_CACHE_DIR", None)  # each side its own cache, keyed by its own compiled sources
    cmd = [sys.executable, str(Path(__file__).resolve()), "--measure", "--repeat", str(repeat)]
    p = subprocess.run(cmd, cwd=code, capture_output=True, text=True, check=False, env=env)
    if p.returncode != 0:
        raise SystemExit(f"simulator_speed: measuring {code} failed ({p.returncode}): {p.stderr[-2000:]}")
    got = json.loads(p.stdout.strip().splitlines()[-1])
    if Path(got.pop("code")) != code.resolve():
        raise SystemExit(f"simulator_speed: the worker for {code} imported another compliance package")
    return got


def _previous(rev: str, tmp: Path) -> Path:
    """A temporary worktree of ``rev`` (the previous implementation)."""
    where = tmp / "previous"
    subprocess.run(["git", "worktree", "add", "--detach", str(where), rev], cwd=ROOT, check=True, capture_output=True)
    return where


def _best(rounds: list[dict]) -> dict:
    return {k: min(r[k] for r in rounds) for k in rounds[0]}


def share(run_s: float, rhs_ns: float) -> float:
    """The loop's share of its RHS limit: real-time factor x RHS ns x 4 x 1000 / 10^9."""
    return DURATION / run_s * rhs_ns * EVALS_PER_MS * 1000 / 1e9


def _reference_step_seconds(repeat: int = 2) -> tuple[float, float]:
    """(wall, CPU) [s] of the same 1.5 s 2 % step by the independent solve_ivp (Radau) implementation, best of ``repeat``."""
    sys.path.insert(0, str(ROOT))
    from compliance.simulation.profiles import steps
    from tests.simulation import reference_model as ref

    prof = steps("2%@0.1s", 0.136, 0.16)
    return best_of(lambda: ref.run(0.136, 11400.0, 6.0, lambda tt: float(prof.at(tt)), 1.5, rtol=1e-6), repeat)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--against", default="main", help="git revision of the previous implementation, or 'none'")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds (each side in a fresh process)")
    ap.add_argument("--repeat", type=int, default=20, help="timed runs per measurement in each round (best kept)")
    ap.add_argument("--measure", action="store_true", help=argparse.SUPPRESS)  # worker: time this process's package
    args = ap.parse_args()
    if args.measure:
        print(json.dumps(measure(args.repeat)))
        return
    with tempfile.TemporaryDirectory() as d:
        sides = {"this": ROOT}
        if args.against != "none":
            sides["previous"] = _previous(args.against, Path(d))
        try:
            for code in sides.values():
                _side(code, 1)  # compiles this side's numba cache, untimed: every timed process loads it
            rounds: dict[str, list[dict]] = {name: [] for name in sides}
            for _ in range(max(args.rounds, 1)):
                for name, code in sides.items():
                    rounds[name].append(_side(code, args.repeat))
        finally:
            if "previous" in sides:
                subprocess.run(["git", "worktree", "remove", "--force", str(sides["previous"])], cwd=ROOT, check=False)
    ref_wall, ref_cpu = _reference_step_seconds()
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    best = {name: _best(r) for name, r in rounds.items()}
    this = best["this"]
    print(f"simulator, plant A, best of {args.repeat} runs x {args.rounds} rounds (load average at the end {load:.1f}):")
    print(f"compiled core: {DURATION:.0f} s closed loop in {this['run_wall'] * 1e3:.1f} ms -> real-time factor "
          f"{DURATION / this['run_wall']:.0f}x (step 1.00 ms RK4, 1 ms controller); CPU {this['run_cpu'] * 1e3:.1f} ms "
          f"-> {DURATION / this['run_cpu']:.0f}x")
    print(f"right-hand side: {this['rhs_wall_ns']:.0f} ns per evaluation ({this['rhs_cpu_ns']:.0f} ns CPU; "
          f"{EVALS_PER_MS} per 1 ms RK4 step)")
    print(f"loop at {100 * share(this['run_wall'], this['rhs_wall_ns']):.0f} % of its RHS limit "
          f"({100 * share(this['run_cpu'], this['rhs_cpu_ns']):.0f} % in CPU time; target >= 60 %)")
    print(f"2 % step, 1.5 s: compiled {this['step_wall'] * 1e3:.2f} ms, solve_ivp Radau {ref_wall:.2f} s -> "
          f"{ref_wall / this['step_wall']:.0f}x faster than the reference (CPU: {this['step_cpu'] * 1e3:.2f} ms vs "
          f"{ref_cpu:.2f} s -> {ref_cpu / this['step_cpu']:.0f}x)")
    if "previous" in best:
        prev = best["previous"]
        print(f"against {args.against} (same run; previous / this, > 1 = faster now):")
        for label, key in (("30 s run, wall", "run_wall"), ("30 s run, CPU", "run_cpu"),
                           ("2 % step, wall", "step_wall"), ("2 % step, CPU", "step_cpu"),
                           ("right-hand side, CPU", "rhs_cpu_ns")):
            print(f"  {label:22s} {prev[key] / this[key]:5.2f}")
        print(f"  previous loop at {100 * share(prev['run_wall'], prev['rhs_wall_ns']):.0f} % of its RHS limit "
              f"({100 * share(prev['run_cpu'], prev['rhs_cpu_ns']):.0f} % in CPU time)")


if __name__ == "__main__":
    main()
