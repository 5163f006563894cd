"""Issue 10's other defects, one focused test each, asserting the correct behaviour.

Each asserts the right answer or a named error. Those that fail on today's build are marked
``xfail(strict=True)``: a fix turns them into XPASS, and the mark must then go. Calls that
abort the interpreter today run in a subprocess (``harness/fuzz.py``).
"""

import math
import re
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from harness import arcs, elastica, fuzz
from harness.balance import LoadSpec, TendonSpec, balance_error
from harness.oracles import castigliano_arc
from harness.robots import TRI_TENDON

import softrod
from softrod import pcc


def xfail(why: str):
    return pytest.mark.xfail(strict=True, reason=f"issue 10: {why}")


def _named(exc: BaseException, *names: str) -> bool:
    return isinstance(exc, (ValueError, TypeError)) and any(
        fuzz.names_parameter(exc, n) for n in names
    )


def _niti_rod():
    return softrod.Rod(0.4, softrod.CircularSection(0.7e-3), softrod.LinearElastic(54e9, 0.3))


def _cantilever_failure():
    """The soft cantilever at PL^2/EI = 300 (RK4): the load steps run out."""
    f = 300 * elastica.EI / elastica.LENGTH**2
    return elastica.rod(), softrod.Loads(tip_force=(f, 0.0, 0.0))


def _seven_pa_arm():
    rod = softrod.Rod(
        0.27, softrod.TaperedCircularSection(0.015, 0.0074), softrod.LinearElastic(7.0, 0.5)
    )
    return rod, [softrod.Tendon.radius_proportional(1 / 3, 0.0, 1.0)]


# ----------------------------------------------------------------------------- non-convergence


def test_converged_stats_report_load_factor_one():
    sol = softrod.solve_statics(_niti_rod(), [softrod.Tendon((0.01, 0.0), 1.0)])
    assert sol.stats["load_factor"] == 1.0


def test_throw_false_returns_the_shape_of_its_load_factor():
    rod, loads = _cantilever_failure()
    sol = softrod.solve_statics(rod, [], loads, throw=False)
    assert not sol.converged
    lam = sol.stats["load_factor"]
    assert 0.0 <= lam < 1.0
    # The returned shape is the equilibrium under lam x the load: its tip force is lam F and it
    # balances lam F (integrated here from the shape).
    f = np.array([300 * elastica.EI / elastica.LENGTH**2, 0.0, 0.0])
    assert np.allclose(np.asarray(sol.force)[-1], lam * f, rtol=1e-8, atol=1e-12 * f[0])
    scale = elastica.EI / elastica.LENGTH**2
    base, _ = balance_error(sol, LoadSpec(tip_force=lam * f), scale, elastica.LENGTH)
    assert base < 1e-8


def test_convergence_error_carries_iterations_residual_and_load_factor():
    rod, loads = _cantilever_failure()
    with pytest.raises(softrod.ConvergenceError) as e:
        softrod.solve_statics(rod, [], loads)
    assert e.value.iterations > 0 and math.isfinite(e.value.residual)
    assert 0.0 <= e.value.load_factor < 1.0


def test_load_steps_running_out_after_an_accepted_step_is_not_converged():
    # The near-axial push at PL^2/EI = 300 (8.1 degrees off -z): the continuation's last
    # accepted step is at load factor ~0.47 when the steps run out; that state was returned as
    # converged at the full load.
    u = np.array([0.14097948, 0.0049786, -0.99])
    f = 300 * elastica.EI / elastica.LENGTH**2 * u / np.linalg.norm(u)
    loads = softrod.Loads(tip_force=tuple(f))
    with pytest.raises(softrod.ConvergenceError) as e:
        softrod.solve_statics(elastica.rod(), [], loads)
    assert 0.0 < e.value.load_factor < 1.0
    sol = softrod.solve_statics(elastica.rod(), [], loads, throw=False)
    assert not sol.converged and sol.stats["load_factor"] < 1.0


def test_a_residual_below_tolerance_comes_with_the_real_cause():
    rod, loads = _cantilever_failure()
    with pytest.raises(softrod.ConvergenceError) as e:
        softrod.solve_statics(rod, [], loads, tolerance=1e-10)
    if e.value.residual <= 1e-10:
        assert getattr(e.value, "load_factor", 1.0) < 1.0


def test_seven_pascal_arm_error_is_consistent():
    rod, tendons = _seven_pa_arm()
    with pytest.raises((softrod.ConvergenceError, softrod.ParameterError)) as e:
        softrod.solve_statics(rod, tendons)
    if isinstance(e.value, softrod.ParameterError):
        assert _named(e.value, "tension", "tendons", "youngs_modulus")
    else:
        assert e.value.residual > 0 or e.value.load_factor < 1.0
        sol = softrod.solve_statics(rod, tendons, throw=False)
        lam = sol.stats["load_factor"]
        # The returned shape belongs to lam x the tension: re-solved there, it is the same.
        again = softrod.solve_statics(
            rod, [tendons[0].with_tension(lam * tendons[0].tension)], warm_start=sol
        )
        assert np.allclose(again.tip_position, sol.tip_position, atol=1e-9 * 0.27)


# ----------------------------------------------------------------------------- validation


@pytest.mark.parametrize("strain", [(0.0, 0.0, -1.0), (0.0, 0.0, 0.0)])
def test_rest_strain_without_positive_stretch_is_a_named_error(strain):
    with pytest.raises(ValueError) as e:
        rod = softrod.Rod(
            0.1, softrod.CircularSection(0.01), softrod.LinearElastic(1e6, 0.3), rest_strain=strain
        )
        softrod.solve_statics(rod)
    assert _named(e.value, "rest_strain")


