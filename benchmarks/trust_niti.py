"""Random loaded two-segment NiTi robots: stability of the answers, convergence, failures.

Issue 10 requires 0 unstable answers reported as stable, a converged rate >= 99.5 % and every
failure a ConvergenceError with iterations, residual and load factor. Oracles: the smallest
eigenvalue of the symmetric tip tangent stiffness, and the same from perturbation re-solves
(``tests/harness/niti.py``).

    python benchmarks/trust_niti.py [--n 10000] [--seed 2024]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import niti


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args()
    t0 = time.perf_counter()
    run = niti.run(args.n, args.seed)
    c = run.counts
    conv = c["converged"]
    print(
        f"{args.n} random NiTi configurations (seed {args.seed}, {time.perf_counter() - t0:.0f} s)"
    )
    print(f"converged: {conv} ({100 * conv / args.n:.2f} %); outcomes {dict(c)}")
    unstable = run.unstable()
    print(
        f"unstable equilibria (tangent stiffness eigenvalue < -{niti.MARGIN_TOL:g}): "
        f"{len(unstable)}"
    )
    print(
        f"  reported as stable (no flag or stable=True, no warning): "
        f"{len(run.unstable_reported_stable())}"
    )
    print(f"  stable ones flagged unstable: {len(run.stable_reported_unstable())}")
    print(
        f"  tangent vs perturbation re-solves disagree in sign: {len(run.oracle_disagreements())}"
    )
    if unstable:
        worst = min(unstable, key=lambda r: r.margin)
        gap = max(abs(r.margin - r.margin_fd) / abs(r.margin) for r in unstable)
        print(
            f"  smallest dimensionless eigenvalue {worst.margin:.3f} (config {worst.index}); "
            f"largest relative gap between the two oracles {gap:.1e}"
        )
    failures = [r for r in run.records if r.outcome != "converged"]
    print(
        f"failures: {len(failures)}; ConvergenceError with iterations, residual and "
        f"load_factor: {sum(r.outcome == 'convergence-error' and r.fields for r in failures)}"
    )
    for r in failures[:3]:
        print(f"  {r.outcome}: {r.error}")
    ex = niti.solve_one(niti.robot(), niti.ISSUE_TENSIONS, niti.ISSUE_FORCE)
    print(
        f"issue example: {ex.outcome}, eigenvalue {ex.margin:.3f} (re-solves {ex.margin_fd:.3f}), "
        f"tip y {ex.tip_y:.4f} m, stable flag {ex.stable}"
    )


if __name__ == "__main__":
    main()
