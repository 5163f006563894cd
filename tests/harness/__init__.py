"""Measurement harnesses and independent oracles for the trust claims (issue 10).

Every oracle here is written from mechanics alone (closed forms, elliptic integrals, our own
shooting and quadrature) and shares no code with softrod. The harness modules run one claim
each over many configurations and return counts; the tests (``tests/test_trust_*.py``) assert
the claims on them, the scripts (``benchmarks/trust_*.py``) print the figures.
"""
