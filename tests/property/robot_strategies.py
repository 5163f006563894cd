"""Hypothesis strategies that generate robots, and plain descriptions that build them.

A :class:`RobotCase` is a plain, printable description (numbers only; callbacks are made from
coefficients when building), so that hypothesis shrinks and reports it, and so that the oracles
can transform it (move the base, scale every length) and read its loads without asking
softrod. :meth:`RobotCase.build` makes the softrod objects.

Sizing: every load is drawn as a dimensionless number ``c`` (a bending angle of about ``c`` rad)
times the base bending stiffness scale (``EI/L^2`` for forces, ``EI/L`` for moments, ``EI/(d L)``
for a tendon at offset ``d``, ...), with the total kept below about 2 rad, so that the solves
converge most of the time on physically sensible robots: stiffness from silicone (10 kPa) to
NiTi-like (1 GPa), lengths 5-50 cm, slender sections.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from harness.balance import ChamberSpec, LoadSpec, TendonSpec
from hypothesis import assume
from hypothesis import strategies as st

import softrod

Vec3 = tuple[float, float, float]


# ----------------------------------------------------------------------------- descriptions


@dataclass(frozen=True)
class SectionCase:
    """``circular`` (r0), ``tapered`` (r0 -> r1), ``tube`` (r0, inner ri) or ``table``
    (elliptical sections (a, b) at nodes s, linear in between)."""

    kind: str
    r0: float
    r1: float = 0.0
    ri: float = 0.0
    nodes: tuple[tuple[float, float, float], ...] = ()  # (s / L, a, b)

    def build(self, length: float):
        if self.kind == "circular":
            return softrod.CircularSection(self.r0)
        if self.kind == "tapered":
            return softrod.TaperedCircularSection(self.r0, self.r1)
        if self.kind == "tube":
            return softrod.TubeSection(self.r0, self.ri)
        s, area, ix, iy, j = [], [], [], [], []
        for x, a, b in self.nodes:
            s.append(x * length)
            area.append(math.pi * a * b)
            ix.append(math.pi * a * b**3 / 4)
            iy.append(math.pi * a**3 * b / 4)
            j.append(math.pi * a**3 * b**3 / (a * a + b * b))
        return softrod.TableSection(s, area, ix, iy, j)

    def radius(self, s: float, length: float) -> float:
        """Outer radius (m) at s (for tables, the smaller semi-axis interpolated)."""
        if self.kind == "tapered":
            return self.r0 + (self.r1 - self.r0) * s / length
        if self.kind == "table":
            xs = [n[0] * length for n in self.nodes]
            return float(np.interp(s, xs, [min(n[1], n[2]) for n in self.nodes]))
        return self.r0

    def area(self, s: float, length: float) -> float:
        """Area (m^2) at s, written from the geometry."""
        if self.kind == "tube":
            return math.pi * (self.r0**2 - self.ri**2)
        if self.kind == "table":
            xs = [n[0] * length for n in self.nodes]
            return float(np.interp(s, xs, [math.pi * n[1] * n[2] for n in self.nodes]))
        r = self.radius(s, length)
        return math.pi * r * r

    def min_radius(self, length: float) -> float:
        if self.kind == "table":
            return min(min(n[1], n[2]) for n in self.nodes)
        return min(self.r0, self.r1) if self.kind == "tapered" else self.r0

    def inertia0(self) -> float:
        """Smallest second moment of area at the base (m^4), for sizing."""
        if self.kind == "tube":
            return math.pi * (self.r0**4 - self.ri**4) / 4
        if self.kind == "table":
            _, a, b = self.nodes[0]
            return math.pi * a * b * min(a, b) ** 2 / 4
        return math.pi * self.r0**4 / 4

    def scaled(self, lam: float) -> SectionCase:
        return replace(
            self,
            r0=self.r0 * lam,
            r1=self.r1 * lam,
            ri=self.ri * lam,
            nodes=tuple((x, a * lam, b * lam) for x, a, b in self.nodes),
        )


@dataclass(frozen=True)
class MaterialCase:
    """``linear`` (E, nu), ``neo-hookean`` (mu), ``yeoh`` (c10, c20, c30) or ``silicone``
    (a library name and law)."""

    kind: str
    a: float = 0.0
    b: float = 0.0
    c: float = 0.0
    name: str = ""

    def build(self):
        if self.kind == "linear":
            return softrod.LinearElastic(self.a, self.b)
        if self.kind == "neo-hookean":
            return softrod.NeoHookean(self.a)
        if self.kind == "yeoh":
            return softrod.Yeoh(self.a, self.b, self.c)
        lib = softrod.silicone(self.name)
        return lib.yeoh if self.a else lib.neo_hookean

    def modulus(self) -> float:
        """Small-strain Young's modulus (Pa), for sizing."""
        if self.kind == "linear":
            return self.a
        if self.kind == "neo-hookean":
            return 3 * self.a
        if self.kind == "yeoh":
            return 6 * self.a
        return float(self.build().small_strain_modulus)


