"""Issue 10: bad input to any public callable gives a named error, never a crash or a NaN.

Every public callable of ``softrod`` and ``softrod.pcc`` x NaN, inf, negative, zero, huge,
wrong type, wrong shape, None, strings, bad callbacks, each in a subprocess pool
(``harness/fuzz.py``). A reproducible sample runs by default, every call behind ``-m slow``
(figure: ``python benchmarks/trust_fuzz.py``).
"""

import pytest
from harness import fuzz

SAMPLE = 600


@pytest.fixture(scope="module")
def sample():
    outcomes = fuzz.run(fuzz.sample(fuzz.calls(), SAMPLE), timeout=10.0)
    return fuzz.summary(outcomes)


@pytest.fixture(scope="module")
def full():
    return fuzz.summary(fuzz.run(fuzz.calls(), timeout=20.0))


def _check_baselines(s):
    assert s["baseline_failures"] == [], s["baseline_failures"]


def _defects(s, kinds):
    return [
        (o.call.target, o.call.parameter, o.call.value, o.detail)
        for o in s["defects"]
        if o.outcome in kinds
    ]


def test_every_public_callable_and_parameter_is_fuzzed():
    # A new public function, method or parameter needs a baseline in harness/fuzz.py.
    assert fuzz.coverage() == []


def test_baselines_run(sample):
    _check_baselines(sample)


def test_sample_no_panic_abort_or_hang(sample):
    assert _defects(sample, ("panic", "abort", "hang")) == []


def test_sample_no_silent_nonfinite_output(sample):
    assert _defects(sample, ("ok-nonfinite",)) == []


def test_sample_errors_name_the_parameter(sample):
    assert sample["named_rate"] >= 0.95


@pytest.mark.slow
def test_full_baselines_run(full):
    _check_baselines(full)


@pytest.mark.slow
def test_full_no_panic_abort_or_hang(full):
    assert _defects(full, ("panic", "abort", "hang")) == []


@pytest.mark.slow
def test_full_no_silent_nonfinite_output(full):
    assert _defects(full, ("ok-nonfinite",)) == []


@pytest.mark.slow
def test_full_callback_errors_reach_the_caller(full):
    assert _defects(full, ("ok-swallowed-callback-error",)) == []


@pytest.mark.slow
def test_full_errors_name_the_parameter(full):
    assert full["named_rate"] >= 0.95
