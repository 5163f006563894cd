"""Regenerates every figure of the gallery page (docs/gallery.md).

Run from the repository root: ``python docs/gallery.py [OUT_DIR]`` (default
``docs/figures/gallery``). The test suite runs it into a temporary folder.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import softrod
from softrod import plot

ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ROOT / "examples" / "robots"


def main(out: Path) -> list[Path]:
    """Writes the gallery's figures into ``out``; returns their paths."""
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []

    def save(fig, name: str) -> None:
        path = out / name
        plot.save_figure(fig, path, dpi=100, overwrite=True)  # regenerates the docs
        plt.close(fig)
        written.append(path)

    niti = softrod.load_robot(ROBOTS / "niti_two_segment.toml")
    pneu = softrod.load_robot(ROBOTS / "pneumatic_arm.toml")
    arm = softrod.load_robot(ROBOTS / "tapered_cable_arm.toml")
    niti_sol, pneu_sol = niti.solve(), pneu.solve()

    save(plot.plot_robot(niti, niti_sol, projections=True), "robot_niti.png")
    save(plot.plot_robot(pneu, pneu_sol, projections=True), "robot_pneumatic.png")
    save(plot.plot_planar_rod(arm.solve(), robot=arm), "planar_rod_arm.png")
    planar = softrod.PlanarCableArm.published_arm()
    save(plot.plot_planar(planar, [planar.solve(t) for t in (0.5, 1, 2, 4)]), "planar_arm.png")
    obstacles = [{"type": "sphere", "center": [0.08, 0.16, 0.25], "radius": 0.03}]
    save(plot.plot_robot(niti, niti_sol, obstacles=obstacles), "robot_obstacle.png")
    comp = softrod.compliance(niti_sol)
    save(
        plot.plot_compliance_ellipsoids(niti_sol, comp, s=[0.1, 0.2, 0.3, 0.4]),
        "compliance_ellipsoids.png",
    )
    levels = (0.0, 20e3, 40e3)
    comps = [softrod.compliance(pneu.with_pressures([p, p, p, p, 0, 0]).solve()) for p in levels]
    save(
        plot.plot_gamma_c(comps, labels=[f"P1 = P2 = {p / 1e3:.0f} kPa" for p in levels]),
        "gamma_c.png",
    )
    one = softrod.workspace_map(
        niti.rod, niti.tendons, softrod.tension_grid(6, {0: np.linspace(0, 4, 40)})
    )
    save(plot.plot_workspace_map(one), "workspace_one_axis.png")
    grid = softrod.tension_grid(6, {0: np.linspace(0, 4, 25), 1: np.linspace(0, 4, 25)})
    two = softrod.workspace_map(niti.rod, niti.tendons, grid)
    save(plot.plot_workspace_map(two), "workspace_surface.png")
    save(plot.plot_workspace_map(two, kind="scatter"), "workspace_binned.png")
    t = np.zeros((12, 6))
    t[:, 0] = np.linspace(0, 4, 12)
    t[:, 4] = np.linspace(0, 2, 12)
    anim = plot.animate_sweep(niti, out / "sweep_niti.gif", tensions=t, fps=6, dpi=70)
    written.append(Path(anim.path))
    return written


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "figures" / "gallery"
    for p in main(target):
        print(f"wrote {p}")
