"""Random PCC statics configurations: every valid input must solve (no spurious errors).

python benchmarks/trust_pcc.py [--n 10000] [--seed 77]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import pcc_random


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=77)
    args = ap.parse_args()
    t0 = time.perf_counter()
    run = pcc_random.run(args.n, args.seed)
    c = run.counts
    print(
        f"{args.n} random PCC configurations (seed {args.seed}, {time.perf_counter() - t0:.1f} s)"
    )
    for k in ("ok", "parameter-error", "convergence-error", "tip-mismatch", "other-error"):
        print(f"  {k:<18} {c.get(k, 0):>6} ({100 * c.get(k, 0) / args.n:.2f} %)")
    for k in ("parameter-error", "convergence-error", "tip-mismatch", "other-error"):
        ex = next((r for r in run.records if r.outcome == k), None)
        if ex is not None:
            print(f"  e.g. {k}: {ex.detail}")


if __name__ == "__main__":
    main()
