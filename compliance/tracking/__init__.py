"""Plant B's path tracking (seed 001): set-point paths (circle, helix, CSV strokes, time
parameterisation) and the Cartesian robot of three state-feedback axes.

The axis controller and observers live in :mod:`compliance.model` (``state_feedback``,
``observers``, ``axis_design``), its compiled loop in
:mod:`compliance.simulation.state_feedback_loop`, the tracking procedures in
:mod:`compliance.procedures.path_tracking` and the path metrics in
:mod:`compliance.metrics.path_tracking`. See docs/plant-b.md.
"""