@dataclass(frozen=True)
class TendonCase:
    """``constant`` (x, y), ``radius`` (ratio, angle) or ``helical`` (radius, pitch, phase)."""

    routing: str
    p1: float
    p2: float
    p3: float
    tension: float
    end: float | None  # fraction of L

    def build(self, length: float):
        end = None if self.end is None else self.end * length
        if self.routing == "constant":
            return softrod.Tendon((self.p1, self.p2), self.tension, end)
        if self.routing == "radius":
            return softrod.Tendon.radius_proportional(self.p1, self.p2, self.tension, end)
        return softrod.Tendon.helical(self.p1, self.p2, self.tension, self.p3, end)

    def distance(self, section: SectionCase, length: float) -> float:
        if self.routing == "constant":
            return math.hypot(self.p1, self.p2)
        if self.routing == "radius":
            return self.p1 * section.min_radius(length)
        return self.p1

    def spec(self, section: SectionCase, length: float) -> TendonSpec:
        end = None if self.end is None else self.end * length
        if self.routing == "constant":
            r = np.array([self.p1, self.p2])
            return TendonSpec(lambda s: r, lambda s: np.zeros(2), self.tension, end)
        if self.routing == "radius":
            d = np.array([math.cos(self.p2), math.sin(self.p2)]) * self.p1
            if section.kind == "tapered":
                slope = (section.r1 - section.r0) / length
            else:
                slope = 0.0
            return TendonSpec(
                lambda s: d * section.radius(s, length),
                lambda s: d * slope,
                self.tension,
                end,
            )
        rho, pitch, phase = self.p1, self.p2, self.p3
        k = 2 * math.pi / pitch
        return TendonSpec(
            lambda s: rho * np.array([math.cos(phase + k * s), math.sin(phase + k * s)]),
            lambda s: rho * k * np.array([-math.sin(phase + k * s), math.cos(phase + k * s)]),
            self.tension,
            end,
        )

    def scaled(self, lam: float) -> TendonCase:
        if self.routing == "constant":
            return replace(self, p1=self.p1 * lam, p2=self.p2 * lam, tension=self.tension * lam**2)
        if self.routing == "radius":
            return replace(self, tension=self.tension * lam**2)
        return replace(self, p1=self.p1 * lam, p2=self.p2 * lam, tension=self.tension * lam**2)


@dataclass(frozen=True)
class ChamberCase:
    pressure: float
    radius: float
    x: float
    y: float
    start: float  # fraction of L
    end: float | None

    def build(self, length: float):
        end = None if self.end is None else self.end * length
        area = math.pi * self.radius**2
        return softrod.Chamber(self.pressure, area, (self.x, self.y), self.start * length, end)

    def spec(self, length: float) -> ChamberSpec:
        end = None if self.end is None else self.end * length
        area = math.pi * self.radius**2
        return ChamberSpec(
            np.array([self.x, self.y]), lambda s: area, self.pressure, self.start * length, end
        )

    def scaled(self, lam: float) -> ChamberCase:
        return replace(self, radius=self.radius * lam, x=self.x * lam, y=self.y * lam)


@dataclass(frozen=True)
class PointLoadCase:
    s: float  # fraction of L
    force: Vec3
    moment: Vec3
    frame: str


