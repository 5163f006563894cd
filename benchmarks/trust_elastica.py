"""Tip-loaded soft cantilever, PL^2/EI from 0.01 to 1000 in 100 directions, both integrators.

Every answer must be on the elastica branch connected to the unloaded rod, or a named error
(issue 10). Oracle: the planar elastica by multiple shooting continued in load from zero
(``tests/harness/oracles.py``; equal to Bisshopp-Drucker for transverse loads to 1e-11 L).

    python benchmarks/trust_elastica.py [--directions 100] [--loads 21]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import elastica

OUTCOMES = (
    "on-branch",
    "on-branch-inaccurate",
    "wrong-branch",
    "convergence-error",
    "not-converged-returned",
    "other-error",
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--directions", type=int, default=100)
    ap.add_argument("--loads", type=int, default=21)
    args = ap.parse_args()
    t0 = time.perf_counter()
    sweep = elastica.run(args.directions, args.loads)
    print(
        f"cantilever L={elastica.LENGTH} m r={elastica.RADIUS} m E={elastica.MODULUS:g} Pa, "
        f"{args.directions} directions x {args.loads} loads (PL^2/EI 0.01..1000), "
        f"tip tolerance {elastica.TIP_TOL:g} L ({time.perf_counter() - t0:.0f} s)"
    )
    print(f"{'integrator':<10} " + " ".join(f"{o:>22}" for o in OUTCOMES))
    for integ in ("rk4", "adaptive"):
        c = sweep.counts(integ)
        print(f"{integ:<10} " + " ".join(f"{c.get(o, 0):>22}" for o in OUTCOMES))
    for integ in ("rk4", "adaptive"):
        rs = [r for r in sweep.records if r.integrator == integ]
        ok = [r.tip_error for r in rs if r.outcome == "on-branch"]
        print(f"\n{integ}: largest on-branch tip error {max(ok, default=float('nan')):.2e} L")
        for outcome in ("on-branch-inaccurate", "wrong-branch"):
            w = sweep.worst(integ, outcome)
            sel = [r for r in rs if r.outcome == outcome]
            if w is not None:
                print(
                    f"  {outcome}: {len(sel)}; alpha >= {min(r.alpha for r in sel):.3g}; worst "
                    f"{w.tip_error:.3e} L at alpha {w.alpha:.3g}, direction {w.direction} "
                    f"(refined {w.refined_error:.2e} L)"
                )
        errs = [r for r in rs if r.outcome == "convergence-error"]
        if errs:
            print(
                f"  convergence errors: {len(errs)}, alpha >= {min(r.alpha for r in errs):.3g}; "
                f"with iterations, residual and load_factor: {sum(r.fields for r in errs)}"
            )
            print(f"  e.g. {errs[0].error}")
        other = [r for r in rs if r.outcome == "other-error"]
        for r in other[:3]:
            print(f"  other error at alpha {r.alpha:.3g}: {r.error}")


if __name__ == "__main__":
    main()