def test_huge_tendon_offset_is_solved_right_or_named():
    rod = _niti_rod()
    tendon = softrod.Tendon((0.5, 0.0), 1.0)
    try:
        sol = softrod.solve_statics(rod, [tendon])
    except softrod.ConvergenceError as exc:
        pytest.fail(f"unnamed ConvergenceError: {exc}")
    except ValueError as exc:
        assert _named(exc, "offset", "tendons", "tendon")
        return
    spec = TendonSpec(lambda s: np.array([0.5, 0.0]), lambda s: np.zeros(2), 1.0, None)
    _base, along = balance_error(sol, LoadSpec(), 1.0, 0.4, [spec])
    assert sol.converged and along < 1e-8


def test_overflowing_tension_is_a_named_error():
    with pytest.raises(ValueError) as e:
        softrod.solve_statics(_niti_rod(), [softrod.Tendon((0.01, 0.0), 1e308)])
    assert _named(e.value, "tension", "tendons")


def test_wrong_length_vector_names_its_argument():
    with pytest.raises(ValueError) as e:
        softrod.Loads(tip_force=(1.0, 2.0))
    assert _named(e.value, "tip_force")


# ------------------------------------------------------------------ sizes, in a subprocess

SIZE_CALLS = [
    ("pcc.solve", "n_points", "size-huge", True),
    ("compliance(pcc)", "panels", "size-huge", True),
    ("PlanarCableArm.solve_many", "n_points", "size-huge", True),
    ("PlanarCableArm.solve", "n_points", "size-huge", True),
    ("backbone_distance", "n_index", "size-huge", True),
    ("compare_models", "repeats", "size-huge", True),
    ("workspace_map", "block", "zero-int", False),
    ("workspace_map", "tensions", "empty-list", False),
    ("workspace_map", "chunk", "zero-int", False),
    ("pcc.solve(s)", "s", "empty-list", False),
    ("PlanarCableArm.solve(s)", "s", "empty-list", False),
    ("pcc.Solution.frames_at", "s", "empty-list", False),
    ("pcc.chain_frames", "s", "empty-list", False),
    ("pcc.arc_frames", "s", "empty-list", False),
]


@pytest.fixture(scope="module")
def size_outcomes():
    wanted = {(t, p, v) for t, p, v, _ in SIZE_CALLS}
    picked = [c for c in fuzz.calls() if (c.target, c.parameter, c.value) in wanted]
    assert len(picked) == len(wanted)
    return {
        (o.call.target, o.call.parameter, o.call.value): o for o in fuzz.run(picked, timeout=10.0)
    }


@pytest.mark.parametrize(
    ("target", "parameter", "value"),
    [pytest.param(t, p, v) for t, p, v, _aborted_before in SIZE_CALLS],
)
def test_sizes_and_empty_samples_are_checked(size_outcomes, target, parameter, value):
    o = size_outcomes[(target, parameter, value)]
    allowed = ("named-error",) if value != "empty-list" else ("named-error", "ok-finite")
    assert o.outcome in allowed, (o.outcome, o.detail)


# ----------------------------------------------------------------------------- callbacks


class CallbackError(Exception):
    pass


def _raise(s):
    raise CallbackError(f"no section at s = {s}")


def _reaches_caller(exc: BaseException) -> bool:
    e, seen = exc, 0
    while e is not None and seen < 10:
        if isinstance(e, CallbackError):
            return True
        e, seen = e.__cause__ or e.__context__, seen + 1
    return False


def test_function_section_exception_reaches_the_caller():
    # The section function is first called when the section is built (at s = 0).
    with pytest.raises(Exception) as e:
        rod = softrod.Rod(0.3, softrod.FunctionSection(_raise), softrod.LinearElastic(5e7, 0.3))
        softrod.solve_statics(rod)
    assert _reaches_caller(e.value), repr(e.value)


def test_rest_curvature_exception_reaches_the_caller():
    with pytest.raises(Exception) as e:
        rod = softrod.Rod(
            0.3,
            softrod.CircularSection(0.002),
            softrod.LinearElastic(5e7, 0.3),
            rest_curvature=_raise,
        )
        softrod.solve_statics(rod)
    assert _reaches_caller(e.value), repr(e.value)


def test_callback_errors_stay_in_their_thread():
    local = threading.local()

    def area(s):
        if getattr(local, "bad", False):
            raise CallbackError("bad thread")
        return (1.2e-5, 1.1e-11, 1.1e-11, 2.2e-11)

    rod = softrod.Rod(0.3, softrod.FunctionSection(area), softrod.LinearElastic(5e7, 0.3))
    tendons = [softrod.Tendon((0.001, 0.0), 0.5)]
    loads = softrod.Loads(tip_force=(0.01, 0.0, 0.0))

    def job(i):
        local.bad = i % 2 == 1
        try:
            softrod.solve_statics(rod, tendons, loads)
            return local.bad, None
        except Exception as exc:
            return local.bad, exc

    with ThreadPoolExecutor(8) as ex:
        results = list(ex.map(job, range(3000)))
    clean_failed = [e for bad, e in results if not bad and e is not None]
    bad_wrong = [e for bad, e in results if bad and (e is None or not _reaches_caller(e))]
    assert clean_failed == [] and bad_wrong == [], (len(clean_failed), len(bad_wrong))


# ----------------------------------------------------------------------------- silent non-finite


def _finite_or_named(call, *names):
    try:
        out = call()
    except ValueError as exc:
        assert _named(exc, *names), repr(exc)
        return
    assert np.all(np.isfinite(np.asarray(out, dtype=float))), out


def test_yeoh_stress_overflow():
    _finite_or_named(lambda: softrod.Yeoh(3e4, -1e2, 10.0).nominal_stress(1e300), "stretch")


def test_planar_radius_of_nan():
    _finite_or_named(lambda: softrod.PlanarCableArm.published_arm().radius([math.nan]), "s")


def test_planar_radius_beyond_the_arm_is_a_named_error():
    with pytest.raises(ValueError) as e:
        softrod.PlanarCableArm.published_arm().radius([1e3])
    assert _named(e.value, "s")


def test_arc_pose_of_a_huge_length():
    _finite_or_named(lambda: pcc.arc_pose(15.7, 0.0, 1e300), "length")


