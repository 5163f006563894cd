"""Compliance of stress-free arcs up to 2 pi against Castigliano's closed form.

Issue 10 requires a relative error <= 10 x rtol with the adaptive integrator at rtol 1e-6 ...
1e-10, and <= 1e-6 with the defaults (``tests/harness/arcs.py``; the error is the largest entry
error of the 6x6 tip compliance, each 3x3 block relative to its largest entry).

    python benchmarks/trust_arcs.py
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import arcs


def main() -> None:
    head = ["case", "angle", "default", "tangent"] + [f"rtol {r:g}" for r in arcs.RTOLS]
    print(
        f"rod L={arcs.LENGTH} m r={arcs.RADIUS} m E={arcs.MODULUS:g} Pa nu={arcs.POISSON}; "
        "adaptive atol = rtol / 100; '*' marks a miss of the bound"
    )
    print(" ".join(f"{h:>11}" for h in head))
    for case in ("precurved", "moment"):
        for theta in arcs.ANGLES:
            row = [case, f"{theta / math.pi:g} pi"]
            e = arcs.errors(case, theta)
            row.append(f"{e:.1e}{'*' if e > 1e-6 else ' '}")
            if case == "precurved":
                e = arcs.errors(case, theta, "tangent")
                row.append(f"{e:.1e}{'*' if e > 1e-6 else ' '}")
            else:
                row.append("-")
            for r in arcs.RTOLS:
                e = arcs.errors(case, theta, **arcs.adaptive_options(r))
                row.append(f"{e:.1e}{'*' if e > 10 * r else ' '}")
            print(" ".join(f"{x:>11}" for x in row))


if __name__ == "__main__":
    main()
