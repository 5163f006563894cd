"""Bad-input fuzz of the Python API: every public callable x bad values, in subprocesses.

Each *target* is one public callable of ``softrod.__all__`` or ``softrod.pcc.__all__`` (a
function, a class constructor, a static or instance method) with a valid baseline call written
out by hand below (every parameter given a valid value). A *call* replaces one parameter of the
baseline by one bad value, chosen by the baseline value's kind: NaN, +-inf, negative, zero, huge
(1e308; 2**40 for sizes), wrong type, wrong shape, None, strings, non-finite elements, empty
arrays, callbacks that raise or return NaN. Results classes that users do not construct
(solutions, compliances) and result dataclasses are not targets; their methods are.

Calls run in worker subprocesses (batches of many calls; the worker announces each call
before making it, so an abort is pinned to its call) under a 4 GB address-space limit, so that
an abort, a segfault or a runaway allocation cannot take the test run down. Outcomes:

- ``ok-finite``: returned; every number reachable from the result is finite;
- ``ok-nonfinite``: returned with NaN/inf somewhere the baseline result has none (a defect);
- ``named-error``: ParameterError/ValueError/TypeError whose ``parameter`` or message names the
  argument;
- ``unnamed-error``: any other exception, or one of those that does not name it;
- ``panic``: a Rust ``PanicException`` (a defect);
- ``abort``: the worker died (signal or exit code; a defect);
- ``hang``: no answer within the timeout (a defect).

``accepted-nonfinite`` is counted beside: a NaN/inf argument that was accepted (ok-finite).
"""

from __future__ import annotations

import json
import math
import os
import queue
import random
import re
import subprocess
import sys
import tempfile
import threading
from collections import Counter
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, fields, is_dataclass
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1]
ERROR_TYPES = ("ParameterError", "ValueError", "TypeError")
MEMORY_LIMIT = 4 << 30

# ----------------------------------------------------------------------------- baselines


class Sentinel(Exception):
    """Raised by fuzzed callbacks: it must reach the caller (not become a NaN)."""


def _sr():
    import softrod

    return softrod


def _rod():
    sr = _sr()
    return sr.Rod(0.3, sr.CircularSection(0.002), sr.LinearElastic(5e7, 0.3), density=1100.0)


def _tendons():
    sr = _sr()
    return [sr.Tendon((0.001, 0.0), 0.5), sr.Tendon((0.0, 0.001), 0.2, 0.15)]


def _loads():
    return _sr().Loads(tip_force=(0.01, 0.0, 0.0))


def _solution():
    return _sr().solve_statics(_rod(), _tendons(), _loads())


ANGLES = [math.pi / 2, -math.pi / 6, 7 * math.pi / 6]


def _pcc_robot():
    from softrod import pcc

    return (
        pcc.Robot.solid_circle([0.2, 0.2], 0.7e-3, 54e9)
        .with_tendons(0, [0.01] * 3, ANGLES)
        .with_tendons(1, [0.01] * 3, ANGLES)
    )


def _pcc_solution():
    from softrod import pcc

    return pcc.solve(_pcc_robot(), [1.0, 0.0, 0.0, 0.0, 0.5, 0.0])


def _planar_shapes():
    import numpy as np

    arm = _sr().PlanarCableArm(0.27, 0.015, 0.0074, 0.3, 1.3e5)
    out = []
    for t in (0.5, 1.0):
        sol = arm.solve(t, 15)
        out.append((t, np.column_stack([sol.x, sol.y])))
    return out


def _niti():
    sr = _sr()
    return sr.load_robot(sr.examples.path("niti_two_segment"))


def _niti_friction():
    robot = _niti()
    spec = robot.spec.model_dump(mode="python", exclude_none=True)
    for t in spec["tendons"]:
        t["friction"] = 0.2
    return _sr().Robot.from_dict(spec)


def _chambered():
    sr = _sr()
    rod = sr.Rod(0.2, sr.CircularSection(0.01), sr.LinearElastic(1e6, 0.45))
    return sr.Robot(rod, chambers=[sr.Chamber(2e3, 1e-5, (0.004, 0.0))])


def _sweep_ds():
    import numpy as np

    return _sr().sweep(
        _niti(),
        actuation={"tendons[0].tension": np.linspace(0.0, 2.0, 5), "tendons[1].tension": [0, 1]},
        outputs=("tip_pose", "translational_compliance"),
        progress=False,
    )


def _law(kind: str):
    sr = _sr()
    return {
        "yeoh": lambda: sr.Yeoh(3e4, -1e2, 10.0),
        "neo-hookean": lambda: sr.NeoHookean(3e4),
        "mooney-rivlin": lambda: sr.MooneyRivlin(3e4, 1e4),
        "ogden": lambda: sr.Ogden([3e4, 1e3], [2.0, -2.0]),
        "hookean": lambda: sr.Hookean(1e5),
    }[kind]()


def _curve_data():
    strain = np.linspace(0.0, 1.0, 11)
    lam = 1.0 + strain
    return strain, 2 * 3e4 * (lam - lam**-2)


def _files(tmp: Path) -> dict[str, str]:
    bb = tmp / "backbone.csv"
    if not bb.exists():
        bb.write_text("x,y,z\n" + "\n".join(f"{0.01 * i},0,{0.02 * i}" for i in range(10)))
    tc = tmp / "tensile.csv"
    if not tc.exists():
        s, p = _curve_data()
        tc.write_text("strain,stress\n" + "\n".join(f"{a},{b}" for a, b in zip(s, p, strict=True)))
    return {"backbone": str(bb), "tensile": str(tc)}


def _robot_dict():
    return {
        "rod": {
            "length": 0.3,
            "section": {"radius": 0.002},
            "material": {"youngs_modulus": 5e7, "poisson_ratio": 0.3},
        },
        "tendons": [{"distance": 0.001, "angle_deg": 0, "tension": 0.5}],
    }


_TOML = """
[rod]
length = 0.3
[rod.section]
radius = 0.002
[rod.material]
youngs_modulus = 5e7
poisson_ratio = 0.3
[[tendons]]
distance = 0.001
angle_deg = 0
tension = 0.5
"""

# name -> builder returning (callable, baseline kwargs). Order is part of the call numbering.
TARGETS: dict[str, Callable[[Path], tuple[Callable, dict]]] = {}


def target(name: str):
    def deco(fn):
        TARGETS[name] = fn
        return fn

    return deco


