"""Figures of docs/compliance.md: ellipsoids along the arm, gamma_c(s), a workspace map.

``python examples/compliance_figures.py`` (from any directory; the figures go to docs/figures).
"""

import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import numpy as np

import softrod
from softrod.plot import plot_compliance_ellipsoids, plot_gamma_c, plot_workspace_map

# The repository's figures, wherever the script is run from.
FIGURES = Path(__file__).resolve().parents[1] / "docs" / "figures"

robot = softrod.examples.load("niti_two_segment")
sol = robot.solve()
comp = softrod.compliance(sol)
fig = plot_compliance_ellipsoids(
    sol, comp, nodes=7, title="NiTi robot, tensions [4, 0, 0, 0, 2, 0] N"
)
fig.savefig(FIGURES / "compliance_ellipsoids.png", dpi=110)

scales = [0.0, 0.5, 1.0, 1.5]
comps = [
    softrod.compliance(robot.with_tensions(np.array([4, 0, 0, 0, 2, 0]) * k).solve())
    for k in scales
]
fig = plot_gamma_c(
    comps,
    labels=[f"tensions x {k}" for k in scales],
    title="NiTi robot: dimensionless flexural compliance along the arm",
)
fig.savefig(FIGURES / "compliance_gamma_c.png", dpi=110)
for k, c in zip(scales, comps, strict=True):
    print(f"tensions x {k}: gamma_c at the tip = {np.round(c.gamma_c[-1], 4)}")

grid = softrod.tension_grid(6, {0: np.linspace(0, 4, 100), 1: np.linspace(0, 4, 100)})
t0 = time.perf_counter()
wmap = softrod.workspace_map(robot.rod, robot.tendons, grid, progress=True, tangent="length")
print(
    f"workspace map: {len(grid)} configurations in {time.perf_counter() - t0:.2f} s (with tangents)"
)
c = wmap.max_translational_compliance
r = np.linalg.norm(wmap.tip_position[:, :2], axis=1)
centre, edge = c[np.argmin(r)], c[np.argmax(r)]
print(f"largest translational compliance: centre {centre:.4f} m/N, periphery {edge:.4f} m/N")
fig = plot_workspace_map(wmap, title="NiTi robot: segment-1 tendons 0 and 1 swept over 0-4 N")
fig.savefig(FIGURES / "compliance_workspace.png", dpi=110)
ct = wmap.tangent_max_translational_compliance
centre, edge = ct[np.argmin(r)], ct[np.argmax(r)]
print(f"tangent, all tendons at fixed length: centre {centre:.4f} m/N, periphery {edge:.4f} m/N")
fig = plot_workspace_map(
    wmap,
    measure="tangent_max_translational_compliance",
    title="NiTi robot: exact tangent compliance, all six tendons held at fixed length",
)
fig.savefig(FIGURES / "compliance_workspace_tangent.png", dpi=110)

# The compliance-methodology paper's Fig. 1e in kind: the pneumatic arm with pairs 1 and 2
# pressurised together.
arm = softrod.examples.load("pneumatic_arm")
pressures = [0, 10, 20, 30, 40]
comps = []
for p in pressures:
    s = arm.with_pressures([p * 1e3] * 4 + [0, 0]).solve()
    comps.append(softrod.compliance(s))
    g = comps[-1].gamma_c[-1]
    z = s.tip_position[2] * 1e3
    print(f"P1 = P2 = {p:2d} kPa: tip z {z:.2f} mm, gamma_c at the tip {g.round(4)}")
fig = plot_gamma_c(
    comps,
    labels=[f"P1 = P2 = {p} kPa" for p in pressures],
    title="compliance-methodology pneumatic arm: dimensionless flexural compliance along the arm",
)
fig.savefig(FIGURES / "compliance_gamma_c_pneumatic.png", dpi=110)
