"""A recorded test run in simulation under its recorded conditions, and measured like the recording.

The one replay (``validation.replay.replay``) runs the model with the recording's own sidecar
conditions (load, supply pressure, controller gains) and start (position and chamber pressures
of its first 50 ms):

- a closed-loop test (steps, staircase, sinusoid, a hold the loop held) follows the recorded
  set-point (``closed_loop``, with the recording's own position noise when it is logged on the
  controller's clock);
- a full stroke is driven by the recorded valve command (``plant_only``): the positioner was in
  manual;
- a hold with the valve at null is run plant-only over its window, from the position and
  pressures recorded at the window's start, with the recorded command (0 V): the closed-loop
  second before it only brought the servo there.

The circuit is the test's: the flow-control valves in or open as its sidecar says. The predicted
figure is measured with the same code as the recording, on the simulated piston position
(``position_true``): the model's prediction of the true figure.
"""

from __future__ import annotations

import pandas as pd

from compliance.acceptance.measure.conditioning import condition
from compliance.acceptance.measure.recording import measure_test
from compliance.acceptance.site.prepared import PreparedTest
from compliance.validation.replay import replay

__all__ = ["circuit_config", "predict_cases", "replay_mode"]


def circuit_config(cfg, test):
    """The plant model with the flow-control valves as the test ran them (unchanged when the sidecar does not say)."""
    if test.flow_control is None:
        return cfg
    return cfg.replace(options={"flow_control.installed": "true" if test.flow_control else "false"})


def replay_mode(test) -> tuple[str, float | None]:
    """How a test is replayed: ``closed_loop`` or ``plant_only``, and the time a plant-only hold window starts (or None)."""
    if test.kind == "full_stroke":
        return "plant_only", None
    if test.kind == "hold" and test.settings.get("valve_null_from") is not None:
        window = test.settings.get("window")
        return "plant_only", float(window[0]) if window else float(test.settings["valve_null_from"])
    return "closed_loop", None


def _predicted_frame(cfg, prep: PreparedTest) -> pd.DataFrame:
    frame, meta = prep.recording.frame, prep.recording.meta
    mode, start = replay_mode(prep.test)
    if start is not None:
        frame = frame[frame["time"] >= start - 1e-9].reset_index(drop=True)
    if mode == "plant_only":  # a start held against an end stop reads a little beyond it (the stop yields): the model starts at the stop
        frame = frame.assign(position=frame["position"].clip(0.0, cfg.p("cylinder.stroke")))
    sim = replay(circuit_config(cfg, prep.test), frame, meta, mode)
    out = pd.DataFrame({"time": frame["time"].to_numpy(), "position": sim["position_true"].to_numpy()})
    for col in ("reference", "valve_command", "pressure_a", "pressure_b"):
        if col in sim.columns:
            out[col] = sim[col].to_numpy()
    if "reference" in frame.columns:
        out["reference"] = frame["reference"].to_numpy()  # the set-point the test gave (the replay followed it)
    return out


def predict_cases(cfg, prep: PreparedTest, *, sine: dict | None = None, step_options: dict | None = None,
                  keep_trace: bool = False):
    """The model's cases of one recorded test (measured on its simulated piston position), and the trace if asked.

    Returns
    -------
    (list of Case, pandas.DataFrame or None)

    Raises
    ------
    InputError
        The replay cannot use the recording (a column its mode needs is missing).
    SimulationError
        The model became non-physical.
    """
    frame = _predicted_frame(cfg, prep)
    sim_prep = PreparedTest(prep.recording, prep.test, condition(frame, {}, f"{prep.name} (predicted)", noise_free=True))
    cases = measure_test(sim_prep, cfg, sine=sine, step_options=step_options)
    return cases, (frame if keep_trace else None)