@dataclass(frozen=True)
class LoadsCase:
    tip_force: Vec3 = (0.0, 0.0, 0.0)
    tip_moment: Vec3 = (0.0, 0.0, 0.0)
    tip_frame: str = "world"
    point_loads: tuple[PointLoadCase, ...] = ()
    #: f(s) = f0 + f1 s (N/m, world), l(s) = l0 (N m/m, world)
    f0: Vec3 | None = None
    f1: Vec3 = (0.0, 0.0, 0.0)
    l0: Vec3 | None = None
    gravity: Vec3 | None = None

    def build(self, length: float, extra_tip: tuple[Vec3, Vec3] | None = None):
        pls = [
            softrod.PointLoad(p.s * length, p.force, p.moment, p.frame) for p in self.point_loads
        ]
        if extra_tip is not None:
            pls.append(softrod.PointLoad(length, extra_tip[0], extra_tip[1], "world"))
        kw = {}
        if self.f0 is not None:
            f0, f1 = np.array(self.f0), np.array(self.f1)
            if np.any(f1):
                kw["distributed_force"] = lambda s: tuple(f0 + f1 * s)
            else:
                kw["distributed_force"] = tuple(f0)
        if self.l0 is not None:
            kw["distributed_moment"] = self.l0
        return softrod.Loads(
            tip_force=self.tip_force,
            tip_moment=self.tip_moment,
            gravity=self.gravity,
            tip_frame=self.tip_frame,
            point_loads=pls,
            **kw,
        )

    def spec(self, length: float, mass_per_length) -> LoadSpec:
        f0 = None if self.f0 is None else np.array(self.f0)
        f1 = np.array(self.f1)
        return LoadSpec(
            tip_force=np.array(self.tip_force),
            tip_moment=np.array(self.tip_moment),
            tip_frame=self.tip_frame,
            point_loads=[
                (p.s * length, np.array(p.force), np.array(p.moment), p.frame)
                for p in self.point_loads
            ],
            distributed_force=None if f0 is None else (lambda s: f0 + f1 * s),
            distributed_moment=None if self.l0 is None else (lambda s: np.array(self.l0)),
            gravity=np.zeros(3) if self.gravity is None else np.array(self.gravity),
            mass_per_length=mass_per_length,
        )

    def magnitude(self, length: float) -> float:
        """A force scale of the loads (N)."""
        f = np.linalg.norm(self.tip_force) + np.linalg.norm(self.tip_moment) / length
        f += sum(
            np.linalg.norm(p.force) + np.linalg.norm(p.moment) / length for p in self.point_loads
        )
        if self.f0 is not None:
            f += (np.linalg.norm(self.f0) + np.linalg.norm(self.f1) * length) * length
        if self.l0 is not None:
            f += np.linalg.norm(self.l0)
        return float(f)

    def rotated(self, r: np.ndarray) -> LoadsCase:
        """World-frame components rotated by ``r`` (body-frame ones unchanged)."""

        def rot(v, frame="world"):
            return v if v is None or frame == "body" else tuple(float(x) for x in r @ v)

        return replace(
            self,
            tip_force=rot(self.tip_force, self.tip_frame),
            tip_moment=rot(self.tip_moment, self.tip_frame),
            point_loads=tuple(
                replace(p, force=rot(p.force, p.frame), moment=rot(p.moment, p.frame))
                for p in self.point_loads
            ),
            f0=rot(self.f0),
            f1=rot(self.f1),
            l0=rot(self.l0),
            gravity=rot(self.gravity),
        )

    def scaled(self, lam: float) -> LoadsCase:
        """Loads of the robot with every length times ``lam``, at the same P L^2 / EI."""

        def mul(v, k):
            return None if v is None else tuple(float(x) * k for x in v)

        return replace(
            self,
            tip_force=mul(self.tip_force, lam**2),
            tip_moment=mul(self.tip_moment, lam**3),
            point_loads=tuple(
                replace(p, force=mul(p.force, lam**2), moment=mul(p.moment, lam**3))
                for p in self.point_loads
            ),
            f0=mul(self.f0, lam),
            f1=self.f1,
            l0=mul(self.l0, lam**2),
            gravity=mul(self.gravity, 1.0 / lam),
        )


