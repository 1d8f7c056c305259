"""Linearised analysis: trim, Jacobians of the one plant right-hand side, python-control
systems, margins, operating maps, the equivalent grid-model parameters, the dead-zone stall band."""
