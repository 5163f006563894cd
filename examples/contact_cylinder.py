"""An arm bent onto a cylinder (docs/contact.md, "An arm bent onto a cylinder").

A soft rod (L = 0.3 m, radius 5 mm, E = 1 MPa, nu = 0.45) clamped upright at the origin, one
tendon at (4 mm, 0) pulling it toward +x, and a cylinder of radius 30 mm across its path (axis
along y at x = 37 mm, z = 0.14 m: 2 mm of surface gap to the straight rod). Prints, per tension,
the contacts, the tip, the stability verdict and the median wall time of three solves, and
writes ``docs/figures/contact_cylinder.png``.

``python examples/contact_cylinder.py`` (from any directory; the figure goes to docs/figures).
"""

import statistics
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np

import softrod
from softrod.plot import plot_rod

# The repository's figures, wherever the script is run from.
FIGURES = Path(__file__).resolve().parents[1] / "docs" / "figures"

L, R, E = 0.3, 0.005, 1e6
RC = 0.03
XC = RC + R + 0.002
cylinder = softrod.Cylinder((XC, -0.05, 0.14), (XC, 0.05, 0.14), RC)
rod = softrod.Rod(L, softrod.CircularSection(R), softrod.LinearElastic(E, 0.45))


def solve(tension: float):
    return softrod.solve_statics(
        rod,
        [softrod.Tendon((0.004, 0.0), tension)],
        None,
        obstacles=[cylinder],
        steps=80,
    )


shown = []
print(
    f"{'T (N)':>6} {'contact s (m)':>16} {'force (N)':>10} {'normal (x, z)':>16} "
    f"{'tip x, z (mm)':>16} {'stable':>7} {'time (ms)':>10}"
)
for tension in (0.3, 0.6, 1.0, 2.0, 3.0, 3.3, 3.5):
    times = []
    try:
        with warnings.catch_warnings():
            # (The verdict is in the table's `stable` column.)
            warnings.filterwarnings("ignore", message="the equilibrium returned is unstable")
            for _ in range(3):
                t0 = time.perf_counter()
                sol = solve(tension)
                times.append(time.perf_counter() - t0)
    except softrod.ConvergenceError as err:
        print(f"{tension:>6.1f}  ConvergenceError: {str(err)[:90]}...")
        continue
    for c in sol.contacts:
        n = np.asarray(c["normal"])
        normal = f"({n[0]:.2f}, {n[2]:.2f})"
        tip = f"{1e3 * sol.tip_position[0]:.1f}, {1e3 * sol.tip_position[2]:.1f}"
        # A point contact at s, or a belt [s, s + length] with its resultant force.
        where = f"{c['s']:.4f}"
        if c["length"] > 0:
            where = f"[{c['s']:.4f}, {c['s'] + c['length']:.4f}]"
        print(
            f"{tension:>6.1f} {where:>16} {c['normal_force']:>10.4f} "
            f"{normal:>16} "
            f"{tip:>16} "
            f"{sol.stable!s:>7} {1e3 * statistics.median(times):>10.1f}"
        )
    if tension in (0.3, 1.0, 2.0, 3.3):
        shown.append((tension, sol))

fig = plot_rod(
    [s for _, s in shown],
    labels=[f"T = {t} N" for t, _ in shown],
    obstacles=[cylinder],
    view=(0, -90),
    radius=R,
)
ax = fig.axes[0]
ax.set_yticks([])  # seen along the cylinder's axis (y)
ax.set_ylabel("")
ax.set_title("Tendon-bent rod against a cylinder (side view, along its axis)")
fig.savefig(FIGURES / "contact_cylinder.png", dpi=100)
print(f"wrote {FIGURES / 'contact_cylinder.png'}")