def _define_targets() -> None:
    sr = _sr()
    from softrod import pcc

    t = target
    t("Chamber")(
        lambda d: (
            sr.Chamber,
            dict(pressure=1e3, area=1e-6, offset=(0.001, 0.0), start=0.0, end=0.2),
        )
    )
    t("Chamber(area function)")(
        lambda d: (
            sr.Chamber,
            dict(pressure=1e3, area=lambda s: 1e-6 * (1 - s), offset=(0.001, 0.0)),
        )
    )
    t("Chamber.with_pressure")(
        lambda d: (sr.Chamber(1e3, 1e-6, (0.001, 0.0)).with_pressure, dict(pressure=2e3))
    )
    t("Chamber.area_at")(lambda d: (sr.Chamber(1e3, 1e-6, (0.001, 0.0)).area_at, dict(s=0.1)))
    t("CircularSection")(lambda d: (sr.CircularSection, dict(radius=0.002)))
    t("TaperedCircularSection")(
        lambda d: (sr.TaperedCircularSection, dict(base_radius=0.003, tip_radius=0.001))
    )
    t("TubeSection")(lambda d: (sr.TubeSection, dict(outer_radius=0.003, inner_radius=0.001)))
    t("TableSection")(
        lambda d: (
            sr.TableSection,
            dict(
                s=[0.0, 0.3],
                area=[1.2e-5, 1.0e-5],
                ix=[1.1e-11, 0.9e-11],
                iy=[1.1e-11, 0.9e-11],
                j=[2.2e-11, 1.8e-11],
            ),
        )
    )
    t("FunctionSection")(
        lambda d: (sr.FunctionSection, dict(function=lambda s: (1.2e-5, 1.1e-11, 1.1e-11, 2.2e-11)))
    )
    t("FunctionSection -> solve_statics")(
        lambda d: (
            _solve_function_section,
            dict(function=lambda s: (1.2e-5, 1.1e-11, 1.1e-11, 2.2e-11)),
        )
    )
    t("Section.properties")(
        lambda d: (sr.CircularSection(0.002).properties, dict(s=0.1, length=0.3))
    )
    t("LinearElastic")(lambda d: (sr.LinearElastic, dict(youngs_modulus=1e6, poisson_ratio=0.3)))
    t("LinearElastic(shear_modulus)")(
        lambda d: (sr.LinearElastic, dict(youngs_modulus=1e6, shear_modulus=3.5e5))
    )
    t("Hookean")(lambda d: (sr.Hookean, dict(youngs_modulus=1e5)))
    t("Linearised")(lambda d: (sr.Linearised, dict(secant_modulus=1e5, reference_strain=0.2)))
    t("Linearised.from_secant_point")(
        lambda d: (sr.Linearised.from_secant_point, dict(nominal_stress=2e4, strain=0.2))
    )
    t("NeoHookean")(lambda d: (sr.NeoHookean, dict(mu=3e4)))
    t("MooneyRivlin")(lambda d: (sr.MooneyRivlin, dict(c10=3e4, c01=1e4)))
    t("Yeoh")(lambda d: (sr.Yeoh, dict(c10=3e4, c20=-1e2, c30=10.0)))
    t("Ogden")(lambda d: (sr.Ogden, dict(mu=[3e4, 1e3], alpha=[2.0, -2.0])))
    for kind in ("yeoh", "neo-hookean", "mooney-rivlin", "ogden", "hookean"):
        for method, kw in (
            ("nominal_stress", dict(stretch=[1.0, 1.2])),
            ("true_stress", dict(stretch=[1.0, 1.2])),
            ("nominal_tangent", dict(stretch=[1.0, 1.2])),
            ("tangent_modulus", dict(strain=[0.0, 0.2])),
            ("stretch_from_nominal_stress", dict(nominal_stress=[0.0, 1e4])),
            ("check_stable", dict(stretch_min=0.8, stretch_max=1.5)),
        ):
            t(f"{kind}.{method}")(
                lambda d, kind=kind, method=method, kw=kw: (getattr(_law(kind), method), dict(kw))
            )
        t(f"{kind}.nominal_stress(scalar)")(
            lambda d, kind=kind: (_law(kind).nominal_stress, dict(stretch=1.2))
        )
    t("fit_uniaxial")(
        lambda d: (
            sr.fit_uniaxial,
            dict(
                strain=_curve_data()[0],
                stress=_curve_data()[1],
                model="yeoh",
                strain_measure="engineering",
                stress_measure="nominal",
                terms=None,
                nonnegative=False,
                stretch_range=(1.0, 2.0),
                max_iterations=200,
                tolerance=1e-10,
            ),
        )
    )
    t("fit_uniaxial(ogden terms)")(
        lambda d: (
            sr.fit_uniaxial,
            dict(strain=_curve_data()[0], stress=_curve_data()[1], model="ogden", terms=2),
        )
    )
    t("silicone")(lambda d: (sr.silicone, dict(name=sr.SILICONES[0])))
    t("TensileCurve")(
        lambda d: (
            sr.TensileCurve,
            dict(
                strain=_curve_data()[0],
                stress=_curve_data()[1],
                strain_measure="engineering",
                stress_measure="nominal",
                name="x",
                metadata={"source": "test"},
            ),
        )
    )
    t("TensileCurve.fit")(lambda d: (sr.TensileCurve(*_curve_data()).fit, dict(model="yeoh")))
    t("read_tensile_csv")(
        lambda d: (
            sr.read_tensile_csv,
            dict(
                path=_files(d)["tensile"],
                columns="engineering",
                strain_measure="engineering",
                stress_measure="nominal",
                strain_unit="fraction",
                stress_unit="Pa",
            ),
        )
    )
    t("PlanarCableArm")(
        lambda d: (
            sr.PlanarCableArm,
            dict(
                length=0.27,
                base_radius=0.015,
                tip_radius=0.0074,
                offset_ratio=1 / 3,
                youngs_modulus=110e3,
                anchor=0.27,
            ),
        )
    )
    t("PlanarCableArm.radius")(
        lambda d: (sr.PlanarCableArm.published_arm().radius, dict(s=[0.0, 0.1, 0.27]))
    )
    t("PlanarCableArm.radius(scalar)")(
        lambda d: (sr.PlanarCableArm.published_arm().radius, dict(s=0.1))
    )
    t("PlanarCableArm.solve")(
        lambda d: (
            sr.PlanarCableArm.published_arm().solve,
            dict(tension=1.0, n_points=21, method="ode", rtol=1e-8, atol=1e-10, max_steps=100000),
        )
    )
    t("PlanarCableArm.solve(s)")(
        lambda d: (
            sr.PlanarCableArm.published_arm().solve,
            dict(tension=1.0, s=[0.0, 0.1, 0.2], method="closed-form"),
        )
    )
    t("PlanarCableArm.solve_many")(
        lambda d: (
            sr.PlanarCableArm.published_arm().solve_many,
            dict(
                tensions=[0.5, 1.0],
                n_points=21,
                method="ode",
                rtol=1e-8,
                atol=1e-10,
                max_steps=100000,
            ),
        )
    )
    t("PlanarCableArm.solve_many(s)")(
        lambda d: (
            sr.PlanarCableArm.published_arm().solve_many,
            dict(tensions=[0.5, 1.0], s=[0.0, 0.1, 0.2]),
        )
    )
    t("write_samples_csv")(
        lambda d: (
            sr.write_samples_csv,
            dict(
                path=str(d / "samples.csv"),
                solutions=[sr.PlanarCableArm.published_arm().solve(1.0, n_points=11)],
            ),
        )
    )
    t("backbone_distance")(
        lambda d: (
            sr.backbone_distance,
            dict(
                a=np.linspace([0, 0, 0], [0.1, 0, 0.2], 20),
                b=np.linspace([0, 0, 0], [0.12, 0, 0.2], 30),
                n_index=50,
            ),
        )
    )
    t("read_backbone_csv")(
        lambda d: (
            sr.read_backbone_csv,
            dict(path=_files(d)["backbone"], scale=1.0, columns=[0, 1, 2]),
        )
    )
    t("Rod")(
        lambda d: (
            sr.Rod,
            dict(
                length=0.3,
                section=sr.CircularSection(0.002),
                material=sr.LinearElastic(5e7, 0.3),
                rest_strain=(0.0, 0.0, 1.0),
                rest_curvature=(0.0, 1.0, 0.0),
                inextensible=False,
                density=1100.0,
                base_pose=np.eye(4),
                shear_coefficient=0.9,
            ),
        )
    )
    t("Rod(functions)")(
        lambda d: (
            sr.Rod,
            dict(
                length=0.3,
                section=sr.CircularSection(0.002),
                material=sr.Yeoh(3e5),
                rest_strain=lambda s: (0.0, 0.0, 1.0),
                rest_curvature=lambda s: (0.0, s, 0.0),
                base_pose=(np.zeros(3), np.eye(3)),
            ),
        )
    )
    t("Rod(functions) -> solve_statics")(
        lambda d: (_solve_rest_curvature, dict(rest_curvature=lambda s: (0.0, s, 0.0)))
    )
    t("Tendon")(lambda d: (sr.Tendon, dict(offset=(0.001, 0.0), tension=0.5, end=0.2)))
    t("Tendon(function)")(
        lambda d: (
            sr.Tendon,
            dict(
                offset=lambda s: (0.001, 0.0005 * s),
                tension=0.5,
                derivative=lambda s: (0.0, 0.0005),
            ),
        )
    )
    t("Tendon(function) -> solve_statics")(
        lambda d: (
            _solve_function_tendon,
            dict(offset=lambda s: (0.001, 0.0005 * s), derivative=lambda s: (0.0, 0.0005)),
        )
    )
    t("Tendon.radius_proportional")(
        lambda d: (
            sr.Tendon.radius_proportional,
            dict(ratio=1 / 3, angle=0.0, tension=1.0, end=0.2),
        )
    )
    t("Tendon.helical")(
        lambda d: (
            sr.Tendon.helical,
            dict(radius=0.001, pitch=0.2, tension=0.5, phase=0.0, end=0.25),
        )
    )
    t("Tendon(friction)")(
        lambda d: (sr.Tendon, dict(offset=(0.001, 0.0), tension=0.5, end=0.2, friction=0.2))
    )
    t("Tendon(guides)")(
        lambda d: (
            sr.Tendon,
            dict(
                offset=(0.001, 0.0),
                tension=0.5,
                end=0.2,
                guides=[0.05, 0.1, 0.15],
                guide_friction=[0.1, 0.2, 0.3],
            ),
        )
    )
    t("Tendon.radius_proportional(friction)")(
        lambda d: (
            sr.Tendon.radius_proportional,
            dict(ratio=1 / 3, angle=0.0, tension=1.0, friction=0.2),
        )
    )
    t("Tendon.helical(friction)")(
        lambda d: (
            sr.Tendon.helical,
            dict(radius=0.001, pitch=0.2, tension=0.5, friction=0.2),
        )
    )
    t("solve_statics(friction, previous)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=_rod(),
                tendons=[sr.Tendon((0.001, 0.0), 0.3, friction=0.2)],
                loads=_loads(),
                previous=sr.solve_statics(
                    _rod(), [sr.Tendon((0.001, 0.0), 0.5, friction=0.2)], _loads()
                ),
            ),
        )
    )
    t("solve_path")(
        lambda d: (
            sr.solve_path,
            dict(
                robot=_niti_friction(),
                actuations=[[1.0, 0, 0, 0, 0.5, 0], [2.0, 0, 0, 0, 0.5, 0], [1.0, 0, 0, 0, 0.5, 0]],
                pressures=None,
                steps=30,
            ),
        )
    )
    t("Tendon.with_tension")(
        lambda d: (sr.Tendon((0.001, 0.0), 0.5).with_tension, dict(tension=1.0))
    )
    t("PointLoad")(
        lambda d: (
            sr.PointLoad,
            dict(s=0.1, force=(0.01, 0.0, 0.0), moment=(0.0, 0.0, 0.001), frame="world"),
        )
    )
    t("Loads")(
        lambda d: (
            sr.Loads,
            dict(
                tip_force=(0.01, 0.0, 0.0),
                tip_moment=(0.0, 0.001, 0.0),
                gravity=(0.0, 0.0, -9.81),
                tip_frame="world",
                point_loads=[sr.PointLoad(0.1, (0.01, 0.0, 0.0))],
                distributed_force=(0.0, 0.01, 0.0),
                distributed_moment=(0.0, 0.0, 0.001),
            ),
        )
    )
    t("Loads(functions) -> solve_statics")(
        lambda d: (
            _solve_distributed,
            dict(
                distributed_force=lambda s: (0.0, 0.01 * s, 0.0),
                distributed_moment=lambda s: (0.0, 0.0, 0.001),
            ),
        )
    )
    t("solve_statics")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=_rod(),
                tendons=_tendons(),
                loads=_loads(),
                integrator="rk4",
                steps=40,
                rtol=1e-8,
                atol=1e-10,
                tolerance=1e-10,
                max_iterations=30,
                continuation=True,
                max_load_steps=64,
                warm_start=None,
                throw=True,
                chambers=[],
                s_out=[0.05, 0.1],
                seek_stable=True,
                on_unstable="ignore",
            ),
        )
    )
    t("solve_statics(contact)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=sr.Rod(1.0, sr.CircularSection(1e-3), sr.LinearElastic(2e9, 0.3)),
                tendons=[],
                loads=sr.Loads(tip_force=(-1e-5, 0.0, 0.0)),
                steps=60,
                obstacles=[sr.Plane((-2e-3, 0.0, 0.0), (1.0, 0.0, 0.0))],
                tip_constraint=None,
            ),
        )
    )
    t("solve_statics(tip_constraint)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=sr.Rod(1.0, sr.CircularSection(1e-3), sr.LinearElastic(2e9, 0.3)),
                tendons=[],
                loads=sr.Loads(point_loads=[sr.PointLoad(0.5, (1e-6, 0.0, 0.0))]),
                steps=60,
                obstacles=None,
                tip_constraint=sr.Pin((0.0, 0.0, 1.0)),
            ),
        )
    )
    t("Plane")(
        lambda d: (sr.Plane, dict(point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), friction=0.3))
    )
    t("Sphere")(lambda d: (sr.Sphere, dict(center=(0.0, 0.0, 0.1), radius=0.02, friction=0.3)))
    t("Capsule")(
        lambda d: (
            sr.Capsule,
            dict(a=(0.0, 0.0, 0.0), b=(0.0, 0.1, 0.0), radius=0.01, friction=0.3),
        )
    )
    t("Cylinder")(
        lambda d: (
            sr.Cylinder,
            dict(a=(0.0, 0.0, 0.0), b=(0.0, 0.1, 0.0), radius=0.01, friction=0.3),
        )
    )
    _tetra = dict(
        vertices=[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
        faces=[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    t("Mesh")(lambda d: (sr.Mesh, dict(_tetra, friction=0.3)))
    t("Mesh.from_file")(
        lambda d: (sr.Mesh.from_file, dict(path=_mesh_file(d, _tetra), friction=0.3))
    )
    t("Clamp")(
        lambda d: (sr.Clamp, dict(pose=np.eye(4), held=[True, True, False, True, True, False]))
    )
    t("Pin")(lambda d: (sr.Pin, dict(point=(0.0, 0.0, 0.1))))
    t("Slide")(lambda d: (sr.Slide, dict(point=(0.0, 0.0, 0.1), normal=(0.0, 0.0, 1.0))))
    t("solve_statics(adaptive, warm)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=_rod(),
                tendons=_tendons(),
                loads=_loads(),
                integrator="adaptive",
                warm_start=[0.01, 0.0, 0.0, 0.0, 0.003, 0.0],
                throw=False,
            ),
        )
    )
    t("solve_statics(displacements)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=_rod(),
                tendons=_tendons(),
                loads=_loads(),
                displacements=[0.0005, None],
                tendon_stiffness=[1e4, 1e4],
            ),
        )
    )
    t("actuation_jacobian")(
        lambda d: (sr.actuation_jacobian, dict(solution=_solution(), node=10, direction=1))
    )
    t("actuation_jacobian(pcc)")(
        lambda d: (sr.actuation_jacobian, dict(solution=_pcc_solution(), node=-1, direction=1))
    )
    t("inverse_statics")(
        lambda d: (
            sr.inverse_statics,
            dict(
                robot=_niti(),
                target_position=[0.03388176, 0.03906025, 0.3958294],
                target_rotation=None,
                weights=[1.0] * 6,
                tension_bounds=(0.0, 10.0),
                pressure_bounds=(0.0, None),
                warm_start=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
                throw=False,
                tolerance=1e-9,
                max_iterations=60,
            ),
        )
    )
    t("inverse_statics(shape)")(
        lambda d: (
            sr.inverse_statics,
            dict(
                robot=_niti(),
                target_position=np.asarray(
                    _niti().solve([0.0, 1.5, 0.4, 0.8, 0.0, 0.0], s_out=[0.2, 0.4]).position
                ),
                target_s=[0.2, 0.4],
                throw=False,
            ),
        )
    )
    t("inverse_statics_path")(
        lambda d: (
            sr.inverse_statics_path,
            dict(
                robot=_niti(),
                targets=[[0.03388176, 0.03906025, 0.3958294], [0.03488176, 0.03906025, 0.3958]],
                target_rotations=None,
                weights=[1.0] * 6,
                tension_bounds=(0.0, 10.0),
                pressure_bounds=(0.0, None),
                warm_start=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
                throw=False,
                tolerance=1e-9,
                max_iterations=60,
            ),
        )
    )
    t("inverse_statics(starts)")(
        lambda d: (
            sr.inverse_statics,
            dict(
                robot=_niti(),
                target_position=[0.03388176, 0.03906025, 0.3958294],
                starts=[[1.0, 0.0, 0.0, 0.0, 0.5, 0.0]],
                throw=False,
            ),
        )
    )
    t("inverse_statics_path(starts)")(
        lambda d: (
            sr.inverse_statics_path,
            dict(
                robot=_niti(),
                targets=[[0.03388176, 0.03906025, 0.3958294]],
                starts=2,
                throw=False,
            ),
        )
    )
    t("solve_statics(chambers)")(
        lambda d: (
            sr.solve_statics,
            dict(
                rod=sr.Rod(0.2, sr.CircularSection(0.01), sr.LinearElastic(1e6, 0.45)),
                tendons=[],
                loads=None,
                chambers=[sr.Chamber(2e3, 1e-5, (0.004, 0.0))],
            ),
        )
    )
    t("compliance")(lambda d: (sr.compliance, dict(solution=_solution())))
    t("compliance(pcc)")(
        lambda d: (
            sr.compliance,
            dict(
                solution=_pcc_solution(),
                rod=sr.Rod(0.4, sr.CircularSection(0.7e-3), sr.LinearElastic(54e9, 0.3)),
                panels=8,
            ),
        )
    )
    t("tangent_compliance")(
        lambda d: (
            sr.tangent_compliance,
            dict(solution=_solution(), tendons="length", held=[0], node=10, direction=1),
        )
    )
    t("eigenscrews")(lambda d: (sr.eigenscrews, dict(matrix=_spd(), kind="stiffness")))
    t("workspace_map")(
        lambda d: (
            sr.workspace_map,
            dict(
                rod=_rod(),
                tendons=_tendons(),
                tensions=np.array([[0.1, 0.0], [0.2, 0.1], [0.3, 0.2]]),
                loads=None,
                chunk=2,
                block=2,
                progress=False,
                tangent="tension",
            ),
        )
    )
    t("tension_grid")(
        lambda d: (
            sr.tension_grid,
            dict(n_tendons=3, axes={0: np.array([0.0, 1.0, 2.0]), 2: np.array([0.0, 1.0])}),
        )
    )
    # design sweeps
    t("sweep")(
        lambda d: (
            sr.sweep,
            dict(
                robot=_niti(),
                actuation={"tendons[0].tension": [0.0, 1.0]},
                design={"rod.section.radius": [7e-4, 8e-4]},
                outputs=["tip_pose", "translational_compliance"],
                arc_lengths=None,
                arm_index=[1.0],
                scheduler=None,
                chunk=8,
                block=4,
                progress=False,
            ),
        )
    )
    t("sweep(arc_lengths)")(
        lambda d: (
            sr.sweep,
            dict(
                robot=_chambered(),
                actuation=sr.samples({"chambers[0].pressure": [0.0, 2e3, 4e3]}),
                outputs=["backbone", "gamma_c"],
                arc_lengths=[0.1, 0.2],
            ),
        )
    )
    t("samples")(lambda d: (sr.samples, dict(table={"tendons[0].tension": [0.0, 1.0]})))
    t("SampleTable")(lambda d: (sr.SampleTable, dict(columns={"rod.length": [0.2, 0.3]})))
    t("design_summary")(
        lambda d: (
            sr.design_summary,
            dict(ds=_sweep_ds(), over=None, voxel=0.01, axis=(0.0, 0.0, 1.0), origin=(0, 0, 0)),
        )
    )
    t("Pareto")(
        lambda d: (
            sr.Pareto,
            dict(
                a=np.array([1.0, 2.0, 3.0]),
                b=np.array([3.0, 1.0, 2.0]),
                better=("min", "max"),
                names=("x", "y"),
            ),
        )
    )
    t("Pareto.table")(lambda d: (sr.Pareto(np.array([1.0, 2.0]), np.array([2.0, 1.0])).table, {}))
    t("Robot")(
        lambda d: (
            sr.Robot,
            dict(
                rod=_rod(),
                tendons=_tendons(),
                chambers=[],
                loads=_loads(),
                solver={"steps": 40},
                name="r",
                description="d",
                obstacles=[],
                tip_constraint=None,
            ),
        )
    )
    t("Robot(source)")(
        lambda d: (
            sr.Robot,
            dict(
                rod=_niti().rod,
                tendons=_niti().tendons,
                solver=_niti().solver,
                source=_niti().source,
            ),
        )
    )
    t("Robot.from_spec")(
        lambda d: (sr.Robot.from_spec, dict(spec=_niti().spec, name="r", source="file.toml"))
    )
    t("Robot.to_toml")(lambda d: (_niti().to_toml, {}))
    t("PlanarCableArm.published_arm")(lambda d: (sr.PlanarCableArm.published_arm, {}))
    t("PlanarCableArm.seed_arm")(lambda d: (sr.PlanarCableArm.seed_arm, {}))
    t("TensileCurve.initial_slope")(lambda d: (sr.TensileCurve(*_curve_data()).initial_slope, {}))
    t("Robot.from_dict")(lambda d: (sr.Robot.from_dict, dict(data=_robot_dict(), name="r")))
    t("Robot.from_toml")(lambda d: (sr.Robot.from_toml, dict(text=_TOML, name="r")))
    t("Robot.solve")(lambda d: (_niti().solve, dict(tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0])))
    t("Robot.solve(pressures)")(lambda d: (_chambered().solve, dict(pressures=[3e3])))
    t("Robot.solve(displacements)")(
        lambda d: (
            _niti().solve,
            dict(
                tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
                displacements=[None, 0.0, None, None, None, -0.001],
                tendon_stiffness=1e5,
            ),
        )
    )
    t("Robot.with_tensions")(
        lambda d: (_niti().with_tensions, dict(tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0]))
    )
    t("Robot.with_disk_guides")(
        lambda d: (_niti().with_disk_guides, dict(spacing=0.02, friction=0.1, tendons=[0, 2]))
    )
    t("Robot.with_pressures")(lambda d: (_chambered().with_pressures, dict(pressures=[3e3])))
    t("Robot.parameter")(lambda d: (_niti().parameter, dict(path="tendons[0].tension")))
    t("Robot.with_parameters")(
        lambda d: (_niti().with_parameters, dict(values={"tendons[0].tension": 1.0}))
    )
    t("Robot.write_toml")(
        lambda d: (_niti().write_toml, dict(path=str(d / "robot.toml"), overwrite=True))
    )
    t("load_robot")(lambda d: (sr.load_robot, dict(path=str(sr.examples.path("niti_two_segment")))))
    t("examples.path")(lambda d: (sr.examples.path, dict(name="niti_two_segment")))
    t("compare_models")(
        lambda d: (
            sr.compare_models,
            dict(robot=_niti(), tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0], repeats=1),
        )
    )
    t("ModelComparison.table")(lambda d: (sr.compare_models(_niti(), repeats=1).table, {}))
    # calibration
    t("StaticsSolution.sensitivities")(
        lambda d: (
            _niti().solve().sensitivities,
            dict(parameters=["stiffness_scale", "tension[0]"], nodes=[0, 10]),
        )
    )
    t("PlanarCableArm.sensitivities")(
        lambda d: (sr.PlanarCableArm.published_arm().sensitivities, dict(tension=1.0, s=[0.0, 0.1]))
    )
    t("calibrate")(
        lambda d: (
            sr.calibrate,
            dict(
                robot=sr.PlanarCableArm.published_arm(),
                measurements=_planar_shapes(),
                parameters=["youngs_modulus", "offset_ratio"],
                bounds={"youngs_modulus": (1e4, 1e6)},
                metric="arm-index",
                actuations=None,
                initial={"youngs_modulus": 1e5},
                loss="linear",
                max_evaluations=50,
                condition_limit=1e8,
                starts=2,
            ),
        )
    )
    t("calibrate(nearest)")(
        lambda d: (
            sr.calibrate,
            dict(
                robot=sr.PlanarCableArm.published_arm(),
                measurements=[p for _, p in _planar_shapes()],
                parameters=["E"],
                metric="nearest",
                actuations=[0.5, 1.0],
            ),
        )
    )
    t("Calibration.interval")(
        lambda d: (
            sr.calibrate(sr.PlanarCableArm.published_arm(), _planar_shapes(), ["E", "a"]).interval,
            dict(level=0.9),
        )
    )
    # backbones from photographs
    t("extract_backbone")(
        lambda d: (
            sr.extract_backbone,
            dict(
                image=_photo(),
                scale=1e-3,
                base=tuple(_backbone().pixels[0]),
                direction=tuple(_backbone().direction),
                mask=None,
                polarity="bright",
                n_points=50,
                knot_spacing=12.0,
                min_area=30,
            ),
        )
    )
    t("extract_backbone(mask)")(
        lambda d: (sr.extract_backbone, dict(image=_photo(), mask=_photo_mask()))
    )
    t("Backbone.at_arm_index")(lambda d: (_backbone().at_arm_index, dict(u=[0.0, 0.5, 1.0])))
    t("Backbone.resample")(lambda d: (_backbone().resample, dict(n=20)))
    t("Backbone.to_dict")(lambda d: (_backbone().to_dict, {}))
    t("Backbone.to_csv")(
        lambda d: (_backbone().to_csv, dict(path=str(d / "backbone-out.csv"), overwrite=True))
    )
    t("Backbone.read_csv")(lambda d: (sr.Backbone.read_csv, dict(path=_backbone_csv(d))))
    t("BackboneQuality.to_dict")(lambda d: (_backbone().quality.to_dict, {}))
    # softrod.pcc
    t("pcc.Robot")(
        lambda d: (
            pcc.Robot,
            dict(
                rest_lengths=[0.2, 0.2],
                bending_stiffness=[1e-2, 1e-2],
                axial_stiffness=[80.0, 80.0],
            ),
        )
    )
    t("pcc.Robot.solid_circle")(
        lambda d: (
            pcc.Robot.solid_circle,
            dict(rest_lengths=[0.2, 0.2], radius=0.7e-3, youngs_modulus=54e9, extensible=True),
        )
    )
    t("pcc.Robot.with_tendons")(
        lambda d: (
            pcc.Robot.solid_circle([0.2, 0.2], 7e-4, 54e9).with_tendons,
            dict(segment=0, distances=[0.01] * 3, angles=ANGLES),
        )
    )
    t("pcc.Robot.with_chambers")(
        lambda d: (
            pcc.Robot.solid_circle([0.2], 0.01, 1e6).with_chambers,
            dict(segment=0, areas=[1e-5], distances=[0.004], angles=[0.0]),
        )
    )
    t("pcc.solve")(
        lambda d: (
            pcc.solve,
            dict(
                robot=_pcc_robot(),
                tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
                pressures=None,
                tip_force=(0.0, -0.01, 0.0),
                tip_moment=(0.0, 0.0, 0.0),
                n_points=50,
                tolerance=1e-12,
                max_iterations=50,
                continuation=True,
                max_load_steps=64,
                warm_start=None,
                throw=True,
            ),
        )
    )
    t("pcc.inverse_statics")(
        lambda d: (
            pcc.inverse_statics,
            dict(
                robot=_pcc_robot(),
                target_position=np.asarray(_pcc_solution().tip_pose)[:3, 3] + [1e-3, 0.0, 0.0],
                target_rotation=None,
                weights=[1.0] * 6,
                tension_bounds=(0.0, 10.0),
                pressure_bounds=(0.0, None),
                tip_force=(0.0, -0.01, 0.0),
                tip_moment=(0.0, 0.0, 0.0),
                warm_start=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0],
                throw=False,
                tolerance=1e-9,
                max_iterations=60,
            ),
        )
    )
    t("pcc.inverse_statics(starts)")(
        lambda d: (
            pcc.inverse_statics,
            dict(
                robot=_pcc_robot(),
                target_position=np.asarray(_pcc_solution().tip_pose)[:3, 3] + [1e-3, 0.0, 0.0],
                starts=3,
                throw=False,
            ),
        )
    )
    t("pcc.solve(s)")(
        lambda d: (
            pcc.solve,
            dict(robot=_pcc_robot(), tensions=[1.0, 0.0, 0.0, 0.0, 0.5, 0.0], s=[0.0, 0.1, 0.3]),
        )
    )
    t("pcc.solve(chambers)")(
        lambda d: (
            pcc.solve,
            dict(
                robot=pcc.Robot.solid_circle([0.2], 0.01, 1e6).with_chambers(
                    0, [1e-5], [0.004], [0.0]
                ),
                tensions=[],
                pressures=[2e3],
                warm_start=[[0.0, 0.0, 0.2]],
            ),
        )
    )
    t("pcc.Solution.frames_at")(lambda d: (_pcc_solution().frames_at, dict(s=[0.0, 0.1, 0.3])))
    arc = dict(curvature=5.0, plane_angle=0.3, length=0.2)
    t("pcc.arc_pose")(lambda d: (pcc.arc_pose, dict(arc)))
    t("pcc.arc_poses")(
        lambda d: (
            pcc.arc_poses,
            dict(curvature=[5.0, 0.0], plane_angle=[0.3, 1.0], length=[0.2, 0.1]),
        )
    )
    t("pcc.arc_frames")(lambda d: (pcc.arc_frames, dict(arc, s=[0.0, 0.1, 0.2])))
    t("pcc.arc_jacobian")(
        lambda d: (pcc.arc_jacobian, dict(arc, frame="spatial", coordinates="arc"))
    )
    seg = [[5.0, 0.3, 0.2], [3.0, 1.0, 0.15]]
    t("pcc.chain_pose")(lambda d: (pcc.chain_pose, dict(segments=seg)))
    t("pcc.chain_frames")(lambda d: (pcc.chain_frames, dict(segments=seg, s=[0.0, 0.1, 0.3])))
    t("pcc.chain_jacobian")(
        lambda d: (
            pcc.chain_jacobian,
            dict(segments=seg, frame="body", coordinates="curvature_vector"),
        )
    )
    t("pcc.arc_from_tip")(lambda d: (pcc.arc_from_tip, dict(position=[0.05, 0.02, 0.15])))
    t("pcc.arc_from_tip_with_length")(
        lambda d: (pcc.arc_from_tip_with_length, dict(position=[0.05, 0.02, 0.15], length=0.2))
    )
    geo = dict(distances=[0.01] * 3, angles=ANGLES)
    t("pcc.tendon_displacements")(
        lambda d: (pcc.tendon_displacements, dict(arc=[5.0, 0.3, 0.2], **geo, rest_length=0.2))
    )
    t("pcc.tendon_displacement_jacobian")(
        lambda d: (
            pcc.tendon_displacement_jacobian,
            dict(arc=[5.0, 0.3, 0.2], **geo, coordinates="arc"),
        )
    )
    t("pcc.arc_from_tendon_displacements")(
        lambda d: (
            pcc.arc_from_tendon_displacements,
            dict(displacements=[-0.001, 0.0005, 0.0005], **geo, rest_length=0.2, extensible=True),
        )
    )
    t("pcc.tendon_displacement_misfit")(
        lambda d: (
            pcc.tendon_displacement_misfit,
            dict(displacements=[-0.001, 0.0005, 0.0006], **geo, rest_length=0.2, extensible=False),
        )
    )
    t("pcc.arc_from_tendon_displacements_jacobian")(
        lambda d: (
            pcc.arc_from_tendon_displacements_jacobian,
            dict(
                displacements=[-0.001, 0.0005, 0.0005],
                **geo,
                rest_length=0.2,
                extensible=True,
                coordinates="arc",
            ),
        )
    )
    t("pcc.arc_from_tendon_tensions")(
        lambda d: (
            pcc.arc_from_tendon_tensions,
            dict(
                tensions=[1.0, 0.0, 0.0],
                **geo,
                rest_length=0.2,
                bending_stiffness=1e-2,
                axial_stiffness=80.0,
            ),
        )
    )
    t("pcc.arc_from_tendon_tensions_jacobian")(
        lambda d: (
            pcc.arc_from_tendon_tensions_jacobian,
            dict(
                tensions=[1.0, 0.0, 0.0],
                **geo,
                rest_length=0.2,
                bending_stiffness=1e-2,
                axial_stiffness=80.0,
                coordinates="curvature_vector",
            ),
        )
    )
    t("pcc.arc_from_pressures")(
        lambda d: (
            pcc.arc_from_pressures,
            dict(
                pressures=[1e4, 0.0, 0.0],
                areas=[1e-5] * 3,
                distances=[0.003] * 3,
                angles=ANGLES,
                rest_length=0.2,
                bending_stiffness=1e-2,
                axial_stiffness=80.0,
            ),
        )
    )
    t("pcc.arc_from_pressures_jacobian")(
        lambda d: (
            pcc.arc_from_pressures_jacobian,
            dict(
                pressures=[1e4, 0.0, 0.0],
                areas=[1e-5] * 3,
                distances=[0.003] * 3,
                angles=ANGLES,
                rest_length=0.2,
                bending_stiffness=1e-2,
                axial_stiffness=None,
                coordinates="arc",
            ),
        )
    )
    t("compliance(s_out)")(lambda d: (sr.compliance, dict(solution=_solution(), s_out=[0.1, 0.2])))