@dataclass(frozen=True)
class RobotCase:
    length: float
    section: SectionCase
    material: MaterialCase
    rest_curvature: Vec3 | None = None
    inextensible: bool = False
    density: float | None = None
    base_rotation: tuple[Vec3, Vec3, Vec3] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    base_position: Vec3 = (0.0, 0.0, 0.0)
    tendons: tuple[TendonCase, ...] = ()
    chambers: tuple[ChamberCase, ...] = ()
    loads: LoadsCase = field(default_factory=LoadsCase)

    # --- building
    def rod(self) -> softrod.Rod:
        return softrod.Rod(
            self.length,
            self.section.build(self.length),
            self.material.build(),
            rest_curvature=self.rest_curvature,
            inextensible=self.inextensible,
            density=self.density,
            base_pose=(np.array(self.base_position), np.array(self.base_rotation)),
        )

    def build(self, extra_tip=None):
        return (
            self.rod(),
            [t.build(self.length) for t in self.tendons],
            self.loads.build(self.length, extra_tip),
            [c.build(self.length) for c in self.chambers],
        )

    def solve(self, extra_tip=None, **options) -> softrod.StaticsSolution:
        rod, tendons, loads, chambers = self.build(extra_tip)
        return softrod.solve_statics(rod, tendons, loads, chambers=chambers, **options)

    # --- scales and specs for the oracles
    def ei(self) -> float:
        return self.material.modulus() * self.section.inertia0()

    def force_scale(self) -> float:
        """EI / L^2 plus the loads' own size (N)."""
        f = self.ei() / self.length**2 + self.loads.magnitude(self.length)
        f += sum(t.tension for t in self.tendons)
        if self.density and self.loads.gravity is not None:
            area = self.section.area(0.0, self.length)
            f += self.density * area * np.linalg.norm(self.loads.gravity) * self.length
        return float(f)

    def load_spec(self) -> LoadSpec:
        mass = None
        if self.density:
            mass = lambda s: self.density * self.section.area(s, self.length)  # noqa: E731
        return self.loads.spec(self.length, mass)

    def tendon_specs(self) -> list[TendonSpec]:
        return [t.spec(self.section, self.length) for t in self.tendons]

    def chamber_specs(self) -> list[ChamberSpec]:
        return [c.spec(self.length) for c in self.chambers]

    # --- transformations
    def moved(self, rotation: np.ndarray, position: np.ndarray) -> RobotCase:
        """The robot with its base moved by (rotation, position) and world loads rotated."""
        r0 = np.array(self.base_rotation)
        p0 = np.array(self.base_position)
        r = rotation @ r0
        p = rotation @ p0 + position
        return replace(
            self,
            base_rotation=tuple(tuple(float(x) for x in row) for row in r),
            base_position=tuple(float(x) for x in p),
            loads=self.loads.rotated(rotation),
        )

    def scaled(self, lam: float) -> RobotCase:
        """Every length times ``lam``, loads scaled to keep P L^2 / EI (E unchanged)."""
        return replace(
            self,
            length=self.length * lam,
            section=self.section.scaled(lam),
            rest_curvature=None
            if self.rest_curvature is None
            else tuple(x / lam for x in self.rest_curvature),
            base_position=tuple(x * lam for x in self.base_position),
            tendons=tuple(t.scaled(lam) for t in self.tendons),
            chambers=tuple(c.scaled(lam) for c in self.chambers),
            loads=self.loads.scaled(lam),
        )


# ----------------------------------------------------------------------------- strategies


def unit_vectors():
    return (
        st.tuples(*[st.floats(-1, 1)] * 3)
        .filter(lambda v: 0.1 < np.linalg.norm(v) <= 1)
        .map(lambda v: np.array(v) / np.linalg.norm(v))
    )


def rotations():
    """Uniform-ish random rotations (unit quaternions)."""
    return (
        st.tuples(*[st.floats(-1, 1)] * 4)
        .filter(lambda q: 0.1 < np.linalg.norm(q) <= 1)
        .map(_quat_to_matrix)
    )


