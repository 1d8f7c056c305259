"""The recording against the nominal model, before any fit: floors, residuals, where it misses.

``residuals`` (the replay of ``validation.replay`` against the recording, normalised by the noise floors of
``validation.recorded_noise``), ``locate_misfit`` (the diagnosis' view of ``compliance.validation.locate``:
windows and regimes where the model misses), ``empirical_force`` (the missing force outside the library),
``discriminating_test`` (the test that tells two explanations apart).
"""