def _photo() -> str:
    return str(_sr().examples.data_path("photos") / "cable-arm-2N.jpg")


_CACHE: dict = {}


def _backbone():
    if "backbone" not in _CACHE:
        _CACHE["backbone"] = _sr().extract_backbone(_photo(), scale=1e-3)
    return _CACHE["backbone"]


def _photo_mask():
    if "mask" not in _CACHE:
        from softrod import vision

        img = np.asarray(vision.read_image(_photo()), dtype=float)
        grey = img.mean(axis=2) if img.ndim == 3 else img
        _CACHE["mask"] = grey > 0.5 * (grey.min() + grey.max())
    return _CACHE["mask"]


def _mesh_file(d: Path, mesh: dict) -> str:
    """A small OBJ file of ``mesh`` in ``d`` (what ``Mesh.from_file`` reads)."""
    path = d / "tetra.obj"
    lines = [f"v {x} {y} {z}" for x, y, z in mesh["vertices"]]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh["faces"]]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def _backbone_csv(d: Path) -> str:
    path = d / "backbone-in.csv"
    if not path.exists():
        _backbone().to_csv(path, overwrite=True)
    return str(path)


def _spd():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(6, 6))
    return a @ a.T + 6 * np.eye(6)


def _solve_function_section(function):
    """Composite target: a rod whose section is ``FunctionSection(function)``, solved."""
    sr = _sr()
    rod = sr.Rod(0.3, sr.FunctionSection(function), sr.LinearElastic(5e7, 0.3))
    return sr.solve_statics(rod, _tendons(), _loads())