@pytest.mark.parametrize(
    ("strain", "stress"),
    [
        (np.array([0.0, np.nan, 0.2]), np.array([0.0, 1e4, 2e4])),
        (np.array([0.0, 0.1, 0.2]), np.array([0.0, np.inf, 2e4])),
        (None, None),
    ],
)
def test_tensile_curve_rejects_nonfinite_and_missing_data(strain, stress):
    with pytest.raises((ValueError, TypeError)) as e:
        softrod.TensileCurve(strain, stress)
    assert _named(e.value, "strain", "stress")


# ----------------------------------------------------------------------------- workspace maps


def _tendon_chamber_robot():
    rod = softrod.Rod(0.12, softrod.CircularSection(0.01), softrod.LinearElastic(300e3, 0.45))
    tendons = [softrod.Tendon((0.006, 0.0), 0.0)]
    chambers = [softrod.Chamber(8e3, math.pi * 0.0025**2, (-0.005, 0.0))]
    return rod, tendons, chambers


def test_workspace_map_keeps_the_chambers():
    rod, tendons, chambers = _tendon_chamber_robot()
    tensions = np.array([[0.0], [0.05]])
    wmap = softrod.workspace_map(rod, tendons, tensions, chambers=chambers)
    for row, tip in zip(tensions, wmap.tip_position, strict=True):
        ref = softrod.solve_statics(
            rod, [tendons[0].with_tension(float(row[0]))], chambers=chambers
        )
        assert np.allclose(tip, ref.tip_position, atol=1e-9)
    assert abs(wmap.tip_position[0, 0]) > 1e-3  # the chamber bends the arm


