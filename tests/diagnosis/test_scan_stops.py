"""Grid scans whose replays stop once a point cannot matter (servo/fit.py ``scan_points``).

A stopped replay returns a lower bound above the level it was given (evidence/residuals.py ``Bound``);
whatever the order of the grid, the argmin and the best point of another main-parameter value (the
second start of a several-parameter fit) must come out exact, and the other points stop.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from compliance.diagnosis.servo.fit import SECOND_START, scan_points

# chi-square of each (main, other) grid point: main 1.0 holds the best point, main 3.0 the runner-up of another
# main value (12.0, beside a 11.0 of main 1.0 itself), the rest only worse
CHI = {(1.0, 0.0): 10.0, (1.0, 1.0): 11.0, (2.0, 0.0): 14.0, (2.0, 1.0): 19.5, (3.0, 0.0): 12.0, (3.0, 1.0): 13.0,
       (4.0, 0.0): 30.0, (4.0, 1.0): 25.0}


class _Replays:
    """A fit context whose replays stop above their limit with a lower bound (half-way between limit and value)."""

    def __init__(self):
        self.full = 0

    def residual(self, params, values, limit=math.inf):
        chi = CHI[tuple(values)]
        if chi > limit:
            return np.array([math.sqrt(0.5 * (limit + chi))]), None
        self.full += 1
        return np.array([math.sqrt(chi)]), {}


@pytest.mark.parametrize("order", list(itertools.islice(itertools.permutations(sorted(CHI)), 0, 40320, 997)))
def test_argmin_and_runner_up_of_another_main_value_are_exact_in_any_grid_order(order):
    points = [list(p) for p in order]
    ctx = _Replays()
    chis = scan_points(ctx, (), points, keep=SECOND_START, runner_up=True)
    best = int(np.argmin(chis))
    assert points[best] == [1.0, 0.0] and chis[best] == pytest.approx(10.0, rel=1e-12)
    others = [i for i in np.argsort(chis, kind="stable") if points[i][0] != points[best][0]]
    assert points[others[0]] == [3.0, 0.0] and chis[others[0]] == pytest.approx(12.0, rel=1e-12)
    for p, c in zip(points, chis):  # a stopped point keeps a lower bound above the runner-up: it can be neither
        assert c <= CHI[tuple(p)] * (1 + 1e-12) and (c == pytest.approx(CHI[tuple(p)], rel=1e-12) or c > 12.0)


def test_points_that_can_be_neither_stop():
    points = [list(p) for p in sorted(CHI)]  # best first: every later point gets a level
    plain, tight = _Replays(), _Replays()
    scan_points(plain, (), points, keep=SECOND_START)
    scan_points(tight, (), points, keep=SECOND_START, runner_up=True)
    # within 2 x the best (20) all but 30 and 25 replay in full; with the runner-up's level 10, 11 and 14 do (two main
    # values known from then on), 19.5 stops beyond 14, 12 does, 13 stops beyond 12
    assert plain.full == 6 and tight.full == 4