def _solve_rest_curvature(rest_curvature):
    """Composite target: a rod with a rest-curvature callback, solved."""
    sr = _sr()
    rod = sr.Rod(
        0.3, sr.CircularSection(0.002), sr.LinearElastic(5e7, 0.3), rest_curvature=rest_curvature
    )
    return sr.solve_statics(rod, _tendons(), _loads())


def _solve_function_tendon(offset, derivative):
    """Composite target: a tendon routed by callbacks, solved."""
    sr = _sr()
    return sr.solve_statics(_rod(), [sr.Tendon(offset, 0.5, derivative=derivative)], _loads())


def _solve_distributed(distributed_force, distributed_moment):
    """Composite target: distributed-load callbacks, solved."""
    sr = _sr()
    loads = sr.Loads(distributed_force=distributed_force, distributed_moment=distributed_moment)
    return sr.solve_statics(_rod(), [], loads)


# ----------------------------------------------------------------------------- bad values

SIZE_NAMES = {
    "n_points",
    "steps",
    "panels",
    "max_iterations",
    "max_load_steps",
    "max_steps",
    "chunk",
    "block",
    "n_index",
    "repeats",
    "terms",
    "node",
    "segment",
    "n_tendons",
}


def kind_of(name: str, value) -> str:
    """The kind of a baseline value, which selects its bad values."""
    if callable(value) and not isinstance(value, type):
        return "callable"
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int) or name in SIZE_NAMES:
        return "size"
    if isinstance(value, float):
        return "float"
    if isinstance(value, str):
        return "path" if name in ("path",) else "str"
    if isinstance(value, dict):
        return "dict"
    if value is None:
        return "none"
    if isinstance(value, np.ndarray) or (
        isinstance(value, (list, tuple)) and value and all(_is_num_tree(v) for v in value)
    ):
        try:
            np.asarray(value, dtype=float)
        except ValueError:  # ragged, e.g. a (position, rotation) pair
            return "object"
        return "array"
    if isinstance(value, (list, tuple)):
        return "objects"
    return "object"


