"""The diagnosis's noise floors are the one noise-floor module's: :mod:`compliance.validation.recorded_noise`.

Kept only as the import path of ``evidence.replay_fit`` (being reworked beside this change);
everything else imports ``validation.recorded_noise`` directly.
"""

from compliance.validation.recorded_noise import position_noise_estimate, sensor_noise_std

__all__ = ["position_noise_estimate", "sensor_noise_std"]
