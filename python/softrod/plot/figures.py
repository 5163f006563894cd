"""Earlier module path of the figures, kept importable: every name now lives in a module of
:mod:`softrod.plot` (``planar``, ``views``, ``compliance``, ``workspace``, ``fit``, ``models``)."""

from .compliance import plot_compliance_ellipsoids, plot_gamma_c
from .fit import plot_fit
from .models import plot_models
from .planar import plot_planar
from .views import plot_rod
from .workspace import plot_workspace_map

__all__ = [
    "plot_compliance_ellipsoids",
    "plot_fit",
    "plot_gamma_c",
    "plot_models",
    "plot_planar",
    "plot_rod",
    "plot_workspace_map",
]