def _is_num_tree(v) -> bool:
    if isinstance(v, (list, tuple, np.ndarray)):
        return all(_is_num_tree(x) for x in v)
    return isinstance(v, (int, float, np.floating)) and not isinstance(v, bool)


COMMON = ["none", "string", "object"]
BAD = {
    "float": ["nan", "inf", "-inf", "negative", "zero", "huge", "tiny", "list", *COMMON, "bool"],
    "size": ["size-huge", "int-overflow", "negative-int", "zero-int", "float-size", "nan", *COMMON],
    "bool": ["string", "none", "int2", "nan"],
    "str": ["bogus", "empty-string", "none", "number", "object"],
    "path": ["missing-file", "directory", "empty-string", "none", "number"],
    "dict": ["empty-dict", "bad-key", "none", "string", "number"],
    "none": ["nan", "inf", "string", "object", "empty-list", "nan-list6", "huge"],
    "array": [
        "elem-nan",
        "elem-inf",
        "elem--inf",
        "elem-huge",
        "elem-negative",
        "empty-list",
        "drop-one",
        "add-one",
        "nest",
        "scalar",
        *COMMON,
        "strings",
    ],
    "objects": ["empty-list", "none", "string", "list-none", "list-number", "list-object"],
    "object": ["none", "string", "number", "object", "other-object"],
    "callable": ["cb-nan", "cb-raises", "cb-short", "cb-none", "not-callable", "none"],
}


