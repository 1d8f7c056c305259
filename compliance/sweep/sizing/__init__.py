"""Sizing a gate servo from its duty: the duty file, the hardware catalogue, cylinders, valve, throttles, controller."""
