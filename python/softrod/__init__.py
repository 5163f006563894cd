"""softrod: steady-state shape and compliance of soft and continuum robots.

SI units everywhere (m, N, Pa, rad). See https://softrod docs in ``docs/`` for the models.

The numerics live in the compiled core ``softrod._core``; this package re-exports it and adds
file I/O (:mod:`softrod.io`), plots (:mod:`softrod.plot`) and the ``softrod`` command line
(:mod:`softrod.cli`).
"""

from ._core import (
    CircularSection,
    ConvergenceError,
    FunctionSection,
    LinearElastic,
    Loads,
    ParameterError,
    PlanarBatch,
    PlanarCableArm,
    PlanarSolution,
    PointLoad,
    Rod,
    Section,
    StaticsSolution,
    TableSection,
    TaperedCircularSection,
    Tendon,
    TubeSection,
    __version__,
    solve_statics,
)
from .compare import BackboneDistance, backbone_distance
from .io import read_backbone_csv, write_samples_csv
from .robot import Robot, load_robot

__all__ = [
    "BackboneDistance",
    "CircularSection",
    "ConvergenceError",
    "FunctionSection",
    "LinearElastic",
    "Loads",
    "ParameterError",
    "PlanarBatch",
    "PlanarCableArm",
    "PlanarSolution",
    "PointLoad",
    "Robot",
    "Rod",
    "Section",
    "StaticsSolution",
    "TableSection",
    "TaperedCircularSection",
    "Tendon",
    "TubeSection",
    "__version__",
    "backbone_distance",
    "load_robot",
    "read_backbone_csv",
    "solve_statics",
    "write_samples_csv",
]