def bad_value(label: str, base, d: Path):
    """The bad value named ``label`` for a parameter whose valid value is ``base``."""
    nan, inf = math.nan, math.inf
    simple = {
        "nan": nan,
        "inf": inf,
        "-inf": -inf,
        "zero": 0.0,
        "huge": 1e308,
        "tiny": 1e-308,
        "list": [1.0, 2.0],
        "none": None,
        "string": "abc",
        "object": object(),
        "bool": True,
        "size-huge": 2**40,
        "int-overflow": 2**70,
        "negative-int": -1,
        "zero-int": 0,
        "float-size": 2.5,
        "int2": 2,
        "bogus": "bogus",
        "empty-string": "",
        "number": 1.5,
        "missing-file": str(d / "missing.toml"),
        "directory": str(d),
        "empty-dict": {},
        "bad-key": {"bogus": 1},
        "empty-list": [],
        "nan-list6": [nan] * 6,
        "scalar": 1.0,
        "strings": ["a", "b"],
        "list-none": [None],
        "list-number": [1.0],
        "list-object": [object()],
        "not-callable": 1.0,
    }
    if label in simple:
        return simple[label]
    if label == "negative":
        return -abs(base) if base else -1.0
    if label == "other-object":
        return _sr().Tendon((0.001, 0.0), 0.1)
    if label.startswith("elem-"):
        arr = np.array(base, dtype=float)
        val = {"nan": nan, "inf": inf, "-inf": -inf, "huge": 1e308}.get(label[5:])
        flat = arr.reshape(-1)
        flat[0] = -abs(flat[0]) - 1.0 if val is None else val
        return _like(base, flat.reshape(arr.shape))
    if label == "drop-one":
        return _like(base, np.array(base, dtype=float)[:-1])
    if label == "add-one":
        arr = np.array(base, dtype=float)
        return _like(base, np.concatenate([arr, arr[-1:]]))
    if label == "nest":
        arr = np.array(base, dtype=float)
        return _like(base, arr[None] if arr.ndim < 2 else arr.reshape(-1))
    if label.startswith("cb-"):
        n = len(_tupleize(base(0.1)))
        return {
            "cb-nan": lambda s: (nan,) * n,
            "cb-raises": _raiser,
            "cb-short": lambda s: (1e-5,) * (n - 1),
            "cb-none": lambda s: None,
        }[label]
    raise KeyError(label)


def _raiser(*args):
    raise Sentinel("raised by the callback")


