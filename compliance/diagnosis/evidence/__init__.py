"""The recording against the nominal model, before any fit: replay, floors, residuals, where it misses.

``replay_fit`` (fast re-synchronised replay with matched noise), ``operating_point`` (the stated load
holds at the start), ``residuals`` (normalised residuals, over the noise floors of ``validation.recorded_noise``), ``locate_misfit`` (the
diagnosis' view of ``compliance.validation.locate``: windows and regimes where the model misses),
``empirical_force`` (the missing force outside the library), ``discriminating_test`` (the test that
tells two explanations apart).
"""
