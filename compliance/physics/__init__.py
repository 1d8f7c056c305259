"""Plain physics functions of SI floats, compiled with numba so the simulator core can call them.

Each function is a scalar kernel (``@njit``); call it from Python with floats, or use
``numpy.vectorize`` for arrays. Every equation cites its source.
"""
