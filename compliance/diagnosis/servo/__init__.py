"""Diagnosis of closed-loop servo recordings: candidates, fits, selection, explanation.

``diagnose`` is the chain (``diagnose(cfg, frame, meta)`` -> ``Diagnosis``); ``candidates`` /
``instrument_candidates`` (what may be fitted), ``fit`` (scan, simplex, least squares),
``effect_sets`` (several effects at once), ``recalibration`` (base parameters), ``parallel_fits``
(worker processes), ``selection`` (information criteria, verdicts, ambiguity), ``lag_split`` (does
the recording pin a lag's split), ``friction_form`` (the friction law's other form as the base),
``explanation`` (the paragraph), ``fitted_model`` (the fitted plant), ``report_data``
(the result and its JSON document), ``stage`` (what the stages share), ``joint_recordings`` (several recordings of one plant).
"""
