"""Issue 10: the tip-loaded soft cantilever lands on the elastica branch or raises a named error.

PL^2/EI from 0.01 to 1000 along 100 directions over the sphere, both integrators, cold solves;
oracle: the planar elastica continued in load from the unloaded rod (``harness/oracles.py``).
The full sweep is ``-m slow`` (figure: ``python benchmarks/trust_elastica.py``); a bounded
sample runs by default.
"""

import numpy as np
import pytest
from harness import elastica

import softrod


@pytest.fixture(scope="module")
def sweep():
    return elastica.run(n_directions=100, n_alphas=21)


@pytest.mark.slow
@pytest.mark.parametrize(
    "integrator",
    ["rk4", "adaptive"],
)
def test_no_silent_wrong_branch(sweep, integrator):
    c = sweep.counts(integrator)
    assert sum(c.values()) == 100 * 21
    assert c["wrong-branch"] == 0, sweep.worst(integrator, "wrong-branch")
    assert c["other-error"] == 0 and c["not-converged-returned"] == 0


@pytest.mark.slow
@pytest.mark.parametrize(
    "integrator",
    ["rk4", "adaptive"],
)
def test_every_failure_is_a_convergence_error_with_its_fields(sweep, integrator):
    errors = [
        r for r in sweep.records if r.integrator == integrator and r.outcome == "convergence-error"
    ]
    assert all(r.fields for r in errors), errors[:1]


# A bounded sample: a transverse, a pulling, a pushing and a nearly axial pushing load (the
# sweep's direction 99, 8.1 degrees off -z), three sizes each.
SAMPLE = np.array(
    [[1.0, 0.0, 0.0], [0.6, 0.0, 0.8], [0.0, 0.6, -0.8], [0.14097948, 0.0049786, -0.99]]
)


@pytest.mark.parametrize(
    "integrator",
    ["rk4", "adaptive"],
)
def test_sample_on_branch_or_named_error(integrator):
    alphas = np.array([0.3, 10.0, 100.0])
    exact = elastica.oracle_tips(SAMPLE / np.linalg.norm(SAMPLE, axis=1, keepdims=True), alphas)
    rod = elastica.rod()
    for i, u in enumerate(SAMPLE / np.linalg.norm(SAMPLE, axis=1, keepdims=True)):
        for k, a in enumerate(alphas):
            loads = softrod.Loads(tip_force=tuple(a * elastica.EI / elastica.LENGTH**2 * u))
            rec = elastica._classify(rod, loads, exact[i, k], integrator, i, a)
            assert rec.outcome in ("on-branch", "on-branch-inaccurate", "convergence-error"), rec
