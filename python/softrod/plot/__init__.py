"""Figures (matplotlib) and the live 3-D view (viser).

Every figure function returns a :class:`matplotlib.figure.Figure` in millimetres and takes
``size`` (inches), ``dpi`` and ``style`` (a matplotlib style); :func:`save_figure` writes PNG,
PDF or SVG from the file's extension. :func:`softrod.plot.live.serve` starts the live view.
"""

from ._figure import FIGURE_FORMATS, check_figure_path, save_figure
from .animation import SweepAnimation, animate_sweep
from .compliance import plot_compliance_ellipsoids, plot_gamma_c
from .fit import plot_fit
from .geometry import ChamberGeometry, RobotGeometry, TendonGeometry, robot_geometry
from .models import plot_models
from .obstacles import Capsule, Cylinder, Plane, Sphere
from .planar import plot_planar, plot_planar_rod
from .views import BendingView, bending_view, plot_robot, plot_rod
from .workspace import plot_workspace_map

__all__ = [
    "FIGURE_FORMATS",
    "BendingView",
    "Capsule",
    "ChamberGeometry",
    "Cylinder",
    "Plane",
    "RobotGeometry",
    "Sphere",
    "SweepAnimation",
    "TendonGeometry",
    "animate_sweep",
    "bending_view",
    "check_figure_path",
    "plot_compliance_ellipsoids",
    "plot_fit",
    "plot_gamma_c",
    "plot_models",
    "plot_planar",
    "plot_planar_rod",
    "plot_robot",
    "plot_rod",
    "plot_workspace_map",
    "robot_geometry",
    "save_figure",
]
