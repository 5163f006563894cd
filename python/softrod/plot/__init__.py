"""Figures (matplotlib): planar arms, 3-D rods, compliance, workspace maps, model comparisons,
material fits. Every function returns a :class:`matplotlib.figure.Figure`."""

from .figures import (
    plot_compliance_ellipsoids,
    plot_fit,
    plot_gamma_c,
    plot_models,
    plot_planar,
    plot_rod,
    plot_workspace_map,
)

__all__ = [
    "plot_compliance_ellipsoids",
    "plot_fit",
    "plot_gamma_c",
    "plot_models",
    "plot_planar",
    "plot_rod",
    "plot_workspace_map",
]
