"""Plots of softrod results (matplotlib). Every function returns the figure it drew on."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._core import PlanarCableArm, PlanarSolution

__all__ = ["plot_fit", "plot_planar", "plot_rod"]


def _section_outline(arm: PlanarCableArm, sol: PlanarSolution) -> tuple[np.ndarray, np.ndarray]:
    """Outline of the deformed cone: backbone offset by +-R(s) along the normal (m)."""
    r = arm.radius(sol.s)
    nx, ny = -np.sin(sol.angle), np.cos(sol.angle)
    upper = np.column_stack((sol.x + r * nx, sol.y + r * ny))
    lower = np.column_stack((sol.x - r * nx, sol.y - r * ny))
    return upper, lower


def plot_planar(
    arm: PlanarCableArm,
    solutions: Sequence[PlanarSolution],
    *,
    title: str | None = None,
    profiles: bool = True,
):
    """Backbones of the planar cable arm for several tensions, with the arm's outline.

    Args:
        arm: The arm that was solved.
        solutions: Solutions to draw, e.g. one per tension.
        title: Figure title (default: describes the arm).
        profiles: Also draw curvature k(s) and axial strain q(s) panels.

    Returns:
        The matplotlib figure (axes in millimetres; x along the unloaded arm, y toward the
        cable).
    """
    import matplotlib.pyplot as plt

    if profiles:
        fig = plt.figure(figsize=(11, 5.2), layout="constrained")
        grid = fig.add_gridspec(2, 2, width_ratios=(1.35, 1))
        ax = fig.add_subplot(grid[:, 0])
        ax_k = fig.add_subplot(grid[0, 1])
        ax_q = fig.add_subplot(grid[1, 1], sharex=ax_k)
    else:
        fig, ax = plt.subplots(figsize=(6.5, 5.2), layout="constrained")
    cmap = plt.get_cmap("viridis")
    n = max(len(solutions), 1)
    for i, sol in enumerate(solutions):
        color = cmap(0.05 + 0.85 * i / max(n - 1, 1))
        upper, lower = _section_outline(arm, sol)
        poly = np.vstack((upper, lower[::-1]))
        ax.fill(poly[:, 0] * 1e3, poly[:, 1] * 1e3, color=color, alpha=0.12, lw=0)
        ax.plot(sol.x * 1e3, sol.y * 1e3, color=color, lw=2, label=f"T = {sol.tension:g} N")
        ax.plot(sol.tip[0] * 1e3, sol.tip[1] * 1e3, "o", color=color, ms=4)
        if profiles:
            ax_k.plot(sol.s * 1e3, sol.curvature, color=color)
            ax_q.plot(sol.s * 1e3, sol.strain * 100, color=color)
    ax.plot([0, 0], [-arm.base_radius * 1e3, arm.base_radius * 1e3], "k-", lw=4)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm), along the unloaded arm")
    ax.set_ylabel("y (mm), toward the cable")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    if profiles:
        ax_k.set_ylabel("curvature k (1/m)")
        ax_k.grid(alpha=0.3)
        ax_q.set_ylabel("axial strain q (%)")
        ax_q.set_xlabel("arc length s (mm)")
        ax_q.grid(alpha=0.3)
    fig.suptitle(
        title
        or (
            f"Tapered cable-driven arm: L = {arm.length * 1e3:g} mm, "
            f"R = {arm.base_radius * 1e3:g} -> {arm.tip_radius * 1e3:g} mm, "
            f"a = {arm.offset_ratio:.3g}, E = {arm.youngs_modulus / 1e3:g} kPa"
        )
    )
    return fig


def _set_equal_3d(ax, pts: np.ndarray) -> None:
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1e-9)
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))


def plot_rod(
    solutions,
    *,
    labels=None,
    frames: int = 5,
    title: str | None = None,
    ax=None,
):
    """3-D backbones of one or more statics solutions, with body frames along them.

    Args:
        solutions: A :class:`softrod.StaticsSolution` or a sequence of them.
        labels: One legend label per solution.
        frames: Number of body-frame triads drawn along each backbone (x red, y green,
            z = tangent blue), 0 for none.
        title: Figure title.
        ax: A 3-D matplotlib axes to draw into (default: a new figure).

    Returns:
        The matplotlib figure (axes in millimetres, world frame).
    """
    import matplotlib.pyplot as plt

    sols = [solutions] if hasattr(solutions, "position") else list(solutions)
    if ax is None:
        fig = plt.figure(figsize=(6.5, 6.5), layout="constrained")
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    allpts = []
    cmap = plt.get_cmap("viridis")
    for i, sol in enumerate(sols):
        p = sol.position * 1e3
        allpts.append(p)
        label = labels[i] if labels else None
        color = cmap(0.1 + 0.8 * i / max(len(sols) - 1, 1))
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color=color, lw=2.2, label=label)
        ax.scatter(*p[-1], color=color, s=18)
        if frames:
            size = 0.08 * max(np.ptp(p, axis=0).max(), 1e-6)
            for k in np.linspace(0, len(p) - 1, frames).round().astype(int):
                r = sol.rotation[k]
                for axis, c in zip(range(3), ("tab:red", "tab:green", "tab:blue"), strict=True):
                    d = r[:, axis] * size
                    ax.plot(*np.column_stack((p[k], p[k] + d)), color=c, lw=1)
    pts = np.vstack(allpts)
    _set_equal_3d(ax, pts)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    if labels:
        ax.legend(loc="upper left", fontsize="small")
    if title:
        ax.set_title(title)
    return fig


def _model_stress(law, stretch: np.ndarray, measure: str) -> np.ndarray:
    """Stress of ``law`` at ``stretch`` in ``measure`` ("nominal" or "true"), Pa."""
    if measure == "true":
        return law.true_stress(stretch)
    return law.nominal_stress(stretch)


def plot_fit(curve, fits, *, labels=None, title: str | None = None, stretch_max=None):
    """Measured tensile curve against fitted laws, with a residual panel.

    Args:
        curve: The data, a :class:`softrod.materials.TensileCurve` (e.g. from
            :func:`softrod.read_tensile_csv`).
        fits: A :class:`softrod.UniaxialFit` (from :func:`softrod.fit_uniaxial` or
            ``curve.fit(...)``) or a sequence of them, fitted to ``curve``.
        labels: One legend label per fit (default: model name, RMS error and R²).
        title: Figure title (default: the curve's name).
        stretch_max: Largest stretch shown (default: the whole curve, or 1.5 times the largest
            fitted strain when the fits used only part of it).

    Returns:
        The matplotlib figure: stress (kPa, in the curve's stress measure) against engineering
        strain (%) on top, each law solid on its fitted range and dashed beyond it; residuals
        model - data (kPa) at the fitted points below. Points no fit used are grey.
    """
    import matplotlib.pyplot as plt

    fits = [fits] if hasattr(fits, "model") else list(fits)
    stretch = np.asarray(curve.stretch, dtype=float)
    stress = np.asarray(curve.stress, dtype=float)
    measure = curve.stress_measure
    fitted_max = max((f.stretch_range[1] for f in fits), default=stretch.max())
    if stretch_max is None:
        stretch_max = min(stretch.max(), 1.0 + 1.5 * (fitted_max - 1.0))
        stretch_max = max(stretch_max, fitted_max)
    shown = stretch <= stretch_max
    fig, (ax, ax_r) = plt.subplots(
        2,
        1,
        figsize=(7.0, 6.2),
        sharex=True,
        layout="constrained",
        gridspec_kw={"height_ratios": (2.4, 1)},
    )
    used = np.zeros(stretch.shape, dtype=bool)
    for fit in fits:
        lo, hi = fit.stretch_range
        used |= (stretch >= lo) & (stretch <= hi)
    strain_pct = (stretch - 1.0) * 100
    name = curve.name or "data"
    sel = used & shown
    ax.plot(strain_pct[sel], stress[sel] / 1e3, "o", ms=3, color="0.15", label=name)
    sel = ~used & shown
    if sel.any():
        ax.plot(strain_pct[sel], stress[sel] / 1e3, "o", ms=3, color="0.75", label="not fitted")
    cmap = plt.get_cmap("tab10")
    for i, fit in enumerate(fits):
        color = cmap(i % 10)
        law = fit.model
        lo, hi = fit.stretch_range
        label = (
            labels[i]
            if labels
            else f"{law.model_name} (RMS {fit.rms / 1e3:.3g} kPa, R² {fit.r_squared:.4f})"
        )
        inside = np.linspace(min(lo, 1.0), hi, 300)
        ax.plot(
            (inside - 1) * 100, _model_stress(law, inside, measure) / 1e3, color=color, label=label
        )
        if hi < stretch_max:
            beyond = np.linspace(hi, stretch_max, 200)
            ax.plot(
                (beyond - 1) * 100,
                _model_stress(law, beyond, measure) / 1e3,
                "--",
                color=color,
                lw=1,
            )
        mask = (stretch >= lo) & (stretch <= hi)
        residual = _model_stress(law, stretch[mask], measure) - stress[mask]
        ax_r.plot(strain_pct[mask], residual / 1e3, ".-", ms=3, lw=0.8, color=color)
    if fitted_max < stretch_max:
        ax.axvline((fitted_max - 1) * 100, color="0.5", ls=":", lw=1)
    # Keep diverging extrapolations from squashing the data.
    lo_y, hi_y = stress[shown].min() / 1e3, stress[shown].max() / 1e3
    pad = 0.08 * (hi_y - lo_y)
    ax.set_ylim(lo_y - pad, hi_y + pad)
    ax.set_xlim(min(strain_pct[shown].min(), 0.0), (stretch_max - 1) * 100)
    ax_r.axhline(0.0, color="0.3", lw=0.8)
    ax.set_ylabel(f"{measure} stress (kPa)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
    ax_r.set_xlabel("engineering strain (%)")
    ax_r.set_ylabel("model - data (kPa)")
    ax_r.grid(alpha=0.3)
    fig.suptitle(title or f"Uniaxial fit: {name}")
    return fig


# ------------------------------------------------------------------ compliance (issue 4)


def _ellipsoid_mesh(center, axes, directions, n: int = 18):
    """Surface of the ellipsoid with semi-axes ``axes`` along the rows of ``directions``."""
    u, v = np.meshgrid(np.linspace(0, 2 * np.pi, n), np.linspace(0, np.pi, n // 2 + 1))
    sphere = np.stack((np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)), axis=-1)
    pts = (sphere * axes) @ directions
    return [center[k] + pts[..., k] for k in range(3)]


def plot_compliance_ellipsoids(
    solution,
    compliance=None,
    *,
    nodes: int = 6,
    which: str = "translational",
    title: str | None = None,
    ax=None,
):
    """Compliance ellipsoids drawn along the backbone (world frame).

    At each selected node the ellipsoid has the principal compliances of the force-to-
    translation block (``which="translational"``, m/N) or of the moment-to-rotation block
    (``"rotational"``, rad/(N m)) of the integrated world compliance as semi-axes, along their
    eigenvectors, all scaled by one factor so that the largest is 20 % of the arm's extent.

    Args:
        solution: A :class:`softrod.StaticsSolution`.
        compliance: Its :func:`softrod.compliance` (computed when omitted).
        nodes: Number of nodes (evenly spaced along the mesh, base excluded).
        which: ``"translational"`` or ``"rotational"``.
        title: Figure title.
        ax: A 3-D matplotlib axes to draw into (default: a new figure).

    Returns:
        The matplotlib figure (axes in millimetres).
    """
    import matplotlib.pyplot as plt

    from .._core import compliance as _compliance

    if which not in ("translational", "rotational"):
        raise ValueError("which must be 'translational' or 'rotational'")
    comp = compliance if compliance is not None else _compliance(solution)
    blk = slice(0, 3) if which == "translational" else slice(3, 6)
    p = solution.position * 1e3
    if ax is None:
        fig = plt.figure(figsize=(6.5, 6.5), layout="constrained")
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    idx = np.unique(np.linspace(1, len(p) - 1, nodes).round().astype(int))
    eig = [np.linalg.eigh(comp.world[k][blk, blk]) for k in idx]
    largest = max(float(w.max()) for w, _ in eig)
    extent = max(float(np.ptp(p, axis=0).max()), 1e-9)
    scale = 0.2 * extent / largest
    cmap = plt.get_cmap("plasma")
    ax.plot(p[:, 0], p[:, 1], p[:, 2], color="0.2", lw=2.0)
    pts = [p]
    for j, (k, (w, v)) in enumerate(zip(idx, eig, strict=True)):
        x, y, z = _ellipsoid_mesh(p[k], np.clip(w, 0, None) * scale, v.T)
        color = cmap(0.15 + 0.7 * j / max(len(idx) - 1, 1))
        ax.plot_surface(x, y, z, color=color, alpha=0.35, linewidth=0)
        pts.append(np.column_stack((x.ravel(), y.ravel(), z.ravel())))
    _set_equal_3d(ax, np.vstack(pts))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    unit = "m/N" if which == "translational" else "rad/(N m)"
    head = title or f"{which} compliance ellipsoids"
    ax.set_title(f"{head}\n(semi-axes: principal compliances, 1 mm = {1 / scale:.3g} {unit})")
    return fig


def plot_gamma_c(compliances, *, labels=None, title: str | None = None):
    """Dimensionless flexural compliance ``gamma_c(s)`` along the arm, one panel per body axis.

    Args:
        compliances: A :class:`softrod.Compliance` or a sequence of them (e.g. one per
            actuation level).
        labels: One legend label per compliance.
        title: Figure title.

    Returns:
        The matplotlib figure.
    """
    import matplotlib.pyplot as plt

    comps = [compliances] if hasattr(compliances, "gamma_c") else list(compliances)
    fig, axes = plt.subplots(1, 3, figsize=(11, 3.6), layout="constrained", sharex=True)
    cmap = plt.get_cmap("viridis")
    for i, c in enumerate(comps):
        color = cmap(0.1 + 0.8 * i / max(len(comps) - 1, 1))
        for k, ax in enumerate(axes):
            ax.plot(
                c.s * 1e3, c.gamma_c[:, k], color=color, lw=1.8, label=labels[i] if labels else None
            )
    for k, ax in enumerate(axes):
        ax.set_title(f"body {'xyz'[k]}")
        ax.set_xlabel("s (mm)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(r"$\gamma_c = C_{f}\,3EI(0)/L^3$")
    if labels:
        axes[0].legend(fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def plot_workspace_map(
    wmap, *, measure: str = "max_translational_compliance", title: str | None = None
):
    """Tip positions of a workspace map coloured by a stiffness measure: top and side views.

    Args:
        wmap: A :class:`softrod.WorkspaceMap`.
        measure: ``"max_translational_compliance"`` (m/N, default),
            ``"min_translational_compliance"``, ``"tangent_max_translational_compliance"``
            (needs ``tangent=`` in :func:`softrod.workspace_map`), ``"condition"`` or
            ``"eigen_stiffness_k"`` (k-th eigenstiffness, k = 0..5).
        title: Figure title.

    Returns:
        The matplotlib figure (millimetres).
    """
    import matplotlib.pyplot as plt

    if measure.startswith("eigen_stiffness_"):
        values = wmap.eigen_stiffness[:, int(measure.rsplit("_", 1)[1])]
    else:
        values = getattr(wmap, measure)
    ok = wmap.converged & np.isfinite(values)
    p = wmap.tip_position[ok] * 1e3
    v = values[ok]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), layout="constrained")
    for ax, (i, j), name in zip(axes, ((0, 1), (0, 2)), ("top view", "side view"), strict=True):
        sc = ax.scatter(p[:, i], p[:, j], c=v, s=6, cmap="viridis")
        ax.set_xlabel(f"{'xyz'[i]} (mm)")
        ax.set_ylabel(f"{'xyz'[j]} (mm)")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(name)
        ax.grid(alpha=0.3)
    unit = {
        "max_translational_compliance": " (m/N)",
        "min_translational_compliance": " (m/N)",
        "tangent_max_translational_compliance": " (m/N)",
    }
    fig.colorbar(sc, ax=axes, label=measure.replace("_", " ") + unit.get(measure, ""))
    failed = int((~wmap.converged).sum())
    fig.suptitle(title or f"workspace map: {ok.sum()} configurations ({failed} not converged)")
    return fig


def plot_models(comparison, *, title: str | None = None):
    """Backbones of every applicable model of a :func:`softrod.compare_models` result,
    overlaid in 3-D, with the inapplicable models named in the legend title.

    Args:
        comparison: A :class:`softrod.ModelComparison`.
        title: Figure title (default: the robot's name).

    Returns:
        The matplotlib figure (axes in millimetres, world frame).
    """
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(6.5, 6.5), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    styles = {"cosserat": ("black", "-", 2.6), "pcc": ("tab:orange", "--", 2.0)}
    allpts = []
    for r in comparison.results:
        if not r.applies:
            continue
        color, ls, lw = styles.get(r.model, ("tab:blue", ":", 2.2))
        p = r.positions * 1e3
        allpts.append(p)
        label = r.model
        if r.model != "cosserat":
            label += f" (tip {r.tip_error * 1e3:.2f} mm, {np.degrees(r.angle_error):.2f} deg)"
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color=color, ls=ls, lw=lw, label=label)
        ax.scatter(*p[-1], color=color, s=18)
    _set_equal_3d(ax, np.vstack(allpts))
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    missing = [r.model for r in comparison.results if not r.applies]
    ax.legend(
        loc="upper left",
        fontsize="small",
        title=("not applicable: " + ", ".join(missing)) if missing else None,
        title_fontsize="small",
    )
    ax.set_title(title or comparison.robot)
    return fig
