"""A live 3-D view of a robot in the browser (viser, on 127.0.0.1).

One slider per tendon tension (N), chamber pressure (kPa) and tip-force component (N, world);
every move re-solves the statics warm-started from the previous solution and redraws the tube,
the tendons, the disks, the chambers, the tip frame and the tip compliance ellipsoid, with the
solver's convergence (and the solution's stability, when the solver reports it). Buttons
download the current configuration: the robot file with the current actuation (TOML), and the
shape (CSV or JSON).

Example:
    >>> view = softrod.plot.live.serve("examples/robots/niti_two_segment.toml", port=8080)
    >>> view.set_actuation(tensions=[2, 0, 0, 0, 1, 0])  # same as moving the sliders
    >>> view.stop()
"""

from __future__ import annotations

import copy
import io
import json
import math
import os
import threading
import time
import webbrowser
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import _args
from .._core import ConvergenceError, ParameterError
from .geometry import RobotGeometry, robot_geometry
from .tube import chamber_grid, disk_polygon, tendon_path, tube_grid, tube_mesh

__all__ = ["LiveView", "RenderTiming", "serve"]

#: Fraction of the rod length the default tip-force range deflects the tip by (linearised).
FORCE_RANGE_DEFLECTION = 0.25
_TENDON_RGB = ((214, 39, 40), (31, 119, 180), (44, 160, 44), (148, 103, 189), (255, 127, 14))


@dataclass
class RenderTiming:
    """Timings of one re-render (s).

    Attributes:
        solve: Wall time of the warm-started solve (and the compliance).
        render: From the end of the solve until the scene updates are sent to the browsers.
        converged: Whether the solve converged.
    """

    solve: float
    render: float
    converged: bool


def _nice(x: float) -> float:
    from ._figure import nice_ceil

    return nice_ceil(x) if x > 0 else 1.0


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def to_toml(data: dict[str, Any], header: str = "") -> str:
    """A robot description (nested tables, arrays of tables, numbers, strings) as TOML."""
    out = [f"# {line}" for line in header.splitlines()] if header else []

    def table(d: dict[str, Any], path: str) -> None:
        scalars = {k: v for k, v in d.items() if not isinstance(v, dict) and not _is_aot(v)}
        for k, v in scalars.items():
            out.append(f"{k} = {_toml_value(v)}")
        for k, v in d.items():
            name = f"{path}.{k}" if path else k
            if isinstance(v, dict):
                out.append(f"\n[{name}]")
                table(v, name)
            elif _is_aot(v):
                for item in v:
                    out.append(f"\n[[{name}]]")
                    table(item, name)

    table(data, "")
    return "\n".join(out) + "\n"