def _quat_to_matrix(q) -> np.ndarray:
    w, x, y, z = np.array(q) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _vec(c, scale, direction) -> Vec3:
    return tuple(float(x) for x in c * scale * direction)


@st.composite
def sections(draw, length: float, kinds=("circular", "tapered", "tube", "table")):
    kind = draw(st.sampled_from(kinds))
    r0 = length * draw(st.floats(1 / 80, 1 / 15))
    if kind == "tapered":
        return SectionCase(kind, r0, r1=r0 * draw(st.floats(0.4, 1.0)))
    if kind == "tube":
        return SectionCase(kind, r0, ri=r0 * draw(st.floats(0.0, 0.7)))
    if kind == "table":
        n = draw(st.integers(2, 4))
        xs = [
            0.0,
            *sorted(
                draw(st.lists(st.floats(0.05, 0.95), min_size=n - 2, max_size=n - 2, unique=True))
            ),
            1.0,
        ]
        nodes = tuple(
            (x, r0 * draw(st.floats(0.7, 1.1)), r0 * draw(st.floats(0.7, 1.1))) for x in xs
        )
        return SectionCase(kind, r0, nodes=nodes)
    return SectionCase(kind, r0)


def materials(linear_only: bool = False):
    linear = st.builds(
        MaterialCase,
        st.just("linear"),
        st.floats(4, 9).map(lambda e: 10.0**e),
        st.floats(0.3, 0.49),
    )
    if linear_only:
        return linear
    neo = st.builds(MaterialCase, st.just("neo-hookean"), st.floats(4, 6).map(lambda e: 10.0**e))
    yeoh = st.floats(4, 5.5).flatmap(
        lambda e: st.builds(
            MaterialCase,
            st.just("yeoh"),
            st.just(10.0**e),
            st.floats(-0.05, 0.2).map(lambda k: k * 10.0**e),
            st.floats(0.0, 0.05).map(lambda k: k * 10.0**e),
        )
    )
    lib = st.builds(
        MaterialCase,
        st.just("silicone"),
        st.sampled_from([0.0, 1.0]),
        name=st.sampled_from(softrod.SILICONES),
    )
    return st.one_of(linear, linear, neo, yeoh, lib)


@st.composite
def tendons(
    draw,
    section: SectionCase,
    length: float,
    ei: float,
    routings=("constant", "radius", "helical"),
    ends=True,
    budget=None,
):
    rmin = section.min_radius(length)
    if section.kind not in ("circular", "tapered"):
        routings = tuple(r for r in routings if r != "radius")  # the ratio needs a radius
    routing = draw(st.sampled_from(routings))
    c = draw(st.floats(0.0, 0.6))
    if budget is not None:
        budget.append(c)
    end = draw(st.one_of(st.none(), st.floats(0.3, 1.0))) if ends else None
    if routing == "constant":
        d = rmin * draw(st.floats(0.1, 0.8))
        a = draw(st.floats(-math.pi, math.pi))
        return TendonCase(
            routing, d * math.cos(a), d * math.sin(a), 0.0, c * ei / (d * length), end
        )
    if routing == "radius":
        ratio = draw(st.floats(0.1, 0.8))
        a = draw(st.floats(-math.pi, math.pi))
        d = ratio * section.r0
        return TendonCase(routing, ratio, a, 0.0, c * ei / (d * length), end)
    rho = rmin * draw(st.floats(0.1, 0.8))
    pitch = length * draw(st.floats(1.0, 6.0)) * draw(st.sampled_from([-1.0, 1.0]))
    phase = draw(st.floats(-math.pi, math.pi))
    return TendonCase(routing, rho, pitch, phase, c * ei / (rho * length), end)


