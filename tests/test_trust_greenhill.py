"""Issue 10: the self-weight column (Greenhill) is stable below its critical length only.

An upright Ecoflex-like rod (E = 100 kPa, 120 mm, inextensible) under its own weight, its radius
set so that L = 0.9 l_c or 1.1 l_c with ``l_c = 1.9863 (EI/q)^(1/3)`` (the constant from the
first zero of J_{-1/3}, ``harness/oracles.py``). Figure: ``python benchmarks/trust_greenhill.py``.
"""

from harness import greenhill


def test_tangent_compliance_changes_sign_at_greenhills_length():
    # Independent of any stability flag: the lateral tip compliance of the straight column
    # goes through a pole at l_c (positive below, negative above). Above l_c the default solve
    # returns the buckled column: the straight one is asked for.
    straight = {"seek_stable": False, "on_unstable": "ignore"}
    assert greenhill.measure(0.97, **straight)["lateral"] > 0
    above = greenhill.measure(1.03, **straight)
    assert above["straight"] and above["lateral"] < 0


def test_reported_straight_and_stable_below_the_critical_length():
    m = greenhill.measure(0.9)
    assert m["converged"] and m["straight"] and m["stable"] is True


def test_not_straight_and_stable_above_the_critical_length():
    m = greenhill.measure(1.1)
    assert m["stable"] is not None, "solution.stable is missing"
    assert not (m["straight"] and m["stable"])
