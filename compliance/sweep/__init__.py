"""Candidate sweeps, remedies, tolerance yield and sizing above the campaign (docs/scaling.md).

Rooms (dependencies point down this list, never back):

- the top level composes them into commands' work: ``run`` (a sweep or yield run from its file to
  its output files), ``check_remedies`` (the remedies of ``govcheck check --remedies``),
  ``summary_text`` (the Markdown summaries);
- ``remedies/``: what would make it pass: the smallest combined change (``smallest_change``), the
  staged search (``staged_search``), the rate limiter's space (``limiter_space``), the finish
  (``finish``) and why the binding requirement binds (``binding_physics``);
- ``tolerance/``: Monte Carlo over tolerances: a candidate's yield (``yield_mc``) and a check's
  verdict bands (``uncertainty_mc``);
- ``sizing/``: a gate servo sized from its duty (``size_servo``, ``throttle_tuning``), the duty file
  and the hardware catalogue (``duty_file``, ``hardware_catalogue``, ``data_file``);
- ``candidates/``: sweep files (``spec``), the parameter paths a sweep may move, drawing
  (``sampling``), judging in workers (``evaluate``) on the one executor (``runner``, resumable with
  ``candidate_store``), ranking and the results table (``ranking``, ``results``).

The HTML page of the remedies / yield section is rendered by ``compliance.report.render.section_page``
(the report's templates), written by ``govcheck sweep``.
"""
