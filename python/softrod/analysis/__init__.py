"""Analyses built on the solvers: backbone comparison at equal arm index, calibration of model
parameters to measured shapes, models side by side,
workspace maps, tensile curves and material fits, the compliance study of soft arms, and design
sweeps with their summaries."""

from .calibration import Calibration, IdentifiabilityWarning, PoorFitWarning, calibrate
from .compare import BackboneDistance, backbone_distance
from .design import Pareto, design_summary
from .materials import TensileCurve, read_tensile_csv
from .models import ModelComparison, ModelResult, compare_models
from .study import compliance_study, seed001_study
from .sweep import SampleTable, samples, sweep
from .workspace import WorkspaceMap, tension_grid, workspace_map

__all__ = [
    "BackboneDistance",
    "Calibration",
    "IdentifiabilityWarning",
    "ModelComparison",
    "ModelResult",
    "Pareto",
    "PoorFitWarning",
    "SampleTable",
    "TensileCurve",
    "WorkspaceMap",
    "backbone_distance",
    "calibrate",
    "compare_models",
    "compliance_study",
    "design_summary",
    "read_tensile_csv",
    "samples",
    "seed001_study",
    "sweep",
    "tension_grid",
    "workspace_map",
]
