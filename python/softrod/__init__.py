"""softrod: steady-state shape and compliance of soft and continuum robots.

SI units everywhere (m, N, Pa, rad). See https://softrod docs in ``docs/`` for the models.

The numerics live in the compiled core ``softrod._core``; this package re-exports it and adds
file I/O (:mod:`softrod.io`), plots (:mod:`softrod.plot`) and the ``softrod`` command line
(:mod:`softrod.cli`).
"""

from . import pcc
from ._core import (
    SILICONES,
    CircularSection,
    ConvergenceError,
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
    StaticsSolution,
    TableSection,
    TaperedCircularSection,
    Tendon,
    TubeSection,
    UniaxialFit,
    UniaxialLaw,
    Yeoh,
    __version__,
    fit_uniaxial,
    silicone,
    solve_statics,
)
from .compare import BackboneDistance, backbone_distance
from .io import read_backbone_csv, write_samples_csv
from .materials import TensileCurve, read_tensile_csv
from .robot import Robot, load_robot

__all__ = [
    "SILICONES",
    "BackboneDistance",
    "CircularSection",
    "ConvergenceError",
    "FunctionSection",
    "Hookean",
    "LinearElastic",
    "Linearised",
    "Loads",
    "MooneyRivlin",
    "NeoHookean",
    "Ogden",
    "ParameterError",
    "PlanarBatch",
    "PlanarCableArm",
    "PlanarSolution",
    "PointLoad",
    "Robot",
    "Rod",
    "Section",
    "Silicone",
    "StaticsSolution",
    "TableSection",
    "TaperedCircularSection",
    "Tendon",
    "TensileCurve",
    "TubeSection",
    "UniaxialFit",
    "UniaxialLaw",
    "Yeoh",
    "__version__",
    "backbone_distance",
    "fit_uniaxial",
    "load_robot",
    "pcc",
    "read_backbone_csv",
    "read_tensile_csv",
    "silicone",
    "solve_statics",
    "write_samples_csv",
]
