"""Issue 10: compliance of stress-free arcs up to 2 pi is under the solver's error control.

Oracle: Castigliano's compliance of the circular arc (``harness/oracles.py``); error: the
largest entry error of the 6x6 tip compliance, each 3x3 block relative to its largest entry.
Figure: ``python benchmarks/trust_arcs.py``.
"""

import math

import pytest
from harness import arcs


@pytest.mark.parametrize(
    ("case", "turns", "rtol"),
    [(c, a, r) for c in ("precurved", "moment") for a in (0.5, 1.0, 1.5, 2.0) for r in arcs.RTOLS],
)
def test_adaptive_compliance_within_ten_rtol(case, turns, rtol):
    err = arcs.errors(case, turns * math.pi, **arcs.adaptive_options(rtol))
    assert err <= 10 * rtol


@pytest.mark.parametrize(
    ("case", "turns"), [(c, a) for c in ("precurved", "moment") for a in (0.5, 1.0, 1.5, 2.0)]
)
def test_default_compliance_within_1e_6(case, turns):
    # RK4 at the default steps: on the strongly curved arcs the compliance is evaluated on a
    # finer nested mesh (the estimated truncation error of the rotations exceeds 1e-7).
    assert arcs.errors(case, turns * math.pi) <= 1e-6


@pytest.mark.parametrize("turns", [0.5, 1.0, 1.5, 2.0])
def test_default_tangent_compliance_within_1e_6(turns):
    assert arcs.errors("precurved", turns * math.pi, "tangent") <= 1e-6


@pytest.mark.parametrize(
    "turns",
    [0.5, 1.0, 1.5, 2.0],
)
def test_adaptive_at_1e_8_is_not_worse_than_the_default(turns):
    theta = turns * math.pi
    adaptive = arcs.errors("precurved", theta, **arcs.adaptive_options(1e-8))
    assert adaptive <= arcs.errors("precurved", theta)