def _is_aot(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


class LiveView:
    """A running live view; :func:`serve` starts one.

    Attributes:
        robot: The robot at the current actuation (:class:`softrod.Robot`).
        solution: The current :class:`softrod.StaticsSolution`.
        url: The page's address (``http://127.0.0.1:PORT``).
        renders: Number of re-renders so far (the first drawing counts as one).
        timings: One :class:`RenderTiming` per re-render.
        last_vertices: Vertices of the tube mesh last sent (m, world), shape (k, 3).
    """

    def __init__(
        self,
        robot,
        *,
        host: str = "127.0.0.1",
        port: int = 8080,
        max_tension: float | None = None,
        max_pressure: float | None = None,
        max_force: float | None = None,
    ):
        import viser

        from ..robot import load_robot

        if isinstance(robot, (str, os.PathLike)):
            robot = load_robot(robot)
        self._base = robot
        self.robot = robot
        self._tensions = np.array([t.tension for t in robot.tendons], dtype=float)
        self._pressures = np.array([c.pressure for c in robot.chambers], dtype=float)
        self._force = np.zeros(3)
        self._lock = threading.RLock()
        self.renders = 0
        self.timings: list[RenderTiming] = []
        self.last_vertices = np.zeros((0, 3))
        self.status = ""
        self.geometry: RobotGeometry = robot_geometry(robot)
        first = robot.solve()
        self.solution = first
        self._compliance = self._tip_compliance(first)
        length = float(robot.rod.length)
        c_max = float(np.linalg.eigvalsh(self._compliance[:3, :3]).max())
        self.max_force = float(
            max_force or _nice(FORCE_RANGE_DEFLECTION * length / max(c_max, 1e-30))
        )
        self.max_tension = float(
            max_tension or _nice(max(2.0 * float(self._tensions.max(initial=0.0)), 1.0))
        )
        top_p = float(self._pressures.max(initial=0.0))
        self.max_pressure = float(max_pressure or _nice(max(2.0 * top_p, 50e3)))
        self._check_port(port)
        self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.url = f"http://{host}:{self.server.get_port()}"
        self._set_camera(first)
        c0 = float(
            np.linalg.eigvalsh(0.5 * (self._compliance[:3, :3] + self._compliance[:3, :3].T)).max()
        )
        #: Force (N) whose tip displacements the ellipsoid shows (a tenth of the rod length
        #: along the largest compliance of the first configuration).
        self.ellipsoid_force = float(_nice(0.1 * length / max(c0, 1e-30)))
        self._build_gui()
        self._render(first, solve_time=0.0)

    def _set_camera(self, sol) -> None:
        """Looks at the rod from the side its bending plane faces (see ``bending_view``)."""
        from .views import bending_view

        p = np.asarray(sol.position)
        centre = 0.5 * (p.min(axis=0) + p.max(axis=0))
        size = max(float(np.ptp(p, axis=0).max()), float(self._base.rod.length))
        normal = bending_view(sol).normal
        self.server.scene.set_up_direction("+z")
        cam = self.server.initial_camera
        cam.position = tuple(centre + 2.2 * size * normal)
        cam.look_at = tuple(centre)
        cam.up = (0.0, 0.0, 1.0)

    # ------------------------------------------------------------------ set-up

    @staticmethod
    def _check_port(port) -> None:
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            err = ParameterError(f"invalid parameter `port` = {port!r}: must be in [0, 65535]")
            err.parameter = "port"
            raise err

    def _tip_compliance(self, sol) -> np.ndarray:
        from .._core import compliance

        try:
            return np.asarray(compliance(sol).tip_world)
        except (ParameterError, ConvergenceError, ValueError):
            return np.full((6, 6), np.nan)

    def _build_gui(self) -> None:
        gui = self.server.gui
        self.sliders: dict[str, Any] = {}
        gui.add_markdown(f"**{self._base.name}** — statics, SI units (m, N, Pa)")
        if len(self._tensions):
            with gui.add_folder("Tendon tensions (N)"):
                for i, t in enumerate(self._tensions):
                    s = gui.add_slider(
                        f"T{i}", 0.0, self.max_tension, self.max_tension / 200, float(t)
                    )
                    s.on_update(lambda _e, i=i, s=s: self._on_tension(i, s.value))
                    self.sliders[f"T{i}"] = s
        if len(self._pressures):
            with gui.add_folder("Chamber pressures (kPa)"):
                for i, p in enumerate(self._pressures):
                    top = self.max_pressure / 1e3
                    s = gui.add_slider(f"P{i}", 0.0, top, top / 200, float(p) / 1e3)
                    s.on_update(lambda _e, i=i, s=s: self._on_pressure(i, s.value * 1e3))
                    self.sliders[f"P{i}"] = s
        self._can_load = bool(getattr(self._base, "source", None))
        with gui.add_folder("Tip force (N, world)"):
            for k, axis in enumerate("xyz"):
                f = self.max_force
                s = gui.add_slider(f"F{axis}", -f, f, f / 200, 0.0, disabled=not self._can_load)
                s.on_update(lambda _e, k=k, s=s: self._on_force(k, s.value))
                self.sliders[f"F{axis}"] = s
        self._status = gui.add_markdown("")
        with gui.add_folder("Export"):
            for kind, label in (
                ("toml", "Robot file (TOML)"),
                ("csv", "Shape (CSV)"),
                ("json", "Shape (JSON)"),
            ):
                b = gui.add_button(label)
                b.on_click(lambda e, kind=kind: self._download(e.client, kind))
        self.server.scene.add_grid(
            "/grid",
            width=2 * float(self._base.rod.length),
            height=2 * float(self._base.rod.length),
            cell_size=float(self._base.rod.length) / 10,
        )

    # ------------------------------------------------------------------ callbacks

    def _on_tension(self, i: int, value: float) -> None:
        t = self._tensions.copy()
        t[i] = value
        self.set_actuation(tensions=t)

    def _on_pressure(self, i: int, value: float) -> None:
        p = self._pressures.copy()
        p[i] = value
        self.set_actuation(pressures=p)

    def _on_force(self, k: int, value: float) -> None:
        f = self._force.copy()
        f[k] = value
        self.set_actuation(tip_force=f)

    def _download(self, client, kind: str) -> None:
        name, content = self.export(kind)
        if client is not None:
            client.send_file_download(name, content)

    # ------------------------------------------------------------------ public API

    def _robot_with(self, tensions, pressures, force):
        robot = self._base
        if np.any(force != 0) and self._can_load:
            robot = type(robot).from_dict(self._source_with(force, None, None), robot.name)
        if len(tensions):
            robot = robot.with_tensions(tensions)
        if len(pressures):
            robot = robot.with_pressures(pressures)
        return robot

    def _source_with(self, force, tensions, pressures) -> dict[str, Any]:
        from .geometry import _plain

        data = copy.deepcopy(dict(_plain(self._base.source)))
        if force is not None:
            loads = dict(data.get("loads", {}))
            base = np.asarray(loads.get("tip_force", [0.0, 0.0, 0.0]), dtype=float)
            if loads.get("tip_frame", "world") != "world" and np.any(force != 0):
                raise ParameterError(
                    "invalid parameter `tip_force`: the robot file's tip load is in the body "
                    "frame; the live view adds world-frame forces only to world-frame tip loads"
                )
            loads["tip_force"] = (base + force).tolist()
            data["loads"] = loads
        if tensions is not None:
            data["tendons"] = [
                {**t, "tension": float(x)}
                for t, x in zip(data.get("tendons", []), tensions, strict=True)
            ]
        if pressures is not None:
            data["chambers"] = [
                {**c, "pressure": float(x)}
                for c, x in zip(data.get("chambers", []), pressures, strict=True)
            ]
        return data

    def set_actuation(self, *, tensions=None, pressures=None, tip_force=None):
        """Re-solves with new actuation (warm-started) and redraws, as the sliders do.

        Args:
            tensions: Tendon tensions (N), one per tendon.
            pressures: Chamber pressures (Pa, gauge), one per chamber.
            tip_force: Extra tip force (N, world frame, shape (3,)), added to the file's.

        Returns:
            The new :class:`softrod.StaticsSolution` (``converged`` False when the solver
            failed: the last converged shape stays on screen and the status says why).
        """
        with self._lock:
            t = self._tensions if tensions is None else np.asarray(tensions, dtype=float)
            p = self._pressures if pressures is None else np.asarray(pressures, dtype=float)
            f = self._force if tip_force is None else np.asarray(tip_force, dtype=float)
            t0 = time.perf_counter()
            robot = self._robot_with(t, p, f)
            try:
                sol = robot.solve(warm_start=self.solution, throw=False)
            except (ConvergenceError, ParameterError) as exc:
                self.status = f"**not solved**: {exc}"
                self._status.content = self.status
                return self.solution
            comp = self._tip_compliance(sol) if sol.converged else self._compliance
            solve_time = time.perf_counter() - t0
            if sol.converged:
                self._tensions, self._pressures, self._force = t, p, f
                self.robot, self.solution, self._compliance = robot, sol, comp
                self.geometry = robot_geometry(robot)
            self._render(sol if sol.converged else self.solution, solve_time, sol)
            return sol

    def export(self, kind: str) -> tuple[str, bytes]:
        """The current configuration as a file: ``"toml"`` (the robot description with the
        current tensions, pressures and tip force: ``softrod solve`` reproduces the shape),
        ``"csv"`` or ``"json"`` (the solution's samples, SI units, world frame).

        Returns:
            ``(file name, content)``.
        """
        from ..io import statics_to_dict

        with self._lock:
            stem = self._base.name
            if kind == "toml":
                if not self._can_load:
                    raise ParameterError(
                        "invalid parameter `kind` = 'toml': the robot has no description "
                        "(`Robot.source`) to write"
                    )
                data = self._source_with(self._force, self._tensions, self._pressures)
                head = (
                    f"{stem}: configuration exported from the live view\n"
                    f"tensions (N) {self._tensions.tolist()}, pressures (Pa) "
                    f"{self._pressures.tolist()}, added tip force (N, world) "
                    f"{self._force.tolist()}"
                )
                return f"{stem}-configuration.toml", to_toml(data, head).encode()
            if kind == "csv":
                from ..io import write_statics_csv

                buf = io.StringIO()
                write_statics_csv(buf, self.solution)
                return f"{stem}-shape.csv", buf.getvalue().encode()
            if kind == "json":
                body = {
                    "robot": stem,
                    "tensions": self._tensions.tolist(),
                    "pressures": self._pressures.tolist(),
                    "tip_force": self._force.tolist(),
                    "solution": statics_to_dict(self.solution),
                }
                return f"{stem}-shape.json", json.dumps(body).encode()
        err = ParameterError(f"invalid parameter `kind` = {kind!r}: must be toml, csv or json")
        err.parameter = "kind"
        raise err

    def stop(self) -> None:
        """Stops the server (the page stops updating)."""
        self.server.stop()

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    # ------------------------------------------------------------------ drawing

    def _render(self, sol, solve_time: float, attempted=None) -> None:
        t1 = time.perf_counter()
        scene = self.server.scene
        geom = self.geometry
        length = float(self._base.rod.length)
        with self.server.atomic():
            if geom.radius is not None:
                r = np.maximum(geom.radius(np.asarray(sol.s)), 2e-3 * length)
                vertices, faces = tube_mesh(tube_grid(sol, r, n_around=24))
                scene.add_mesh_simple(
                    "/robot/tube",
                    vertices,
                    faces,
                    color=(201, 162, 126),
                    opacity=0.55 if geom.chambers else None,
                    side="double",
                )
                self.last_vertices = vertices
            else:
                pts = np.asarray(sol.position)
                scene.add_spline_catmull_rom(
                    "/robot/tube", pts, thickness=3.0, thickness_units="screen"
                )
                self.last_vertices = pts
            for i, t in enumerate(geom.tendons):
                q = tendon_path(sol, t)
                seg = np.stack((q[:-1], q[1:]), axis=1)
                color = (150, 150, 150) if t.tension <= 0 else _TENDON_RGB[i % len(_TENDON_RGB)]
                scene.add_line_segments(
                    f"/robot/tendon{i}", seg, color, thickness=2.5, thickness_units="screen"
                )
            for k, s in enumerate(geom.disks):
                rim = disk_polygon(sol, s, geom.disk_radius, n=40)
                centre = rim.mean(axis=0)
                v = np.vstack((centre, rim))
                n = len(rim)
                f = np.array([[0, 1 + j, 1 + (j + 1) % n] for j in range(n)], dtype=np.uint32)
                scene.add_mesh_simple(
                    f"/robot/disk{k}", v, f, color=(190, 190, 200), opacity=0.7, side="double"
                )
            pmax = max(float(self._pressures.max(initial=0.0)), 1.0)
            for k, c in enumerate(geom.chambers):
                cv, cf = tube_mesh(chamber_grid(sol, c, n_around=12))
                shade = max(c.pressure, 0.0) / pmax
                color = (255, int(230 - 180 * shade), int(120 - 100 * shade))
                scene.add_mesh_simple(f"/robot/chamber{k}", cv, cf, color=color)
            q = np.asarray(sol.quaternion)[-1]  # [x, y, z, w]
            tip = np.asarray(sol.tip_position)
            scene.add_frame(
                "/robot/tip",
                wxyz=(q[3], q[0], q[1], q[2]),
                position=tip,
                axes_length=0.12 * length,
                axes_radius=0.006 * length,
            )
            self._draw_ellipsoid(tip)
            self.renders += 1
            converged = attempted is None or attempted.converged
            self._status.content = self._status_text(attempted or sol, solve_time)
        self.server.flush()
        render = time.perf_counter() - t1
        self.timings.append(RenderTiming(solve_time, render, bool(converged)))

    def _draw_ellipsoid(self, tip: np.ndarray) -> None:
        c = self._compliance[:3, :3]
        if not np.all(np.isfinite(c)):
            return
        w, v = np.linalg.eigh(0.5 * (c + c.T))
        axes = np.clip(w, 0, None) * self.ellipsoid_force  # tip displacement (m) under |f|
        n = 24
        uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, n + 1), np.linspace(0, np.pi, n // 2 + 1))
        sphere = np.stack((np.cos(uu) * np.sin(vv), np.sin(uu) * np.sin(vv), np.cos(vv)), -1)
        grid = tip + (sphere * axes) @ v.T
        verts, faces = tube_mesh(grid)
        self.server.scene.add_mesh_simple(
            "/robot/compliance", verts, faces, color=(68, 1, 84), opacity=0.25, side="double"
        )

    def _status_text(self, sol, solve_time: float) -> str:
        st = dict(sol.stats)
        ok = "converged" if sol.converged else "**NOT converged** (last converged shape shown)"
        lines = [
            f"**solver**: {ok}, {st.get('iterations', '?')} iterations, residual "
            f"{float(st.get('residual', math.nan)):.1e}, solve {solve_time * 1e3:.1f} ms",
        ]
        stable = getattr(sol, "stable", None)
        if stable is not None:
            lines.append(f"**stability**: {'stable' if stable else '**UNSTABLE** equilibrium'}")
        else:
            lines.append("**stability**: not reported by this solver")
        tip = np.asarray(self.solution.tip_position) * 1e3
        lines.append(f"**tip** (mm): ({tip[0]:.2f}, {tip[1]:.2f}, {tip[2]:.2f})")
        c = float(
            np.linalg.eigvalsh(0.5 * (self._compliance[:3, :3] + self._compliance[:3, :3].T)).max()
        )
        lines.append(
            f"**ellipsoid**: tip displacements under |f| = {self.ellipsoid_force:.3g} N "
            f"(largest compliance {c:.3g} m/N)"
        )
        return "\n\n".join(lines)


def serve(
    robot,
    *,
    port: int = 8080,
    open_browser: bool = True,
    host: str = "127.0.0.1",
    max_tension: float | None = None,
    max_pressure: float | None = None,
    max_force: float | None = None,
) -> LiveView:
    """Starts the live view of a robot and returns its handle (``.stop()`` ends it).

    Args:
        robot: A :class:`softrod.Robot` or the path of a robot file (TOML).
        port: TCP port on ``host`` (0: any free port; the handle's ``url`` tells).
        open_browser: Open the page in the default browser.
        host: Interface to listen on (the default serves this machine only).
        max_tension: Top of the tension sliders (N; default twice the largest tension, at
            least 1 N).
        max_pressure: Top of the pressure sliders (Pa; default twice the largest pressure, at
            least 50 kPa).
        max_force: Range of the tip-force sliders (N; default the force that deflects the tip
            by a quarter of the rod length at the starting compliance).

    Returns:
        The running :class:`LiveView`.

    Raises:
        ParameterError: A slider range that is not a finite number > 0 (naming it).
    """
    units = {"max_tension": "N", "max_pressure": "Pa", "max_force": "N"}
    given = {"max_tension": max_tension, "max_pressure": max_pressure, "max_force": max_force}
    for name, value in given.items():
        if value is not None:
            _args.number(value, name, positive=True, unit=units[name])
    view = LiveView(
        robot,
        host=host,
        port=port,
        max_tension=max_tension,
        max_pressure=max_pressure,
        max_force=max_force,
    )
    if open_browser:
        webbrowser.open(view.url)
    return view
