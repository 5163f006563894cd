"""The hysteresis figure of docs/friction.md: tip deflection of the two-segment NiTi robot over a
load/unload cycle of its first tendon, with capstan friction (several coefficients) and without.

Run from the repository root: ``python docs/friction.py [OUT_DIR]`` (default ``docs/figures``).
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import softrod

TENSIONS = np.r_[np.linspace(0.0, 4.0, 21), np.linspace(4.0, 0.0, 21)[1:]]  # N, tendon 0


def robot(mu: float) -> softrod.Robot:
    base = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    spec = base.spec.model_dump(mode="python", exclude_none=True)
    for t in spec["tendons"]:
        t["friction"] = mu
    return softrod.Robot.from_dict(spec)


def cycle(mu: float) -> np.ndarray:
    """Lateral tip deflection (mm) along the cycle (the other tendons slack)."""
    table = [[t, 0, 0, 0, 0, 0] for t in TENSIONS]
    sols = softrod.solve_path(robot(mu), table)
    return np.array([np.hypot(*s.tip_position[:2]) * 1e3 for s in sols])


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11.0, 4.2))
    n = len(TENSIONS) // 2 + 1
    free = cycle(0.0)
    ax.plot(TENSIONS, free, "k-", lw=2, label="frictionless")
    bx.axhline(0.0, color="k", lw=2, label="frictionless")
    for mu, c in [(0.05, "tab:blue"), (0.1, "tab:orange"), (0.2, "tab:red")]:
        x = cycle(mu)
        for axis, y in ((ax, x), (bx, x - free)):
            axis.plot(TENSIONS[:n], y[:n], "-", color=c, label=f"μ = {mu}: loading")
            axis.plot(TENSIONS[n - 1 :], y[n - 1 :], "--", color=c, label=f"μ = {mu}: unloading")
        width = np.max(np.abs(x[:n] - x[n - 1 :][::-1]))
        print(f"mu = {mu}: loop width {width:.3f} mm")
    for axis in (ax, bx):
        axis.set_xlabel("commanded tension of tendon 1 at the base (N)")
    ax.set_ylabel("lateral tip deflection (mm)")
    bx.set_ylabel("deflection minus the frictionless one (mm)")
    ax.set_title("Two-segment NiTi robot: load/unload cycle")
    bx.set_title("The hysteresis loops")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "friction_hysteresis.png", dpi=110)
    print(f"wrote {out / 'friction_hysteresis.png'}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/figures"))
