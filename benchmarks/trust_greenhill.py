"""Self-weight column (Greenhill): stable below l_c = 1.986 (EI/q)^(1/3), not above.

The lateral tip compliance of the straight column (``tangent_compliance``) against L / l_c, the
solver's ``stable`` flag, and the critical ratio where the compliance changes sign (bisection).

    python benchmarks/trust_greenhill.py
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from harness import greenhill, oracles


def crossing(inextensible: bool) -> float:
    lo, hi = 0.9, 1.1
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if greenhill.measure(mid, inextensible)["lateral"] > 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def main() -> None:
    c, j = oracles.greenhill_constant()
    print(f"Greenhill: first zero of J_-1/3 j = {j:.10f}, l_c = {c:.6f} (EI/q)^(1/3)")
    print(
        f"column: L = {greenhill.LENGTH} m, E = {greenhill.MODULUS:g} Pa, "
        f"rho = {greenhill.DENSITY} kg/m^3, upright under g = {greenhill.GRAVITY} m/s^2"
    )
    print(f"{'L/l_c':>6} {'radius mm':>9} {'straight':>8} {'stable':>7} {'lateral C (m/N)':>16}")
    for ratio in (0.5, 0.8, 0.9, 0.95, 1.05, 1.1, 1.2, 1.5):
        m = greenhill.measure(ratio)
        print(
            f"{ratio:6.2f} {1e3 * greenhill.radius_for(ratio):9.3f} {m['straight']!s:>8} "
            f"{m['stable']!s:>7} {m['lateral']:16.4e}"
        )
    print(
        f"tangent compliance changes sign at L/l_c = {crossing(True):.6f} (inextensible), "
        f"{crossing(False):.6f} (extensible, nu = 0.5)"
    )


if __name__ == "__main__":
    main()