def _tupleize(v):
    return tuple(v) if isinstance(v, (list, tuple, np.ndarray)) else (v,)


def _like(base, arr: np.ndarray):
    if isinstance(base, np.ndarray):
        return arr
    return arr.tolist() if isinstance(base, list) else tuple(arr.tolist())


# ----------------------------------------------------------------------------- calls


@dataclass(frozen=True)
class Call:
    index: int
    target: str
    parameter: str
    value: str


def calls() -> list[Call]:
    """Every (target, parameter, bad value), numbered; the baseline of each target is call
    ``parameter == ""``."""
    if not TARGETS:
        _define_targets()
    out: list[Call] = []
    d = Path(tempfile.gettempdir())
    for name, build in TARGETS.items():
        _, kwargs = build(d)
        out.append(Call(len(out), name, "", ""))
        for p, v in kwargs.items():
            for label in BAD[kind_of(p, v)]:
                out.append(Call(len(out), name, p, label))
    return out


#: Values always in the sample: the sizes that abort or hang, and raising callbacks.
ALWAYS = ("size-huge", "int-overflow", "cb-raises")


def sample(all_calls: list[Call], n: int, seed: int = 10) -> list[Call]:
    """A reproducible sample: every baseline, every call with a value in ``ALWAYS``, and
    ``n`` other calls drawn at random."""
    base = [c for c in all_calls if not c.parameter or c.value in ALWAYS]
    rest = [c for c in all_calls if c.parameter and c.value not in ALWAYS]
    rng = random.Random(seed)
    picked = rng.sample(rest, min(n, len(rest)))
    return sorted(base + picked, key=lambda c: c.index)


# ----------------------------------------------------------------------------- worker side


def nonfinite_paths(obj, path: str = "", depth: int = 0, seen=None) -> set[str]:
    """Attribute paths of every non-finite number reachable from a result."""
    seen = set() if seen is None else seen
    out: set[str] = set()
    if depth > 3 or id(obj) in seen:
        return out
    if isinstance(obj, bool) or obj is None or isinstance(obj, (str, bytes)):
        return out
    if isinstance(obj, (int, float, np.number)):
        return {path or "."} if not math.isfinite(float(obj)) else out
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc" and not np.all(np.isfinite(obj)):
            return {path or "."}
        return out
    seen.add(id(obj))
    if isinstance(obj, dict):
        for k, v in obj.items():
            out |= nonfinite_paths(v, f"{path}[{k}]", depth + 1, seen)
        return out
    if isinstance(obj, (list, tuple)):
        for i, v in enumerate(obj[:50]):
            out |= nonfinite_paths(v, f"{path}[{i}]", depth + 1, seen)
        return out
    module = type(obj).__module__ or ""
    if not (module.startswith("softrod") or module.startswith("_core")):
        return out
    if is_dataclass(obj):
        items = [(f.name, getattr(obj, f.name)) for f in fields(obj)] if depth < 2 else []
    else:
        items = []
        for name in dir(obj):
            if name.startswith("_"):
                continue
            try:
                v = getattr(obj, name)
            except Exception:
                continue
            if callable(v):
                continue
            items.append((name, v))
    for k, v in items:
        out |= nonfinite_paths(v, f"{path}.{k}", depth + 1, seen)
    return out


def documented_nonfinite(result, kwargs: dict) -> set[str]:
    """Non-finite fields the docs promise: stiffness at the clamp (the compliance is zero
    there; only at the nodes with ``s = 0``), and the measures of failed workspace-map samples
    (``converged`` False) or of the tangent compliance when it was not requested."""
    name = type(result).__name__
    out: set[str] = set()
    if name == "TangentCompliance" and float(result.s) == 0.0:
        out |= {".condition", ".stiffness_body", ".stiffness_world"}
    if name == "Compliance":
        at_clamp = np.asarray(result.s) == 0.0
        if all(
            np.all(np.isfinite(np.asarray(getattr(result, f))[~at_clamp]))
            for f in ("condition", "stiffness_body", "stiffness_world")
        ):
            out |= {".condition", ".stiffness_body", ".stiffness_world"}
    if name == "WorkspaceMap":
        failed = ~np.asarray(result.converged, dtype=bool)
        for f in fields(result):
            v = np.asarray(getattr(result, f.name))
            if v.dtype.kind == "f" and np.all(np.isfinite(v[~failed])):
                out.add(f".{f.name}")
        if kwargs.get("tangent") is None:
            out.add(".tangent_max_translational_compliance")
    return out


def names_parameter(exc: BaseException, param: str) -> bool:
    """Whether an error names the parameter: its ``parameter`` or its message.

    Short names (``s``, ``a``) must appear quoted or followed by ``=`` or ``[``; a plural
    parameter named in the singular for one element (``tensions`` as `` `tension` ``) counts.
    """
    names = [param]
    if param.endswith("s") and len(param) > 4:
        names.append(param[:-1])
    got = getattr(exc, "parameter", None)
    msg = str(exc)
    for name in names:
        if isinstance(got, str) and re.match(rf"(\w+\.)*{re.escape(name)}(\W|$)", got):
            return True
        if len(name) <= 2:
            pat = rf"[`'\"]{re.escape(name)}[`'\"\[]|\b{re.escape(name)}\s*(=|\[)"
        else:
            pat = rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])"
        if re.search(pat, msg):
            return True
    return False


def classify(fn, kwargs, param: str, value_label: str, baseline_nonfinite: set[str]) -> dict:
    try:
        result = fn(**kwargs)
    except BaseException as exc:
        name = type(exc).__name__
        first = str(exc).splitlines()[0][:300] if str(exc) else ""
        detail = f"{name}: {first}"
        if name == "PanicException":
            return {"outcome": "panic", "detail": detail}
        if isinstance(exc, (KeyboardInterrupt, SystemExit)):
            return {"outcome": "unnamed-error", "detail": detail}
        if not param:
            return {"outcome": "baseline-error", "detail": detail}
        if value_label == "cb-raises":
            # The callback's own exception must reach the caller: itself, as the cause, or
            # quoted in the message.
            chain, e = [], exc
            while e is not None and len(chain) < 10:
                chain.append(e)
                e = e.__cause__ or e.__context__
            ok = any(isinstance(e, Sentinel) for e in chain) or "Sentinel" in str(exc)
            return {"outcome": "named-error" if ok else "unnamed-error", "detail": detail}
        named = any(t in [c.__name__ for c in type(exc).__mro__] for t in ERROR_TYPES)
        if named and names_parameter(exc, param):
            return {"outcome": "named-error", "detail": detail}
        path = kwargs.get(param)
        if isinstance(exc, OSError) and isinstance(path, str) and exc.filename == path:
            # The idiomatic error for a file argument names the file.
            return {"outcome": "named-error", "detail": detail}
        return {"outcome": "unnamed-error", "detail": detail}
    bad = sorted(
        nonfinite_paths(result) - baseline_nonfinite - documented_nonfinite(result, kwargs)
    )
    if bad and getattr(result, "converged", True) is False:
        # A result that says it did not converge (``throw=False``) is not silent.
        return {"outcome": "ok-not-converged", "detail": ", ".join(bad[:6])}
    if bad:
        return {"outcome": "ok-nonfinite", "detail": ", ".join(bad[:6])}
    if value_label == "cb-raises":
        return {"outcome": "ok-swallowed-callback-error", "detail": ""}
    return {"outcome": "ok-finite", "detail": ""}


