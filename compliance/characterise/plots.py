"""Figures for the characterisation results (matplotlib, no display needed)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from compliance.errors import InputError


def _figure(rows: int):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt, *plt.subplots(rows, 1, figsize=(7.5, 3.4 * rows), squeeze=False)


def _save(plt, fig, path) -> None:
    try:
        from compliance.files.atomic import write_atomic_with

        fig.tight_layout()
        write_atomic_with(Path(path), lambda tmp: fig.savefig(tmp, dpi=120))  # format from the suffix, atomic
    except (OSError, ValueError) as exc:
        raise InputError(f"--plot {path}: cannot write the figure ({exc})") from None
    finally:
        plt.close(fig)


def plot_valve(result, path) -> None:
    """Measured mass flow against pressure ratio, with every fitted law (cf. seed 001 figs. 2-4)."""
    plt, fig, axes = _figure(2)
    ratio = result.p_down / result.p_up
    ax = axes[0][0]
    ax.plot(ratio, result.mass_flow * 1e3, ".", ms=2, color="0.6", label="measured (V/(gamma R T) dp/dt)")
    order = np.argsort(ratio)
    for fit in result.fits:
        q = fit.predict(result.p_up, result.p_down, result.t_up)
        ax.plot(ratio[order], q[order] * 1e3, lw=1.4, label=f"{fit.law} (AIC {fit.aic:.0f})")
    ax.set_xlabel("pressure ratio p_down / p_up [-]")
    ax.set_ylabel("mass flow [g/s]")
    ax.legend(fontsize=7)
    ax.set_title(f"{Path(result.source).name}: {result.mode}, V = {result.volume * 1e3:.3g} L")
    ax = axes[1][0]
    best = result.best
    ax.plot(result.time, (result.mass_flow - best.predict(result.p_up, result.p_down, result.t_up)) * 1e3, lw=0.8)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"residual of {best.law} [g/s]")
    _save(plt, fig, path)


def plot_friction(result, path) -> None:
    """Friction against velocity per run, bin medians and the fitted maps (cf. seed 000 fig. 3)."""
    plt, fig, axes = _figure(1)
    ax = axes[0][0]
    fit = result.fits.get("pressure-dependent", result.fits["pressure-independent"])
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, run in enumerate(result.runs):
        c = colours[i % len(colours)]
        step = max(1, run.velocity.size // 3000)
        ax.plot(run.velocity[::step] * 1e3, run.friction[::step], ".", ms=1.5, color=c, alpha=0.3)
        b = result.bins[(result.bins["group"] == i) & result.bins["populated"]]
        ax.plot(b["direction"] * b["speed"] * 1e3, b["friction"], "o", ms=4, color=c,
                label=f"{run.name} ({run.mean_pressure_gauge / 1e5:.2g} bar g)")
        vmax = np.max(np.abs(run.velocity))
        v = np.concatenate((np.linspace(-vmax, -1e-6, 200), np.linspace(1e-6, vmax, 200)))
        ax.plot(v * 1e3, fit.predict(v, run.mean_pressure_gauge), "-", color=c, lw=1.2)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlabel("velocity [mm/s]")
    ax.set_ylabel("friction [N]")
    ax.set_title(f"friction map ({fit.model} fit, lines)")
    ax.legend(fontsize=7)
    _save(plt, fig, path)