@st.composite
def chambers(draw, section: SectionCase, length: float, ei: float, modulus: float, budget=None):
    rmin = section.min_radius(length)
    rc = rmin * draw(st.floats(0.1, 0.3))
    dc = (0.9 * rmin - rc) * draw(st.floats(0.2, 1.0))
    a = draw(st.floats(-math.pi, math.pi))
    area = math.pi * rc * rc
    c = draw(st.floats(0.0, 0.5))
    if budget is not None:
        budget.append(c)
    pressure = min(c * ei / (area * dc * length), 0.2 * modulus)
    start = draw(st.one_of(st.just(0.0), st.floats(0.01, 0.3)))
    end = draw(st.one_of(st.none(), st.floats(0.6, 1.0)))
    return ChamberCase(pressure, rc, dc * math.cos(a), dc * math.sin(a), start, end)


@st.composite
def loads(draw, length: float, ei: float, area: float, budget: list):
    """External loads of total dimensionless size below ``2 - sum(budget)``."""
    fs, ms = ei / length**2, ei / length
    kw: dict = {}
    density = None

    def c():
        v = draw(st.floats(0.0, 0.8))
        budget.append(v)
        return v

    if draw(st.booleans()):
        kw["tip_force"] = _vec(c(), fs, draw(unit_vectors()))
    if draw(st.booleans()):
        kw["tip_moment"] = _vec(c(), ms, draw(unit_vectors()))
    if kw and draw(st.booleans()):
        kw["tip_frame"] = "body"
    if draw(st.integers(0, 3)) == 0:
        pls = []
        for _ in range(draw(st.integers(1, 2))):
            x = draw(st.floats(0.2, 0.9))
            pls.append(
                PointLoadCase(
                    x,
                    _vec(c(), ei / (x * length) ** 2, draw(unit_vectors())),
                    _vec(0.3 * c(), ms, draw(unit_vectors())),
                    draw(st.sampled_from(["world", "body"])),
                )
            )
        kw["point_loads"] = tuple(pls)
    if draw(st.integers(0, 3)) == 0:
        kw["f0"] = _vec(c(), 2 * ei / length**3, draw(unit_vectors()))
        if draw(st.booleans()):
            kw["f1"] = _vec(c(), 2 * ei / length**4, draw(unit_vectors()))
    if draw(st.integers(0, 4)) == 0:
        kw["l0"] = _vec(c(), ei / length**2, draw(unit_vectors()))
    if draw(st.integers(0, 2)) == 0:
        density = draw(st.floats(500.0, 8000.0))
        g = 9.81 * draw(unit_vectors())
        q = density * area * 9.81
        assume(q * length**3 / ei < 2.0)
        budget.append(q * length**3 / (3 * ei))
        kw["gravity"] = tuple(float(x) for x in g)
    return LoadsCase(**kw), density


@st.composite
def robots(
    draw,
    *,
    base: bool = False,
    chambers_allowed: bool = True,
    rest: bool = True,
    max_tendons: int = 3,
):
    """Generated robots: sections, tapers, precurvature, tendons (constant, proportional,
    helical, staggered ends), chambers (inside the section), linear and hyperelastic materials,
    tip/point/distributed loads, gravity and (with ``base``) base poses."""
    length = draw(st.floats(0.05, 0.5))
    section = draw(sections(length))
    material = draw(materials())
    linear = material.kind == "linear"
    inextensible = linear and draw(st.integers(0, 4)) == 0
    ei = material.modulus() * section.inertia0()
    budget: list[float] = []
    rc = None
    if rest and draw(st.booleans()):
        direction = draw(unit_vectors())
        k = draw(st.floats(0.0, 1.5))
        budget.append(k)
        rc = tuple(float(x) for x in direction * k / length)
    ts = tuple(
        draw(tendons(section, length, ei, budget=budget))
        for _ in range(draw(st.integers(0, max_tendons)))
    )
    cs = ()
    if chambers_allowed and section.kind in ("circular", "tapered") and not inextensible:
        cs = tuple(
            draw(chambers(section, length, ei, material.modulus(), budget=budget))
            for _ in range(draw(st.integers(0, 2)))
        )
    lc, density = draw(loads(length, ei, section.area(0.0, length), budget))
    assume(sum(budget) < 2.0)
    case = RobotCase(
        length, section, material, rc, inextensible, density, tendons=ts, chambers=cs, loads=lc
    )
    if base:
        r = draw(rotations())
        p = np.array(draw(st.tuples(*[st.floats(-1, 1)] * 3)))
        case = case.moved(r, p)
    return case