def worker_main() -> None:
    """Runs the calls whose indices arrive on stdin; one JSON line per event on fd 3."""
    import resource
    import warnings

    warnings.simplefilter("ignore")
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    proto = os.fdopen(os.dup(1), "w", buffering=1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    indices = json.loads(sys.stdin.readline())
    all_calls = calls()
    d = Path(os.getcwd())
    _files(d)
    base_nonfinite: dict[str, set[str]] = {}
    for i in indices:
        c = all_calls[i]
        proto.write(json.dumps({"start": i}) + "\n")
        proto.flush()
        try:
            fn, kwargs = TARGETS[c.target](d)
            if c.target not in base_nonfinite:
                try:
                    base_nonfinite[c.target] = nonfinite_paths(fn(**kwargs))
                except BaseException:
                    base_nonfinite[c.target] = set()
                fn, kwargs = TARGETS[c.target](d)
            if c.parameter:
                kwargs[c.parameter] = bad_value(c.value, kwargs[c.parameter], d)
            res = classify(fn, kwargs, c.parameter, c.value, base_nonfinite[c.target])
        except BaseException as exc:
            res = {"outcome": "harness-error", "detail": f"{type(exc).__name__}: {exc}"}
        proto.write(json.dumps({"done": i, **res}) + "\n")
        proto.flush()


# ----------------------------------------------------------------------------- parent side


@dataclass
class Outcome:
    call: Call
    outcome: str
    detail: str


def _batch(indices: list[int], all_calls: list[Call], timeout: float) -> list[Outcome]:
    out: list[Outcome] = []
    remaining = list(indices)
    code = (
        f"import sys; sys.path.insert(0, {str(TESTS)!r}); "
        "from harness.fuzz import worker_main; worker_main()"
    )
    env = {
        **os.environ,
        "RAYON_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "OMP_NUM_THREADS": "1",
        "MPLBACKEND": "Agg",
        "PYTHONFAULTHANDLER": "0",
    }
    while remaining:
        with tempfile.TemporaryDirectory() as tmp:
            proc = subprocess.Popen(
                [sys.executable, "-c", code],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                cwd=tmp,
                env=env,
                text=True,
            )
            proc.stdin.write(json.dumps(remaining) + "\n")
            proc.stdin.flush()
            lines: queue.Queue = queue.Queue()

            def pump(stream=proc.stdout, lines=lines):
                for line in stream:
                    lines.put(line)
                lines.put(None)

            threading.Thread(target=pump, daemon=True).start()
            current = None
            done: set[int] = set()
            while True:
                try:
                    line = lines.get(timeout=timeout if current is not None else 120)
                except queue.Empty:
                    proc.kill()
                    proc.wait()
                    if current is not None:
                        out.append(Outcome(all_calls[current], "hang", f"> {timeout:g} s"))
                        done.add(current)
                    break
                if line is None:
                    proc.wait()
                    if current is not None:
                        rc = proc.returncode
                        what = f"signal {-rc}" if rc < 0 else f"exit {rc}"
                        out.append(Outcome(all_calls[current], "abort", what))
                        done.add(current)
                    break
                msg = json.loads(line)
                if "start" in msg:
                    current = msg["start"]
                else:
                    out.append(Outcome(all_calls[msg["done"]], msg["outcome"], msg["detail"]))
                    done.add(msg["done"])
                    current = None
            proc.stdout.close()
            remaining = [i for i in remaining if i not in done]
            if remaining and current is None and not done:
                # The worker died before its first call: do not loop forever.
                for i in remaining:
                    out.append(Outcome(all_calls[i], "harness-error", "worker did not start"))
                remaining = []
    return out


def run(
    selected: list[Call], *, workers: int = 2, batch: int = 150, timeout: float = 20.0
) -> list[Outcome]:
    """Runs the calls in ``workers`` parallel subprocess pools; outcomes in call order."""
    all_calls = calls()
    idx = [c.index for c in selected]
    chunks = [idx[i : i + batch] for i in range(0, len(idx), batch)]
    with ThreadPoolExecutor(workers) as ex:
        parts = list(ex.map(lambda ch: _batch(ch, all_calls, timeout), chunks))
    return sorted((o for p in parts for o in p), key=lambda o: o.call.index)


DEFECTS = ("ok-nonfinite", "panic", "abort", "hang", "ok-swallowed-callback-error")


def summary(outcomes: list[Outcome]) -> dict:
    """Counts per outcome, the error-naming rate and the defects."""
    fuzzed = [o for o in outcomes if o.call.parameter]
    counts = Counter(o.outcome for o in fuzzed)
    named, unnamed = counts["named-error"], counts["unnamed-error"]
    accepted_nonfinite = sum(
        1
        for o in fuzzed
        if o.outcome == "ok-finite"
        and o.call.value
        in ("nan", "inf", "-inf", "elem-nan", "elem-inf", "elem--inf", "nan-list6", "cb-nan")
    )
    return {
        "calls": len(fuzzed),
        "targets": len({o.call.target for o in outcomes}),
        "counts": counts,
        "named_rate": named / (named + unnamed) if named + unnamed else 1.0,
        "accepted_nonfinite": accepted_nonfinite,
        "baseline_failures": [
            o
            for o in outcomes
            if not o.call.parameter and o.outcome not in ("ok-finite", "ok-nonfinite")
        ],
        "defects": [o for o in fuzzed if o.outcome in DEFECTS],
        "unnamed": [o for o in fuzzed if o.outcome == "unnamed-error"],
    }


# ----------------------------------------------------------------------------- coverage

#: Public classes users do not construct (results, exceptions) and result records: their
#: constructors are not fuzzed (their public methods are).
NOT_CONSTRUCTED = {
    "Backbone",
    "Calibration",
    "IdentifiabilityWarning",
    "PoorFitWarning",
    "BackboneQuality",
    "BackboneDistance",
    "Compliance",
    "ConvergenceError",
    "Eigenscrews",
    "InverseSolution",
    "InversePath",
    "ModelComparison",
    "ModelResult",
    "ParameterError",
    "PlanarBatch",
    "PlanarSolution",
    "Section",
    "Silicone",
    "StabilityError",
    "StabilityWarning",
    "StaticsSolution",
    "TangentCompliance",
    "TargetUnreachableError",
    "UniaxialFit",
    "UniaxialLaw",
    "WorkspaceMap",
    "Solution",
    "PccSolution",
}


def _public_callables():
    """(owner class or None, name, callable) for every public callable of the two modules."""
    import inspect

    import softrod
    from softrod import pcc

    out = []
    for mod in (softrod, pcc):
        for name in mod.__all__:
            obj = getattr(mod, name)
            if inspect.ismodule(obj) or not callable(obj):
                continue
            if inspect.isclass(obj):
                if obj.__name__ not in NOT_CONSTRUCTED and name not in NOT_CONSTRUCTED:
                    out.append((obj, "__init__", obj))
                for m, v in vars(obj).items():
                    if m.startswith("_") or isinstance(v, property):
                        continue
                    attr = getattr(obj, m)
                    if callable(attr) and not inspect.isclass(attr):
                        out.append((obj, m, attr))
            else:
                out.append((None, obj.__qualname__, obj))
    out.append((None, "path", softrod.examples.path))
    return out


def _parameters(fn) -> set[str]:
    import inspect

    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return set()
    return {
        p.name
        for p in sig.parameters.values()
        if p.name not in ("self", "cls") and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)
    }


def coverage() -> list[str]:
    """Public callables, or parameters of them, that no target fuzzes."""
    import inspect

    if not TARGETS:
        _define_targets()
    d = Path(tempfile.gettempdir())
    covered: dict[tuple[str, str], set[str]] = {}
    for build in TARGETS.values():
        fn, kwargs = build(d)
        if inspect.isclass(fn):
            key = (fn.__name__, "__init__")
        else:
            owner = getattr(fn, "__self__", None)
            qual = fn.__qualname__
            if "." in qual:
                cls_name, method = qual.rsplit(".", 1)
            else:
                cls_name, method = "", qual
            if inspect.isclass(owner):
                cls_name = owner.__name__
            elif owner is not None and not inspect.ismodule(owner):
                cls_name = type(owner).__name__
            key = (cls_name, method)
        covered.setdefault(key, set()).update(kwargs)
    missing = []
    for owner, name, fn in _public_callables():
        if owner is None:
            keys = [("", name)]
        else:
            subclasses = {owner.__name__} | {c.__name__ for c in _all_subclasses(owner)}
            keys = [(c, name) for c in subclasses]
        got = [covered[k] for k in keys if k in covered]
        label = name if owner is None else f"{owner.__name__}.{name}"
        if not got:
            missing.append(label)
            continue
        params = _parameters(fn) - set().union(*got)
        if params:
            missing.append(f"{label}({', '.join(sorted(params))})")
    return missing


def _all_subclasses(cls):
    out = set()
    for c in cls.__subclasses__():
        out |= {c} | _all_subclasses(c)
    return out
