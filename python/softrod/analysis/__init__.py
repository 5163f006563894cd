"""Analyses built on the solvers: backbone comparison at equal arm index, models side by side,
workspace maps, tensile curves and material fits, and the compliance study of soft arms."""

from .compare import BackboneDistance, backbone_distance
from .materials import TensileCurve, read_tensile_csv
from .models import ModelComparison, ModelResult, compare_models
from .study import seed001_study
from .workspace import WorkspaceMap, tension_grid, workspace_map

__all__ = [
    "BackboneDistance",
    "ModelComparison",
    "ModelResult",
    "TensileCurve",
    "WorkspaceMap",
    "backbone_distance",
    "compare_models",
    "read_tensile_csv",
    "seed001_study",
    "tension_grid",
    "workspace_map",
]
