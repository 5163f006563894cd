"""softrod.sweep: labelled design x actuation sweeps. Oracles: single solves of the same robots
(``Robot.solve`` with the documented warm-start rule), the core's compliance at mesh nodes,
NetCDF round trips, and independence of the scheduler and the chunking, bit for bit."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import xarray as xr

import softrod
from softrod.analysis.sweep import STATUS


def niti():
    return softrod.examples.load("niti_two_segment")


def loaded_niti():
    return niti().with_parameters({"loads.tip_force": [0.0, 0.05, -0.1]})


def test_grid_sweep_equals_single_solves_under_the_warm_start_rule():
    robot = loaded_niti()
    t0, t4 = np.linspace(0.0, 2.0, 5), np.linspace(0.0, 1.5, 4)
    block = 6
    ds = softrod.sweep(
        robot,
        actuation={"tendons[0].tension": t0, "tendons[4].tension": t4},
        outputs=("tip_pose", "tendon_lengths", "convergence"),
        block=block,
        progress=False,
    )
    assert ds["tip_position"].dims == ("tendons[0].tension", "tendons[4].tension", "xyz")
    assert ds["tip_position"].attrs["units"] == "m"
    assert ds["tendons[0].tension"].attrs["units"] == "N"
    # The rule: boustrophedon order, blocks of `block`, cold at block starts.
    order = [(i, j if i % 2 == 0 else len(t4) - 1 - j) for i in range(len(t0)) for j in range(4)]
    prev = None
    base = [t.tension for t in robot.tendons]
    for k, (i, j) in enumerate(order):
        tensions = list(base)
        tensions[0], tensions[4] = t0[i], t4[j]
        warm = {} if k % block == 0 or prev is None else {"warm_start": prev}
        sol = robot.solve(tensions=tensions, **warm)
        got = ds.isel({"tendons[0].tension": i, "tendons[4].tension": j})
        assert np.array_equal(got["tip_position"].values, sol.tip_position), (i, j)
        assert np.array_equal(got["tip_quaternion"].values, sol.quaternion[-1])
        assert np.array_equal(got["tendon_lengths"].values, sol.tendon_lengths)
        assert int(got["iterations"]) == sol.stats["iterations"]
        assert int(got["status"]) == STATUS["converged"]
        prev = sol
    assert (ds["error"] == "").all()
    assert ds.attrs["actuation_dims"] == "tendons[0].tension tendons[4].tension"
    assert ds.attrs["softrod_version"] == softrod.__version__
    assert softrod.load_robot  # the robot file round-trips through the attrs
    assert softrod.Robot.from_toml(ds.attrs["robot"]) == robot


def test_chambers_and_pressures_are_swept_like_tendons():
    robot = softrod.examples.load("pneumatic_arm")
    p = np.linspace(0.0, 3e4, 3)
    ds = softrod.sweep(
        robot,
        actuation={"chambers[0].pressure": p, "chambers[2].pressure": p},
        outputs=("tip_pose", "gamma_c"),
        progress=False,
    )
    assert ds["chambers[0].pressure"].attrs["units"] == "Pa"
    base = [c.pressure for c in robot.chambers]
    for i, a in enumerate(p):
        for j, b in enumerate(p):
            pressures = list(base)
            pressures[0], pressures[2] = a, b
            sol = robot.solve(pressures=pressures)
            got = ds.isel({"chambers[0].pressure": i, "chambers[2].pressure": j})
            assert np.array_equal(got["tip_position"].values, sol.tip_position)
            # gamma_c at the tip (arm_index 1) is the compliance's at the last node.
            g = softrod.compliance(sol).gamma_c[-1]
            np.testing.assert_allclose(got["gamma_c"].values[0], g, rtol=1e-12)
    # The pressures move the tip.
    tips = ds["tip_position"].values.reshape(-1, 3)
    assert np.ptp(tips[:, 0]) > 1e-3


def test_tip_loads_are_swept_like_the_file_s_loads():
    robot = niti().with_parameters({"loads.tip_moment": [0.0, 0.0, 0.002]})
    fy = [0.0, 0.02, 0.05]
    ds = softrod.sweep(robot, actuation={"loads.tip_force[1]": fy}, block=1, progress=False)
    assert ds["loads.tip_force[1]"].attrs["units"] == "N"
    for i, f in enumerate(fy):
        loaded = robot.with_parameters({"loads.tip_force": [0.0, f, 0.0]})
        sol = loaded.solve()  # cold, like every sample with block=1
        assert np.array_equal(ds["tip_position"].values[i], sol.tip_position), f


def test_tables_give_a_sample_and_a_design_dimension():
    pd = pytest.importorskip("pandas")
    robot = niti()
    table = pd.DataFrame({"tendons[0].tension": [0.0, 1.0, 2.0], "tendons[1].tension": [0.5, 0, 1]})
    design = softrod.samples({"rod.section.radius": [0.7e-3, 0.8e-3]})
    ds = softrod.sweep(robot, actuation=table, design=design, progress=False)
    assert ds["tip_position"].dims == ("design", "sample", "xyz")
    assert list(ds["tendons[1].tension"].values) == [0.5, 0.0, 1.0]
    stiff = robot.with_parameters({"rod.section.radius": 0.8e-3})
    sol = stiff.solve(tensions=[2.0, 1.0, *[t.tension for t in robot.tendons][2:]])
    assert np.array_equal(ds["tip_position"].values[1, 2], sol.tip_position)
    with pytest.raises(softrod.ParameterError, match="rows like the others"):
        softrod.samples({"tendons[0].tension": [0.0, 1.0], "tendons[1].tension": [0.0]})


def test_values_at_arc_lengths_are_the_compliance_at_the_mesh_nodes():
    robot = niti()
    ds = softrod.sweep(
        robot,
        actuation={"tendons[0].tension": [0.5, 2.0]},
        outputs=("backbone", "compliance", "stiffness", "eigen_stiffness"),
        arc_lengths=[0.2, 0.4],  # the segment-1 tendon ends at 0.2 m: a node
        progress=False,
    )
    assert ds["compliance"].dims == ("tendons[0].tension", "s", "twist", "wrench")
    tensions = [2.0, *[t.tension for t in robot.tendons][1:]]
    sol = robot.solve(tensions=tensions)
    c = softrod.compliance(sol)
    node = np.flatnonzero(sol.s == 0.2)[-1]
    got = ds.sel({"tendons[0].tension": 2.0})
    assert np.array_equal(got["compliance"].sel(s=0.2).values, c.world[node])
    assert np.array_equal(got["compliance"].sel(s=0.4).values, c.world[-1])
    assert np.array_equal(got["backbone_position"].sel(s=0.2).values, sol.position[node])
    k = got["stiffness"].sel(s=0.4).values
    np.testing.assert_allclose(k @ c.world[-1], np.eye(6), atol=1e-8)
    np.testing.assert_allclose(
        got["eigen_stiffness"].sel(s=0.4).values,
        softrod.eigenscrews(k, "stiffness").values,
        rtol=1e-12,
    )


def test_infeasible_designs_complete_and_are_marked():
    arm = softrod.examples.load("tapered_cable_arm").with_parameters(
        {"solver": {"integrator": "rk4", "steps": 30}}
    )
    ds = softrod.sweep(
        arm,
        actuation={"tendons[0].tension": [0.0, 1.0]},
        design={"rod.section.tip_radius": [0.0, 0.006], "tendons[0].ratio": [0.3, 1.2]},
        progress=False,
    )
    status = ds["design_status"]
    assert status.sel({"rod.section.tip_radius": 0.006, "tendons[0].ratio": 0.3}) == 0
    assert int(status.sum()) == 3
    bad = ds.sel({"rod.section.tip_radius": 0.0, "tendons[0].ratio": 0.3})
    assert (bad["status"] == STATUS["infeasible_design"]).all()
    assert np.isnan(bad["tip_position"]).all()
    assert "rod.section.tip_radius" in str(bad["design_error"].values)
    outside = ds.sel({"rod.section.tip_radius": 0.006, "tendons[0].ratio": 1.2})
    assert "tendons[0].ratio" in str(outside["design_error"].values)
    ok = ds.sel({"rod.section.tip_radius": 0.006, "tendons[0].ratio": 0.3})
    assert (ok["status"] == 0).all() and np.isfinite(ok["tip_position"]).all()


def test_failed_samples_are_recorded_not_dropped():
    # A thin, strongly tapered arm curls into itself at high tension: the solver reports it.
    arm = softrod.examples.load("tapered_cable_arm").with_parameters(
        {
            "solver": {"integrator": "rk4", "steps": 40},
            "rod.section.tip_radius": 0.004,
            "tendons[0].ratio": 0.5,
        }
    )
    ds = softrod.sweep(arm, actuation={"tendons[0].tension": np.linspace(0, 3, 31)}, progress=False)
    failed = ds["status"] != 0
    assert 0 < int(failed.sum()) < 31
    assert set(ds["error"].values[failed.values]) == {"ConvergenceError"}
    assert np.isnan(ds["tip_position"].values[failed.values]).all()
    # The same solve alone, without raising, does not panic either. (A sweep solves on the
    # mesh given; the first failing tension, 2.7 N, converges alone: a failure of the default
    # mesh is tried again on a finer one. The largest fails on every mesh.)
    t = float(ds["tendons[0].tension"][failed.values][-1])
    assert not arm.solve(tensions=[t], throw=False).converged


def test_netcdf_round_trip(tmp_path):
    ds = softrod.sweep(
        niti(),
        actuation={"tendons[0].tension": [0.0, 1.0, 2.0]},
        design={"rod.material.youngs_modulus": [50e9, 60e9]},
        outputs=("tip_pose", "compliance", "gamma_c", "convergence"),
        arm_index=[0.5, 1.0],
        progress=False,
    )
    path = tmp_path / "study.nc"
    ds.to_netcdf(path)
    with xr.open_dataset(path) as back:
        back = back.load()
    xr.testing.assert_identical(ds, back)
    assert back["compliance"].attrs["long_name"].startswith("integrated compliance")


def test_results_do_not_depend_on_the_chunking():
    kw = dict(
        actuation={"tendons[0].tension": np.linspace(0, 2, 9), "tendons[1].tension": [0, 0.5]},
        design={"rod.section.radius": [0.7e-3, 0.75e-3]},
        outputs=("tip_pose", "translational_compliance", "convergence"),
        block=4,
        progress=False,
    )
    a = softrod.sweep(loaded_niti(), **kw)
    b = softrod.sweep(loaded_niti(), chunk=1, **kw)  # one block per task
    c = softrod.sweep(loaded_niti(), chunk=7, **kw)  # rounded up to 8
    xr.testing.assert_identical(a, b)
    xr.testing.assert_identical(a, c)


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as c:
        yield c


def test_dask_local_cluster_equals_in_process_bit_for_bit(cluster):
    kw = dict(
        actuation={"tendons[0].tension": np.linspace(0, 2, 12), "tendons[4].tension": [0, 1]},
        design={"rod.material.youngs_modulus": [50e9, 54e9, 58e9]},
        outputs=("tip_pose", "compliance", "convergence"),
        arc_lengths=[0.1, 0.4],
        block=8,
        progress=False,
    )
    local = softrod.sweep(loaded_niti(), **kw)
    on_cluster = softrod.sweep(loaded_niti(), scheduler=cluster, chunk=8, **kw)
    xr.testing.assert_identical(local, on_cluster)
    from distributed import Client

    with Client(cluster) as client:
        by_client = softrod.sweep(loaded_niti(), scheduler=client, **kw)
        by_address = softrod.sweep(loaded_niti(), scheduler=cluster.scheduler_address, **kw)
    xr.testing.assert_identical(local, by_client)
    xr.testing.assert_identical(local, by_address)


def test_bad_arguments_are_named():
    robot = niti()
    cases = [
        (dict(actuation={"tendons[9].tension": [0.0]}), "tendon index"),
        (dict(actuation={"rod.length": [0.3]}), "actuation path"),
        (dict(actuation={"tendons[0].tension": [-1.0]}), "tendons\\[0\\].tension"),
        (dict(actuation={"tendons[0].tension": [[0.0, 1.0]]}), "1-D grid"),
        (dict(actuation={"tendons[0].tension": [np.nan]}), "finite"),
        (dict(design={"rod.sectoin.radius": [1e-3]}), "did you mean `section`"),
        (dict(outputs=("tip_pos",)), "did you mean 'tip_pose'"),
        (dict(actuation={"tendons[0].displacement": [0.0]}), "displacement"),
        (dict(arc_lengths=[0.5]), "in \\[0, 0.4\\] m"),
        (dict(arc_lengths=[0.1], arm_index=[1.0]), "arm_index"),
        (dict(scheduler="not an address"), "scheduler"),
        (dict(block=0), "block"),
        (dict(chunk=2.5), "chunk"),
    ]
    for kwargs, match in cases:
        with pytest.raises(softrod.ParameterError, match=match):
            softrod.sweep(robot, progress=False, **kwargs)
    with pytest.raises(TypeError, match="robot"):
        softrod.sweep("niti_two_segment")


def test_killing_a_dask_worker_loses_no_sample():
    import os
    import signal
    import threading
    import time

    distributed = pytest.importorskip("distributed")
    arm = softrod.examples.load("tapered_cable_arm")
    kw = dict(
        actuation={"tendons[0].tension": np.linspace(0.0, 2.0, 1024)},
        design={"tendons[0].ratio": np.linspace(0.1, 0.5, 24)},
        outputs=("tip_pose", "convergence"),
        progress=False,
    )
    local = softrod.sweep(arm, **kw)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as c,
        distributed.Client(c) as client,
    ):
        result = {}

        def run():
            result["ds"] = softrod.sweep(arm, scheduler=client, chunk=256, **kw)

        thread = threading.Thread(target=run)
        thread.start()
        # Kill a worker while it runs a task, once the sweep has been going for a while.
        victim, started = None, None
        deadline = time.monotonic() + 60
        while victim is None and time.monotonic() < deadline:
            busy = [w for w, tasks in client.processing().items() if tasks]
            if busy and started is None:
                started = time.monotonic()
            if busy and time.monotonic() - started > 0.5:
                victim = busy[0]
            else:
                time.sleep(0.02)
        assert victim is not None and thread.is_alive(), "the sweep ended before the kill"
        pid = client.run(os.getpid, workers=[victim])[victim]
        os.kill(pid, signal.SIGKILL)
        thread.join(timeout=300)
        assert not thread.is_alive()
        assert victim not in client.scheduler_info()["workers"]
    ds = result["ds"]
    assert (ds["status"] >= 0).all() and int((ds["status"] == 0).sum()) > 0
    xr.testing.assert_identical(local, ds)


def test_arc_lengths_are_checked_against_the_design_lengths():
    robot = niti()  # 0.4 m long
    # beyond the shortest design rod: refused before any solve, naming the shortest length
    for design in ({"rod.length": [0.3, 0.4]}, softrod.samples({"rod.length": [0.4, 0.3]})):
        with pytest.raises(softrod.ParameterError, match=r"rod.length = 0\.3 m") as info:
            softrod.sweep(
                robot, design=design, outputs=["backbone"], arc_lengths=[0.35], progress=False
            )
        assert info.value.parameter == "arc_lengths" and "0.35" in str(info.value)
    # within every design rod, though beyond the robot's own 0.4 m: solved
    ds = softrod.sweep(
        robot,
        design={"rod.length": [0.45, 0.5]},
        outputs=["backbone"],
        arc_lengths=[0.42],
        progress=False,
    )
    assert (ds["status"] == 0).all() and np.isfinite(ds["backbone_position"]).all()


def test_a_sample_whose_arc_length_is_beyond_its_rod_is_failed_not_converged():
    # A design point whose rod is shorter than an arc length (a path the up-front check does
    # not see): every sample fails, naming arc_lengths; never status 0 with NaN outputs.
    from softrod.analysis import _sweep_run as run

    spec = run.TaskSpec(axes=(), outputs=("backbone",), arc_lengths=(0.35,), arm_index=(), block=4)
    pieces = [
        run.Piece(0, {"rod.length": 0.3}, 0, 2, np.zeros((2, 0))),
        run.Piece(1, {"rod.length": 0.4}, 0, 2, np.zeros((2, 0))),
    ]
    short, long = run.run_task(niti(), spec, pieces, False)
    assert list(short["status"]) == [STATUS["failed"]] * 2
    assert all("arc_lengths" in e for e in short["error"])
    assert list(long["status"]) == [0, 0] and np.isfinite(long["backbone_position"]).all()


CURLED_ARM = """
name = "curled"
[rod]
length = 0.4
[rod.section]
type = "tapered"
base_radius = 0.0055
tip_radius = 0.0013
[rod.material]
type = "neo_hookean"
mu = 0.25e6
[[chambers]]
pressure = 2.3e6
area = 1.5205308443374597e-07
offset = [0.00065, 0.0]
"""


def test_a_curl_the_default_mesh_cannot_resolve_is_swept_on_a_finer_one():
    # A tapered Neo-Hookean arm curled one to two turns by its chamber, to several hundred
    # 1/m at its thin tip: the default 40 RK4 steps turn by radians a step there. Swept, each
    # sample was solved on the default mesh alone and reported converged 2.5e-4 m (2.3 MPa)
    # to 1.0e-2 m (5 MPa) from the tip; `Robot.solve` refines such a mesh. Oracle: the
    # adaptive integrator at rtol 1e-10; bound: the default mesh's accuracy, 1e-4 L.
    robot = softrod.Robot.from_toml(CURLED_ARM)
    pressures = [2.3e6, 3e6, 4e6, 5e6]
    ds = softrod.sweep(robot, actuation={"chambers[0].pressure": pressures}, progress=False)
    for i, p in enumerate(pressures):
        arm = robot.with_pressures([p])
        ref = arm.solve(integrator="adaptive", rtol=1e-10, atol=1e-12).tip_position
        got = ds["tip_position"].values[i]
        assert int(ds["status"][i]) == STATUS["converged"]
        assert np.linalg.norm(got - ref) <= 1e-4 * 0.4, (p, got, ref)


def test_an_adaptive_robot_s_compliance_is_marched_to_the_arc_lengths():
    # The adaptive integrator's compliance is a controlled march; the sweep stops it at the arc
    # lengths asked (as compliance(sol, s_out=...)), not at every node of the solution (which
    # made the compliance 4x the solve on the tapered arm).
    arm = softrod.examples.load("tapered_cable_arm")
    s = [0.1, 0.2, 0.27]
    ds = softrod.sweep(
        arm,
        actuation={"tendons[0].tension": [0.5, 2.0]},
        outputs=("compliance", "gamma_c", "translational_compliance"),
        arc_lengths=s,
        block=1,
        progress=False,
    )
    for t in (0.5, 2.0):
        sol = arm.solve([t])
        c = softrod.compliance(sol, s_out=s)
        got = ds.sel({"tendons[0].tension": t})
        assert np.array_equal(got["compliance"].values, np.asarray(c.world))
        assert np.array_equal(got["gamma_c"].values, np.asarray(c.gamma_c))
        # Against the compliance at every node: the same to the march's tolerance.
        every = softrod.compliance(sol)
        np.testing.assert_allclose(got["compliance"].values[-1], every.world[-1], rtol=1e-6, atol=0)


def test_the_stability_of_each_sample_is_the_solve_s_own_verdict():
    # A uniform silicone column standing under its own weight: 0.25 m is past its buckling
    # length (0.236 m for r = 6 mm, E = 2 MPa, 1100 kg/m^3), 0.2 m is not. The sweep reported
    # every sample as converged with no flag; `stable` is now each sample's verdict, the one
    # Robot.solve gives (oracle: the same solves, cold like block=1).
    toml = _TRI_COLUMN
    robot = softrod.Robot.from_toml(toml)
    ds = softrod.sweep(
        robot,
        design={"rod.length": [0.2, 0.25]},
        actuation={"tendons[0].tension": [0.0, 0.05]},
        outputs=("tip_pose", "stability"),
        block=1,
        progress=False,
    )
    assert ds["stable"].attrs["flag_meanings"] == "not_converged unstable stable"
    for length in (0.2, 0.25):
        for t in (0.0, 0.05):
            r = robot.with_parameters({"rod.length": length})
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = r.solve([t, 0.0, 0.0])
            at = {"rod.length": length, "tendons[0].tension": t}
            assert int(ds["stable"].sel(at)) == int(sol.stable), (length, t)
            assert np.array_equal(ds["tip_position"].sel(at).values, sol.tip_position)
    # Short of the buckling length: stable. Past it, unpulled: the straight column, unstable
    # (no stable one found from it); pulled by 0.05 N: the buckled, stable one the solve seeks.
    assert int(ds["stable"].sel({"rod.length": 0.2, "tendons[0].tension": 0.0})) == 1
    assert int(ds["stable"].sel({"rod.length": 0.25, "tendons[0].tension": 0.0})) == 0
    assert int(ds["stable"].sel({"rod.length": 0.25, "tendons[0].tension": 0.05})) == 1


_TRI_COLUMN = """
[rod]
length = 0.25
density = 1100.0
[rod.section]
type = "circular"
radius = 0.006
[rod.material]
type = "linear"
youngs_modulus = 2.0e6
poisson_ratio = 0.49
[[tendons]]
distance = 0.004
angle_deg = 0.0
[[tendons]]
distance = 0.004
angle_deg = 120.0
[[tendons]]
distance = 0.004
angle_deg = 240.0
[loads]
gravity = [0.0, 0.0, -9.81]
"""
