"""The seed papers' own tests beside the simulated figures: plant A (seed 000), plant B (seed 001)."""
