"""softrod: steady-state shape and compliance of soft and continuum robots.

SI units everywhere (m, N, Pa, rad). See https://softrod docs in ``docs/`` for the models.

The numerics live in the compiled core ``softrod._core``; this package re-exports it and adds
file I/O (:mod:`softrod.io`), analyses (:mod:`softrod.analysis`), plots (:mod:`softrod.plot`),
backbones from photographs (:mod:`softrod.vision`) and the ``softrod`` command line
(:mod:`softrod.cli`).
"""

from . import examples, pcc, vision
from ._core import (
    SILICONES,
    Chamber,
    CircularSection,
    Compliance,
    ConvergenceError,
    Eigenscrews,
    FunctionSection,
    Hookean,
    LinearElastic,
    Linearised,
    Loads,
    MooneyRivlin,
    NeoHookean,
    Ogden,
    ParameterError,
    PlanarBatch,
    PlanarCableArm,
    PlanarSolution,
    PointLoad,
    Rod,
    Section,
    Silicone,
    StabilityError,
    StabilityWarning,
    StaticsSolution,
    TableSection,
    TangentCompliance,
    TaperedCircularSection,
    TargetUnreachableError,
    Tendon,
    TubeSection,
    UniaxialFit,
    UniaxialLaw,
    Yeoh,
    __version__,
    actuation_jacobian,
    compliance,
    eigenscrews,
    fit_uniaxial,
    silicone,
    solve_statics,
    tangent_compliance,
)
from .analysis import (
    BackboneDistance,
    Calibration,
    IdentifiabilityWarning,
    ModelComparison,
    ModelResult,
    Pareto,
    PoorFitWarning,
    SampleTable,
    TensileCurve,
    WorkspaceMap,
    backbone_distance,
    calibrate,
    compare_models,
    design_summary,
    read_tensile_csv,
    samples,
    sweep,
    tension_grid,
    workspace_map,
)
from .contact import Capsule, Clamp, Cylinder, Mesh, Pin, Plane, Slide, Sphere
from .inverse import InversePath, InverseSolution, inverse_statics, inverse_statics_path
from .io import read_backbone_csv, write_samples_csv
from .robot import Robot, load_robot, solve_path
from .vision import Backbone, BackboneQuality

__all__ = [
    "SILICONES",
    "Backbone",
    "BackboneDistance",
    "BackboneQuality",
    "Calibration",
    "Capsule",
    "Chamber",
    "CircularSection",
    "Clamp",
    "Compliance",
    "ConvergenceError",
    "Cylinder",
    "Eigenscrews",
    "FunctionSection",
    "Hookean",
    "IdentifiabilityWarning",
    "InversePath",
    "InverseSolution",
    "LinearElastic",
    "Linearised",
    "Loads",
    "Mesh",
    "ModelComparison",
    "ModelResult",
    "MooneyRivlin",
    "NeoHookean",
    "Ogden",
    "ParameterError",
    "Pareto",
    "Pin",
    "PlanarBatch",
    "PlanarCableArm",
    "PlanarSolution",
    "Plane",
    "PointLoad",
    "PoorFitWarning",
    "Robot",
    "Rod",
    "SampleTable",
    "Section",
    "Silicone",
    "Slide",
    "Sphere",
    "StabilityError",
    "StabilityWarning",
    "StaticsSolution",
    "TableSection",
    "TangentCompliance",
    "TaperedCircularSection",
    "TargetUnreachableError",
    "Tendon",
    "TensileCurve",
    "TubeSection",
    "UniaxialFit",
    "UniaxialLaw",
    "WorkspaceMap",
    "Yeoh",
    "__version__",
    "actuation_jacobian",
    "backbone_distance",
    "calibrate",
    "compare_models",
    "compliance",
    "design_summary",
    "eigenscrews",
    "examples",
    "extract_backbone",
    "fit_uniaxial",
    "inverse_statics",
    "inverse_statics_path",
    "load_robot",
    "pcc",
    "read_backbone_csv",
    "read_tensile_csv",
    "samples",
    "silicone",
    "solve_path",
    "solve_statics",
    "sweep",
    "tangent_compliance",
    "tension_grid",
    "vision",
    "workspace_map",
    "write_samples_csv",
]


# Module paths of earlier releases, kept importable: ``softrod.study``, ``softrod.workspace``,
# ``softrod.models``, ``softrod.compare`` and ``softrod.materials`` now live in ``analysis``.
def _alias_modules() -> None:
    import sys

    from .analysis import compare, materials, models, study
    from .analysis import workspace as _workspace

    for name, module in {
        "compare": compare,
        "materials": materials,
        "models": models,
        "study": study,
        "workspace": _workspace,
    }.items():
        sys.modules[f"{__name__}.{name}"] = module
        globals()[name] = module


_alias_modules()


def __getattr__(name: str):
    # ``extract_backbone`` loads the image-processing stack on first use (see softrod.vision).
    if name == "extract_backbone":
        from .vision import extract_backbone

        globals()[name] = extract_backbone
        return extract_backbone
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