def test_cli_workspace_keeps_the_chambers(tmp_path):
    import json

    from softrod.cli import main

    rod, tendons, chambers = _tendon_chamber_robot()
    robot = softrod.Robot(rod, tendons=tendons, chambers=chambers, name="tc")
    path = tmp_path / "tc.toml"
    robot.write_toml(path)
    out = tmp_path / "map.json"
    assert main(["workspace", str(path), "--sweep", "0:0.05", "--n", "2", "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    ref = softrod.solve_statics(rod, tendons, chambers=chambers)
    assert np.allclose(data["tip_position"][0], ref.tip_position, atol=1e-9)


def test_workspace_tangent_at_fixed_length_is_finite_on_a_ten_tendon_robot():
    rod = softrod.Rod(0.3, softrod.CircularSection(0.001), softrod.LinearElastic(50e9, 0.3))
    tendons = [
        softrod.Tendon((0.008 * math.cos(a), 0.008 * math.sin(a)), 0.0, 0.15 if k < 5 else None)
        for k, a in enumerate(np.linspace(0, 2 * math.pi, 10, endpoint=False))
    ]
    tensions = np.zeros((3, 10))
    tensions[:, 0] = [0.5, 1.0, 1.5]
    try:
        wmap = softrod.workspace_map(rod, tendons, tensions, tangent="length")
    except ValueError as exc:
        assert _named(exc, "tangent", "tendons", "held")
        return
    assert wmap.converged.all()
    assert np.all(np.isfinite(wmap.tangent_max_translational_compliance))


# ----------------------------------------------------------------------------- output at chosen s


def test_solve_statics_reports_exactly_at_s_out():
    kappa = 1.5 * math.pi / arcs.LENGTH
    s_out = np.array([0.0, 0.0123, 0.1, 0.1777, arcs.LENGTH])
    sol = softrod.solve_statics(arcs._rod(kappa), s_out=s_out)
    assert np.array_equal(np.asarray(sol.s), s_out)
    exact = np.stack(
        [(1 - np.cos(kappa * s_out)) / kappa, 0 * s_out, np.sin(kappa * s_out) / kappa], axis=1
    )
    assert np.max(np.abs(np.asarray(sol.position) - exact)) < 1e-9 * arcs.LENGTH


def test_compliance_at_s_out_matches_castigliano():
    theta = 1.5 * math.pi
    sol = arcs.solve("precurved", theta, **arcs.adaptive_options(1e-10))
    s_out = [0.05, 0.1234]
    c = softrod.compliance(sol, s_out=s_out)
    for k, s in enumerate(s_out):
        exact = castigliano_arc(theta / arcs.LENGTH, s, arcs.stiffness())
        err = np.max(np.abs(np.asarray(c.world)[k] - exact)) / np.max(np.abs(exact))
        assert err < 1e-8


# ------------------------------------------------------------------ found by the harnesses


def _table_yeoh_rod(base_rotation):
    nodes = [
        (0.0, 0.00515620598800513, 0.0064849853515625),
        (0.3333333333333333, 0.006461143493652344, 0.004291534423828125),
        (0.625, 0.006699562072753906, 0.00667572021484375),
        (1.0, 0.005953949125742169, 0.0042724609375),
    ]
    length = 0.15625
    section = softrod.TableSection(
        [x * length for x, _, _ in nodes],
        [math.pi * a * b for _, a, b in nodes],
        [math.pi * a * b**3 / 4 for _, a, b in nodes],
        [math.pi * a**3 * b / 4 for _, a, b in nodes],
        [math.pi * a**3 * b**3 / (a * a + b * b) for _, a, b in nodes],
    )
    c10 = 316227.7660168379
    rod = softrod.Rod(
        length,
        section,
        softrod.Yeoh(c10, 0.125 * c10, 12352.64711003273),
        rest_curvature=(0.09979250034173506, 0.0, -0.4508841804731354),
        base_pose=(np.zeros(3), np.asarray(base_rotation, dtype=float)),
    )
    tendons = [
        softrod.Tendon(
            (-0.0024959722673536426, 0.0014178277004398044), 1.1076066823408115, 0.5 * length
        ),
        softrod.Tendon(
            (1.7722662770693556e-05, 0.0021361569518273137), 1.0247749020971715, 0.5 * length
        ),
    ]
    loads = softrod.Loads(distributed_force=(0.0, 0.34444201701569443, -0.03827133522396605))
    return rod, tendons, loads


@pytest.mark.parametrize(
    ("integrator", "at"),
    [
        ("rk4", 0.25),
        ("adaptive", 0.4),
    ],
)
def test_hyperelastic_tip_strains_are_finite(integrator, at):
    rod = softrod.Rod(0.5, softrod.CircularSection(0.00625), softrod.NeoHookean(1e4))
    loads = softrod.Loads(
        tip_force=(1e-3, 0.0, 0.0), point_loads=[softrod.PointLoad(at, (0.0, 0.0, 0.0))]
    )
    sol = softrod.solve_statics(rod, [], loads, integrator=integrator)
    assert sol.converged
    assert np.all(np.isfinite(np.asarray(sol.v))) and np.all(np.isfinite(np.asarray(sol.u)))


def test_converged_solution_has_no_nan_strains():
    rod, tendons, loads = _table_yeoh_rod(np.diag([-1.0, -1.0, 1.0]))
    try:
        sol = softrod.solve_statics(rod, tendons, loads, steps=200, tolerance=1e-12)
    except softrod.ConvergenceError:
        return  # a named failure is acceptable; a silent NaN is not
    for name in ("v", "u", "force", "moment", "position"):
        assert np.all(np.isfinite(np.asarray(getattr(sol, name)))), name


def test_absurd_warm_start_is_not_reported_converged():
    rod = softrod.Rod(0.3, softrod.CircularSection(0.002), softrod.LinearElastic(5e7, 0.3))
    loads = softrod.Loads(tip_force=(0.01, 0.0, 0.0))
    try:
        sol = softrod.solve_statics(
            rod,
            [],
            loads,
            integrator="adaptive",
            warm_start=[1e308, 0, 0, 0, 0.003, 0],
            throw=False,
        )
    except ValueError as exc:
        assert _named(exc, "warm_start")
        return
    if sol.converged:
        assert math.isfinite(sol.stats["residual"])
        assert np.all(np.isfinite(np.asarray(sol.force)))


def _fd_tip_compliance(rod, tendons, sol, h_force, h_moment, **options):
    """Central differences of the tip twist under a +-h world tip wrench, warm-started."""
    from harness.oracles import rotation_vector

    cols = []
    for k in range(6):
        tips = []
        for sgn in (1.0, -1.0):
            f, m = np.zeros(3), np.zeros(3)
            if k < 3:
                f[k] = sgn * h_force
            else:
                m[k - 3] = sgn * h_moment
            s = softrod.solve_statics(
                rod,
                tendons,
                softrod.Loads(tip_force=tuple(f), tip_moment=tuple(m)),
                warm_start=sol,
                tolerance=1e-13,
                **options,
            )
            tips.append((np.asarray(s.tip_position), np.asarray(s.tip_rotation)))
        (p1, r1), (p2, r2) = tips
        h = h_force if k < 3 else h_moment
        cols.append(np.concatenate([p1 - p2, rotation_vector(r1 @ r2.T)]) / (2 * h))
    return np.array(cols).T


def test_tangent_compliance_is_the_derivative_of_the_solve_on_a_soft_tapered_rod():
    from harness.oracles import block_relative_error

    length, r0, r1, modulus = 0.5, 0.015625, 0.0068359375, 51614.7
    rod = softrod.Rod(
        length, softrod.TaperedCircularSection(r0, r1), softrod.LinearElastic(modulus, 0.49)
    )
    tendons = [softrod.Tendon((0.00341796875, 0.0), 0.7069281979685804)] * 2
    sol = softrod.solve_statics(rod, tendons, steps=80, tolerance=1e-13)
    ei = modulus * math.pi * r0**4 / 4
    fd = _fd_tip_compliance(rod, tendons, sol, 1e-4 * ei / length**2, 1e-4 * ei / length, steps=80)
    tangent = np.asarray(softrod.tangent_compliance(sol, "tension").world)
    assert block_relative_error(tangent, fd) < 1e-5


def test_a_curl_the_default_mesh_cannot_resolve_is_mapped_on_a_finer_one():
    # A tapered silicone-like arm (0.4 m, radius 8 mm to 3 mm) whose one tendon curls it more
    # than a turn: the workspace map solved each row on the default 40 RK4 steps alone and
    # reported tips up to 7e-4 m off (1.7e-3 L) as converged; `Robot.solve` refines such a
    # mesh. Oracle: the adaptive integrator at rtol 1e-10; bound: the default mesh's accuracy,
    # 1e-4 L.
    rod = softrod.Rod(
        0.4, softrod.TaperedCircularSection(0.008, 0.003), softrod.LinearElastic(1e6, 0.5)
    )
    tendons = [softrod.Tendon((0.002, 0.0), 0.0)]
    tensions = np.array([[1.0], [5.0], [6.0], [7.0]])
    wmap = softrod.workspace_map(rod, tendons, tensions)
    for row, tip, ok in zip(tensions, wmap.tip_position, wmap.converged, strict=True):
        ref = softrod.solve_statics(
            rod,
            [tendons[0].with_tension(float(row[0]))],
            integrator="adaptive",
            rtol=1e-10,
            atol=1e-12,
        )
        assert ok
        assert np.linalg.norm(tip - ref.tip_position) <= 1e-4 * 0.4, (row, tip)


def _curled_rod():
    return softrod.Rod(
        0.4, softrod.TaperedCircularSection(0.008, 0.003), softrod.LinearElastic(1e6, 0.5)
    )


_ADAPTIVE = {"integrator": "adaptive", "rtol": 1e-10, "atol": 1e-12}


def test_a_curl_the_default_mesh_cannot_resolve_is_solved_on_a_finer_one_with_obstacles():
    # The tapered arm above, curled by 7 N: with an obstacle the solve went through the
    # contact path on the default 40 RK4 steps alone, 0.7 mm (1.8e-3 L) from the tip, with the
    # obstacle far away or touched. Oracles: the adaptive integrator without contact (a plane
    # 1 m away), and a chosen fine mesh (1,280 steps; 640 agree with it to 2.5e-8 m) against a
    # plane the arm presses on. Bound: the default mesh's accuracy, 1e-4 L.
    tendons = [softrod.Tendon((0.002, 0.0), 7.0)]
    far = softrod.Plane((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))
    near = softrod.Plane((0.12, 0.0, 0.0), (-1.0, 0.0, 0.0))
    free = softrod.Robot(_curled_rod(), tendons=tendons, name="curl")
    ref = free.solve(**_ADAPTIVE).tip_position
    away = softrod.Robot(_curled_rod(), tendons=tendons, name="curl", obstacles=[far])
    assert np.linalg.norm(away.solve().tip_position - ref) <= 1e-4 * 0.4
    pressed = softrod.Robot(_curled_rod(), tendons=tendons, name="curl", obstacles=[near])
    fine, finer = (pressed.solve(steps=n) for n in (640, 1280))
    assert len(finer.contacts) == 1 and finer.contacts[0]["normal_force"] > 0.01
    assert np.linalg.norm(fine.tip_position - finer.tip_position) <= 1e-7
    got = pressed.solve()
    assert len(got.contacts) == 1
    assert np.linalg.norm(got.tip_position - finer.tip_position) <= 1e-4 * 0.4


def test_a_curl_the_default_mesh_cannot_resolve_is_solved_on_a_finer_one_with_friction():
    # The same arm with tendon friction (mu 0.05), pulled to 6 N from rest, then to 7 N from
    # that state: the frictional solve ran on the default 40 RK4 steps alone, 9.4e-5 m and
    # 1.3e-4 m from the adaptive integrator's tip; the history's state now sets the mesh of
    # the next solve. Oracle: the same two solves with the adaptive integrator. Bound: 1e-4 L.
    def robot(tension):
        tendon = softrod.Tendon((0.002, 0.0), tension, friction=0.05)
        return softrod.Robot(_curled_rod(), tendons=[tendon], name="curl")

    first, first_ref = robot(6.0).solve(), robot(6.0).solve(**_ADAPTIVE)
    then = robot(7.0).solve(previous=first)
    then_ref = robot(7.0).solve(previous=first_ref, **_ADAPTIVE)
    for got, ref in ((first, first_ref), (then, then_ref)):
        assert np.linalg.norm(got.tip_position - ref.tip_position) <= 1e-4 * 0.4
    # A history on the default mesh whose next shape needs a finer one raised a ParameterError
    # naming `previous` (and `solve_path`, which takes no `previous`, stopped there): the
    # history, the tension profile read between its nodes as the solve reads it, is carried
    # onto the finer mesh. Oracle: the same history with the adaptive integrator.
    gentle = robot(1.0).solve()
    assert len(gentle.s) == 41
    got = robot(7.0).solve(previous=gentle)
    ref = robot(7.0).solve(previous=robot(1.0).solve(**_ADAPTIVE), **_ADAPTIVE)
    assert len(got.s) > 41
    assert np.linalg.norm(got.tip_position - ref.tip_position) <= 1e-4 * 0.4
    # Pulled to 7 N in 14 steps and released: the mesh refined on the way (41, then 481
    # nodes); measured 4.3e-5 L at most.
    up = np.linspace(0.5, 7.0, 14)[:, None]
    tensions = np.concatenate([up, up[::-1][1:]])
    path = softrod.solve_path(robot(0.0), tensions)
    path_ref = softrod.solve_path(robot(0.0), tensions, **_ADAPTIVE)
    for a, b in zip(path, path_ref, strict=True):
        assert np.linalg.norm(a.tip_position - b.tip_position) <= 1e-4 * 0.4


_CURL_TOML = """
name = "curl"
[rod]
length = 0.4004321480925477
[rod.section]
type = "tapered"
base_radius = 0.005336149340969354
tip_radius = 0.0012293510470560262
[rod.material]
type = "neo_hookean"
mu = 35686.90457170585
[[chambers]]
pressure = 357086.2514575653
area = 6.126080114978979e-07
offset = [0.0003565590886614968, 9.684793183689941e-05]
"""


def _curl(scale, friction=0.0, obstacles=None):
    """The tapered Neo-Hookean arm of `_CURL_TOML`, its chamber and a tendon (with `friction`)
    scaled together: 0.4 turns at 0.15, 3.7 turns at 1."""
    base = softrod.Robot.from_toml(_CURL_TOML)
    tendon = softrod.Tendon(
        (0.0004101559602322555, 0.00027241087980608915),
        0.02775249556468293 * scale,
        friction=friction,
    )
    robot = softrod.Robot(
        base.rod, tendons=[tendon], chambers=list(base.chambers), obstacles=obstacles or []
    )
    return robot.with_pressures([357086.2514575653 * scale])


def _frictional_curl(scale):
    """`_curl` with a tendon friction of 0.05."""
    return _curl(scale, friction=0.05)


def test_a_curl_the_default_mesh_cannot_march_is_tried_on_a_finer_one_with_obstacles():
    # The tapered Neo-Hookean arm of `_CURL_TOML` curled 3.7 turns by its chamber and a tendon
    # (740 1/m at the tip): on the default mesh the free solve fails and is tried on one
    # eight times finer; with a plane 1 m away (never touched) the contact path made no such
    # retry and raised a ConvergenceError. Oracle: the adaptive integrator; bound 1e-4 L.
    far = softrod.Plane((0.0, 0.0, -1.0), (0.0, 0.0, 1.0))
    ref = _curl(1.0).solve(**_ADAPTIVE).tip_position
    got = _curl(1.0, obstacles=[far]).solve()
    assert got.converged and not got.contacts
    assert np.linalg.norm(got.tip_position - ref) <= 1e-4 * 0.4


@pytest.mark.parametrize("scale", [0.15, 0.5, 1.0])
def test_the_adaptive_friction_mesh_follows_the_curl(scale):
    # With the adaptive integrator the friction mesh was 32 cells per interval whatever the
    # shape: the capstan rule of a cell turning 9.3 rad (more than pi: its end tangents' angle
    # aliases) put the tip 1.5e-3 L off and its tension 61 % high, reported converged; 0.76
    # rad per cell (scale 0.15) 8.9e-6 L. Cells now turn by 0.25 rad at most. Oracle: RK4 on
    # 10,240 steps (its friction mesh its nodes; 5,120 steps agree to 2.1e-8 L at scale 1,
    # second order). Bound: 1e-5 L (measured 3.8e-6 to 4.2e-6 L, the second-order error of
    # the 32 cells of the straighter part).
    robot = _frictional_curl(scale)
    length = 0.4004321480925477
    ref = robot.solve(steps=10240)
    got = robot.solve(**_ADAPTIVE)
    assert got.converged
    assert np.linalg.norm(got.tip_position - ref.tip_position) <= 1e-5 * length
    tip = lambda sol: np.asarray(sol.tendon_tension)[-1, 0]  # noqa: E731
    assert abs(tip(got) - tip(ref)) <= 1e-3 * tip(ref)
    # Every cell turns by at most 0.25 rad on the returned shape (|u| at the cell's ends).
    k = np.linalg.norm(np.asarray(got.u), axis=1)
    assert (np.diff(got.s) * np.maximum(k[1:], k[:-1])).max() <= 0.25


def test_a_displacement_controlled_frictional_curl_is_solved_on_the_chosen_mesh():
    # The whole curl with its tendon held at the displacement the tension gives: the base
    # tension is solved for, every evaluation a frictional solve on one mesh, and the mesh
    # refined between such solves. Oracle: RK4 on 5,120 steps; bound 1e-5 L (measured 1.2e-6).
    robot = _frictional_curl(1.0)
    pulled = robot.solve(steps=5120)
    d = list(pulled.tendon_displacements)
    got = robot.solve(displacements=d, **_ADAPTIVE)
    ref = robot.solve(displacements=d, steps=5120)
    assert np.linalg.norm(got.tip_position - ref.tip_position) <= 1e-5 * 0.4004321480925477
    assert abs(got.tensions[0] - ref.tensions[0]) <= 1e-4 * ref.tensions[0]


def test_a_history_on_an_adaptive_friction_mesh_is_carried_onto_a_finer_one():
    # Loaded from rest to 0.5 of the curl, then to the whole curl from that state: the second
    # shape needs a finer friction mesh than the first state's; the history (the tension
    # profile, read between the nodes as the solve reads it) is carried onto it. Oracle: the
    # same two solves on RK4 with 5,120 steps (its friction mesh its nodes). Bound: 1e-5 L.
    length = 0.4004321480925477
    first = _frictional_curl(0.5).solve(**_ADAPTIVE)
    first_ref = _frictional_curl(0.5).solve(steps=5120)
    then = _frictional_curl(1.0).solve(previous=first, **_ADAPTIVE)
    then_ref = _frictional_curl(1.0).solve(previous=first_ref, steps=5120)
    assert len(then.s) > len(first.s)
    assert np.linalg.norm(then.tip_position - then_ref.tip_position) <= 1e-5 * length
    # And back down to 0.5 from the curled state, slipping toward the tip where it unloads.
    # This state converges slowly with the mesh: RK4 on 640, 1,280 and 2,560 steps is 1.3e-5,
    # 1.3e-5 and 2.6e-5 L from 10,240 steps (5,120 agree with them to 3.8e-9 L); bound 5e-5 L
    # (measured 3.6e-5 L on the 135 nodes the history carries).
    back = _frictional_curl(0.5).solve(previous=then, **_ADAPTIVE)
    back_ref = _frictional_curl(0.5).solve(previous=then_ref, steps=5120)
    assert np.linalg.norm(back.tip_position - back_ref.tip_position) <= 5e-5 * length
    # Hysteresis: the unloaded state is not the loaded one.
    assert np.linalg.norm(back.tip_position - first.tip_position) > 1e-4 * length


def test_a_soft_arm_pressed_onto_a_plane_is_solved_on_the_mesh_its_curl_needs():
    # A soft arm (0.37 m, E 10.5 MPa) curled by two tendons and pressed onto a plane: the
    # default solve refines its mesh for the curl, and on meshes finer than 1.2 mm the contact
    # solve failed (its check between the nodes added contacts in one cell next to the kink of
    # the shearable backbone without end): a ConvergenceError after 5.6 s, while 320 and 640
    # steps converged in milliseconds. Oracle: 640 chosen steps; bound 1e-4 L (the mesh
    # control's); measured 2.5e-7 m.
    robot = softrod.Robot.from_toml(
        """
name = "pressed"
[rod]
length = 0.3690821757359716
[rod.section]
type = "tapered"
base_radius = 0.005744967655878824
tip_radius = 0.0056872651556404315
[rod.material]
type = "linear"
youngs_modulus = 10543184.136131344
poisson_ratio = 0.36599269107709165
[[tendons]]
tension = 108.754920214864
offset = [0.0008529250982936978, 0.0010378918948175035]
[[tendons]]
tension = 0.0
offset = [-0.00103524000042526, 0.000551268967112326]
[[tendons]]
tension = 92.4270689031148
offset = [0.000565454170044816, -0.004225781057125604]
[[obstacles]]
type = "plane"
point = [0.019468490651460453, -0.037279679141238094, 0.0]
normal = [-0.462906559550684, 0.8864070831874872, 0.0]
"""
    )
    ref = robot.solve(steps=640)
    got = robot.solve()
    assert got.converged and len(got.s) > 41 and got.contacts
    assert np.linalg.norm(got.tip_position - ref.tip_position) <= 1e-4 * 0.3690821757359716
    assert all(c["normal_force"] > 0 for c in got.contacts)


def test_a_chosen_mesh_too_coarse_for_the_shape_is_named_with_s_out_and_when_it_fails():
    # 8 RK4 steps turning a curled tendon arm by radians each: refused naming `steps` without
    # `s_out`, but with `s_out` returned converged with its tip 5.8 % of L off; and on a
    # Neo-Hookean arm curled 4.8 turns, 8 to 32 chosen steps failed as a `ParameterError`
    # naming the fibre `stretch` (blaming the loads) or a bare `ConvergenceError`. A chosen
    # mesh is now judged with `s_out` too, and one that fails is judged on the shape the
    # default mesh solves. Oracle: that shape's estimate on the chosen steps (tens of lengths).
    length = 0.41848084366072713
    rod = softrod.Rod(
        length,
        softrod.TaperedCircularSection(0.002165276355285291, 0.0018418191265751084),
        softrod.LinearElastic(6605524.798050307, 0.4458993121967997),
    )
    tendons = [
        softrod.Tendon((0.001308284336688203, -0.0005526508050886761), 2.5855007558402927),
        softrod.Tendon((-0.0005131067589266444, -0.00030090944448719795), 0.7749053195187314),
    ]
    for s_out in (None, [length / 2, length]):
        with pytest.raises(softrod.ParameterError) as info:
            softrod.solve_statics(rod, tendons, steps=8, s_out=s_out)
        assert info.value.parameter == "steps"
    curled = softrod.Robot.from_toml(
        """
name = "curl"
[rod]
length = 0.2831734577160381
[rod.section]
type = "tapered"
base_radius = 0.0085319168760092
tip_radius = 0.004841603762263498
[rod.material]
type = "neo_hookean"
mu = 598896.9547114645
[[chambers]]
pressure = 17966908.641343933
area = 3.336685073973283e-06
offset = [-0.0021274781941819534, -0.0007711551929593986]
[loads]
tip_force = [0.0046825961503964425, 0.008368720958967861, -0.002364326514424756]
"""
    )
    assert curled.solve().converged
    for steps in (8, 12, 24):
        with pytest.raises(softrod.ParameterError) as info:
            curled.solve(steps=steps)
        assert info.value.parameter == "steps", str(info.value)


def _helix_rod() -> softrod.Rod:
    return softrod.Rod(0.4, softrod.CircularSection(5e-3), softrod.LinearElastic(5e6, 0.3))


@pytest.mark.parametrize("pitch", [0.02, 0.005])
def test_a_helical_tendon_the_default_mesh_cannot_follow_is_solved_on_a_finer_one(pitch):
    # A helix of 20 or 80 turns on a 0.4 m rod: on the 40-step mesh each step turns the routing
    # by pi or 4 pi and RK4 misses its loads (tip 4e-5 m and 2.3e-2 m off, reported converged);
    # the mesh control counts the routing's turn as it counts the backbone's. Oracle: the
    # adaptive integrator (error-controlled Dormand-Prince).
    tendon = [softrod.Tendon.helical(2e-3, pitch, 1.0)]
    got = softrod.solve_statics(_helix_rod(), tendon)
    ref = softrod.solve_statics(_helix_rod(), tendon, integrator="adaptive", rtol=1e-10, atol=1e-12)
    assert len(got.s) > 41
    assert np.linalg.norm(got.tip_position - ref.tip_position) < 1e-7 * 0.4
    assert np.isfinite(got.tendon_displacements).all()


def _helix_function(radius: float, pitch: float, tension: float) -> softrod.Tendon:
    w = 2.0 * np.pi / pitch
    return softrod.Tendon(
        lambda s: (radius * np.cos(w * s), radius * np.sin(w * s)),
        tension,
        derivative=lambda s: (-radius * w * np.sin(w * s), radius * w * np.cos(w * s)),
    )


@pytest.mark.parametrize("pitch", [0.02, 0.005])
def test_a_routing_function_the_default_mesh_cannot_follow_is_solved_on_a_finer_one(pitch):
    # The same helices given as a routing function: the mesh control did not inspect it and
    # the 40 steps came back 4.1e-5 m and 2.4e-2 m off, reported converged. Its rate
    # |r'| / |r| is now counted on every step. Oracles: the adaptive integrator, and the
    # closed-form helix's solve (the same routing, the same mesh chosen).
    tendon = [_helix_function(2e-3, pitch, 1.0)]
    got = softrod.solve_statics(_helix_rod(), tendon)
    ref = softrod.solve_statics(_helix_rod(), tendon, integrator="adaptive", rtol=1e-10, atol=1e-12)
    helix = softrod.solve_statics(_helix_rod(), [softrod.Tendon.helical(2e-3, pitch, 1.0)])
    assert len(got.s) == len(helix.s) > 41
    assert np.linalg.norm(got.tip_position - ref.tip_position) < 1e-7 * 0.4
    assert np.linalg.norm(got.tip_position - helix.tip_position) < 1e-12


def test_a_routing_function_crossing_the_backbone_keeps_the_default_mesh():
    # Its rate is |r'| over its largest distance from the backbone, not over the distance
    # where it is (infinite at the crossing: a straight tendon moved across the rod was
    # refused on every mesh). Oracle: the adaptive integrator.
    length, rho = 0.4, 2e-3
    for side in (0.0, 1e-5):
        tendon = softrod.Tendon(
            lambda s, side=side: (rho * (1.0 - 2.0 * s / length), side),
            1.0,
            derivative=lambda s: (-2.0 * rho / length, 0.0),
        )
        got = softrod.solve_statics(_helix_rod(), [tendon])
        ref = softrod.solve_statics(
            _helix_rod(), [tendon], integrator="adaptive", rtol=1e-10, atol=1e-12
        )
        assert got.steps == 40
        assert np.linalg.norm(got.tip_position - ref.tip_position) < 1e-8 * length


@pytest.mark.parametrize("pitch", [1e-3, 1e-4, 1e-6])
def test_a_routing_function_no_rk4_mesh_can_follow_is_refused_naming_steps(pitch):
    # 400 to 4e5 turns given as a function, which the mesh control did not inspect: refused
    # on every mesh like a closed-form helix no mesh can follow (the test below). From 4,000
    # turns the check of the derivative refused the (right) derivative: its differences, with
    # a step of 1e-6 of the length, could not follow the offset.
    tendon = [_helix_function(2e-3, pitch, 1.0)]
    for kw in ({}, {"steps": 640}):
        with pytest.raises(softrod.ParameterError, match="adaptive") as e:
            softrod.solve_statics(_helix_rod(), tendon, **kw)
        assert e.value.parameter == "steps"


@pytest.mark.parametrize("pitch", [1e-6, 1e-300])
def test_a_helix_no_rk4_mesh_can_follow_is_refused_naming_steps(pitch):
    # 4e5 turns and more (1e-300: an infinite tendon, whose displacement was NaN, reported
    # converged): refused on the default mesh and on a chosen one.
    tendon = [softrod.Tendon.helical(2e-3, pitch, 1.0)]
    for kw in ({}, {"steps": 640}):
        with pytest.raises(softrod.ParameterError, match="steps") as e:
            softrod.solve_statics(_helix_rod(), tendon, **kw)
        assert e.value.parameter == "steps"
        assert "adaptive" in str(e.value)


@pytest.mark.parametrize("scale", [1e-30, 1e-20, 1e20])
def test_the_inverse_depends_on_the_ratios_of_its_weights_only(scale):
    # Minimising sum w_i a_i^2 has the same minimiser for every common factor of the weights;
    # with [1e-20] * 6 the step test, in the weighted norm, stopped the iteration early and a
    # reachable target was reported unreachable (1.6e-9 m; 0.2 m with 1e-30).
    robot = softrod.examples.load("niti_two_segment")
    target = 0.9 * robot.solve().tip_position
    weights = [1.0, 2.0, 1.0, 3.0, 1.0, 2.0]
    ref = softrod.inverse_statics(robot, target, weights=weights)
    got = softrod.inverse_statics(robot, target, weights=[scale * w for w in weights])
    assert got.position_error < 1e-9
    np.testing.assert_allclose(got.tensions, ref.tensions, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("radius", [3e-4, 5e-4, 6e-4, 6.5e-4, 7e-4])
@pytest.mark.parametrize("z", [0.05, 0.1234])
def test_a_sphere_around_the_rod_at_rest_is_refused_whatever_its_size(radius, z):
    # The check sampled the rest backbone at points about 1.6 mm apart: a sphere of radius
    # 0.6 mm centred on it fell between two samples, and the solve went on (a bare
    # ConvergenceError unactuated, a converged answer through the sphere actuated). The
    # backbone's arcs between the nodes are now searched for their least gap.
    robot = softrod.examples.load("niti_two_segment")
    sphere = softrod.Sphere((0.0, 0.0, z), radius)
    for tensions in (np.zeros(6), None):
        with pytest.raises(softrod.ParameterError, match="clear of the rod at rest") as e:
            robot.solve(tensions, obstacles=[sphere])
        assert e.value.parameter == "obstacles[0]"
        # The depth reported is the sphere's radius (its centre is on the backbone) where the
        # backbone passes its centre.
        depth, s = (
            float(v)
            for v in re.search(r"lies (\S+) m inside it at s = (\S+) m", str(e.value)).groups()
        )
        assert depth == pytest.approx(radius, rel=1e-3)
        assert s == pytest.approx(z, abs=1e-4)


_TRI = TRI_TENDON


def test_an_inverse_meets_its_default_tolerance_on_a_loaded_arm():
    # A tapered silicone arm under gravity, three tendons pulling against each other: the
    # iteration met the target to 4e-11 m, then wandered at 1.2e-10 to 2.4e-10 m (the tips of
    # its warm-started forward solves, converged to the statics' 1e-10 residual, scatter that
    # much) and raised a ConvergenceError after 60 iterations at 1.9e-10 m. Oracle: the
    # tensions found, solved cold, reach the target.
    robot = softrod.Robot.from_toml(_TRI)
    target = [0.05, 0.0, 0.24]
    inv = softrod.inverse_statics(robot, target)
    assert inv.converged and inv.position_error <= 1e-10
    assert inv.iterations < 20
    tip = robot.solve(inv.tensions).tip_position
    assert np.linalg.norm(tip - target) < 1e-10


@pytest.mark.parametrize("p", [0.0, -0.5e-3, -0.999e-3])
def test_a_plane_cutting_the_rod_s_surface_at_rest_is_refused(p):
    # The backbone outside the plane, the rod's surface (radius 1 mm) inside it: answers
    # "converged" with the surface still 1 mm through the plane, or a ConvergenceError after 0
    # iterations unloaded. A plate through the base, normal to the rod, stays allowed.
    rod = softrod.Rod(1.0, softrod.CircularSection(1e-3), softrod.LinearElastic(2e9, 0.3))
    plane = softrod.Plane((p, 0.0, 0.0), (1.0, 0.0, 0.0))
    for loads in (softrod.Loads(), softrod.Loads(tip_force=(-1e-6, 0.0, 0.0))):
        with pytest.raises(softrod.ParameterError, match="surface lies") as e:
            softrod.solve_statics(rod, loads=loads, obstacles=[plane])
        assert e.value.parameter == "obstacles[0]"
    plate = softrod.Plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    pushed = softrod.Loads(tip_force=(1e-3, 0.0, 0.0))
    sol = softrod.solve_statics(rod, loads=pushed, obstacles=[plate])
    assert sol.converged and not sol.contacts


def test_a_failed_march_of_a_constrained_solve_is_said_once():
    # A slide plane 4 m beyond a 1 m rod's tip: "... did not converge after 38 iterations
    # (residual inf) did not converge after 0 iterations (residual inf)".
    rod = softrod.Rod(1.0, softrod.CircularSection(1e-3), softrod.LinearElastic(2e9, 0.3))
    with pytest.raises(softrod.ConvergenceError) as e:
        softrod.solve_statics(rod, tip_constraint=softrod.Slide((0.0, 0.0, 5.0), (0.0, 0.0, 1.0)))
    assert str(e.value).count("did not converge") == 1
    assert "constrained shooting" in str(e.value)
