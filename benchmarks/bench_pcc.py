"""Python overhead of the small PCC calls and the batched pose entry point.

Run: ``python benchmarks/bench_pcc.py`` (after ``pip install .``). Prints medians of
individually timed calls; the Rust side of the same maps is in ``cargo bench --bench pcc``.
"""

import numpy as np
from _timing import median_time

from softrod import pcc


def main() -> None:
    rows = []
    rows.append(
        (
            "arc_pose (one arc)",
            median_time(lambda: pcc.arc_pose(3.0, 0.2, 0.1), calls=2000, repeats=5),
        )
    )
    rows.append(
        (
            "arc_jacobian (one arc)",
            median_time(lambda: pcc.arc_jacobian(3.0, 0.2, 0.1), calls=2000, repeats=5),
        )
    )
    n = 1_000_000
    rng = np.random.default_rng(0)
    k, phi, length = rng.uniform(0, 20, n), rng.uniform(-np.pi, np.pi, n), rng.uniform(0.05, 0.2, n)
    t = median_time(lambda: pcc.arc_poses(k, phi, length), calls=1, repeats=5)
    rows.append((f"arc_poses, {n} arcs in one call", t))
    rows.append(("  per pose", t / n))
    width = max(len(r[0]) for r in rows)
    print(f"{'case':<{width}}  median")
    for name, sec in rows:
        print(f"{name:<{width}}  {sec * 1e6:10.3f} us")


if __name__ == "__main__":
    main()