@dataclass(frozen=True)
class PccCase:
    """A uniform, linear, circular rod cut into segments at tendon ends and chamber bounds."""

    segments: tuple[float, ...]  # lengths (m)
    radius: float
    modulus: float
    poisson: float
    extensible: bool
    #: (segment index the tendon ends at, distance, angle, tension)
    tendons: tuple[tuple[int, float, float, float], ...]
    #: (first segment, last segment, radius, distance, angle, pressure)
    chambers: tuple[tuple[int, int, float, float, float, float], ...]

    @property
    def length(self) -> float:
        return float(sum(self.segments))

    def bounds(self) -> np.ndarray:
        return np.concatenate([[0.0], np.cumsum(self.segments)])

    def cosserat(self, **options):
        b = self.bounds()
        rod = softrod.Rod(
            self.length,
            softrod.CircularSection(self.radius),
            softrod.LinearElastic(self.modulus, self.poisson),
            inextensible=not self.extensible,
        )
        ts = [
            softrod.Tendon(
                (d * math.cos(a), d * math.sin(a)),
                t,
                None if k == len(self.segments) - 1 else float(b[k + 1]),
            )
            for k, d, a, t in self.tendons
        ]
        cs = [
            softrod.Chamber(
                p,
                math.pi * rc * rc,
                (d * math.cos(a), d * math.sin(a)),
                float(b[k0]),
                None if k1 == len(self.segments) - 1 else float(b[k1 + 1]),
            )
            for k0, k1, rc, d, a, p in self.chambers
        ]
        return softrod.solve_statics(rod, ts, None, chambers=cs, **options)

    def pcc(self):
        from softrod import pcc

        robot = pcc.Robot.solid_circle(
            list(self.segments), self.radius, self.modulus, extensible=self.extensible
        )
        for k, d, a, _ in self.tendons:
            robot = robot.with_tendons(k, [d], [a])
        pressures = []
        for k0, k1, rc, d, a, p in self.chambers:
            for k in range(k0, k1 + 1):
                robot = robot.with_chambers(k, [math.pi * rc * rc], [d], [a])
                pressures.append(p)
        # One output point: the default backbone sampling can trip the round-off rejection
        # that tests/test_trust_pcc.py covers; the tip pose does not depend on it.
        return pcc.solve(robot, [t for *_, t in self.tendons], pressures, s=[0.0])


@st.composite
def pcc_robots(draw):
    n = draw(st.integers(1, 3))
    segments = tuple(draw(st.floats(0.05, 0.2)) for _ in range(n))
    length = sum(segments)
    radius = length * draw(st.floats(1 / 80, 1 / 20))
    modulus = 10.0 ** draw(st.floats(4, 9))
    ei = modulus * math.pi * radius**4 / 4
    ts = []
    for _ in range(draw(st.integers(1, 4))):
        k = draw(st.integers(0, n - 1))
        d = radius * draw(st.floats(0.1, 0.9)) * draw(st.sampled_from([1.0, 20.0]))
        c = draw(st.floats(0.0, 0.5))
        ts.append((k, d, draw(st.floats(-math.pi, math.pi)), c * ei / (d * length)))
    cs = []
    for _ in range(draw(st.integers(0, 2))):
        k0 = draw(st.integers(0, n - 1))
        k1 = draw(st.integers(k0, n - 1))
        rc = radius * draw(st.floats(0.1, 0.3))
        d = (0.9 * radius - rc) * draw(st.floats(0.2, 1.0))
        c = draw(st.floats(0.0, 0.4))
        p = min(c * ei / (math.pi * rc * rc * d * length), 0.2 * modulus)
        cs.append((k0, k1, rc, d, draw(st.floats(-math.pi, math.pi)), p))
    return PccCase(
        segments,
        radius,
        modulus,
        draw(st.floats(0.3, 0.49)),
        draw(st.booleans()),
        tuple(ts),
        tuple(cs),
    )
