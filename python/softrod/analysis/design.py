"""Summaries of a sweep for design: the reachable workspace, stiffness over it, the
centre-to-periphery compliance ratio, and the Pareto front of two objectives.

:func:`design_summary` reduces the actuation dimensions of a :func:`softrod.sweep` result,
design point by design point, over its converged samples:

* the convex hull of the tip positions (``scipy.spatial.ConvexHull``): its volume (m³) when
  the points span 3-D, else the area (m²) of the hull in their plane (a planar arm);
* a voxel measure: the number of cubes (squares in a plane) of edge ``voxel`` that contain a
  tip, times the cube's volume (the square's area), which does not fill the concavities a
  hull bridges;
* statistics of the tip stiffness in the softest direction, ``1 / c_max`` with ``c_max`` the
  largest principal translational compliance (N/m), over the workspace;
* the centre-to-periphery compliance ratio of *A Configuration-based Compliance Modelling and
  Analysis Methodology for Soft Continuum Robots*: ``c_max`` at the tip farthest from the
  robot's axis over ``c_max`` at the tip nearest to it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from .._core import ParameterError

__all__ = ["Pareto", "design_summary", "workspace_measures"]

#: Relative size of the smallest singular value of the centred points below which they are
#: taken to lie in a plane (or on a line).
FLATNESS = 1e-6
#: Default voxel edge: this fraction of the diagonal of the bounding box of every tip in the
#: sweep (the same edge for every design point, so the measures compare).
VOXEL_FRACTION = 0.02


def _bad(name: str, value: Any, expected: str) -> ParameterError:
    exc = ParameterError(f"invalid parameter `{name}` = {value!r}: must be {expected}")
    exc.parameter = name
    return exc


def workspace_measures(points: np.ndarray, voxel: float) -> dict[str, float]:
    """Hull and voxel measures of a set of points.

    Args:
        points: Positions (m), shape (n, 3); non-finite rows are ignored.
        voxel: Edge of the voxels (m, > 0).

    Returns:
        ``dimension`` (0 to 3: the dimension the points span), ``hull_volume`` (m³, 0 unless
        3-D), ``hull_area`` (m², the planar hull's area; NaN when 3-D), ``voxel_volume``
        (m³, NaN unless 3-D), ``voxel_area`` (m², NaN when 3-D) and ``count``.
    """
    from scipy.spatial import ConvexHull, QhullError

    p = np.asarray(points, dtype=float).reshape(-1, 3)
    p = p[np.all(np.isfinite(p), axis=1)]
    out = {
        "dimension": 0,
        "hull_volume": 0.0,
        "hull_area": 0.0,
        "voxel_volume": np.nan,
        "voxel_area": 0.0,
        "count": len(p),
    }
    if len(p) == 0:
        out.update(hull_volume=np.nan, hull_area=np.nan, voxel_area=np.nan)
        return out
    centred = p - p.mean(axis=0)
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    scale = sv[0] if sv.size else 0.0
    dim = int(np.sum(sv > FLATNESS * scale)) if scale > 0 else 0
    out["dimension"] = dim
    if dim == 3:
        try:
            out["hull_volume"] = float(ConvexHull(p).volume)
        except QhullError:
            out["hull_volume"] = 0.0
        out["hull_area"] = np.nan
        cells = np.unique(np.floor(p / voxel).astype(np.int64), axis=0)
        out["voxel_volume"] = len(cells) * voxel**3
        out["voxel_area"] = np.nan
        return out
    plane = centred @ vt[:2].T
    if dim == 2:
        try:
            out["hull_area"] = float(ConvexHull(plane).volume)
        except QhullError:
            out["hull_area"] = 0.0
    cells = np.unique(np.floor(plane / voxel).astype(np.int64), axis=0)
    out["voxel_area"] = len(cells) * voxel**2
    return out


def _vector(name: str, value: Any) -> np.ndarray:
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _bad(name, value, "3 numbers") from None


def _largest_compliance(ds) -> Any:
    """``c_max`` per sample (m/N) at the last arc point (the tip by default), or None."""
    arc = "s" if "s" in ds.dims else "arm_index" if "arm_index" in ds.dims else None
    if "translational_compliance" in ds:
        c = ds["translational_compliance"].isel(principal=0)
    elif "compliance" in ds:
        block = ds["compliance"].isel(twist=slice(0, 3), wrench=slice(0, 3)).values
        shape = block.shape[:-2]
        flat = block.reshape(-1, 3, 3)
        ok = np.all(np.isfinite(flat), axis=(1, 2))
        e = np.full(len(flat), np.nan)
        if ok.any():
            e[ok] = np.linalg.eigvalsh(0.5 * (flat[ok] + flat[ok].transpose(0, 2, 1)))[:, -1]
        c = ds["compliance"].isel(twist=0, wrench=0).copy(data=e.reshape(shape))
    else:
        return None
    return c.isel({arc: -1}) if arc else c


def design_summary(
    ds,
    *,
    over: Sequence[str] | None = None,
    voxel: float | None = None,
    axis: Sequence[float] = (0.0, 0.0, 1.0),
    origin: Sequence[float] = (0.0, 0.0, 0.0),
):
    """Workspace, stiffness statistics and the centre-to-periphery ratio per design point.

    Args:
        ds: A :func:`softrod.sweep` result with ``tip_position`` (``outputs`` with
            ``"tip_pose"``); with ``translational_compliance`` (or ``compliance``) also the
            stiffness statistics and the ratio, from the last arc point (the tip by default).
        over: The dimensions the workspace spans (default the actuation dimensions).
        voxel: Voxel edge (m, > 0); default :data:`VOXEL_FRACTION` of the diagonal of the
            bounding box of every converged tip of the sweep.
        axis: Direction of the robot's axis (world), for the distance of a tip to it.
        origin: A point of the axis (m, world).

    Returns:
        An ``xarray.Dataset`` over the remaining (design) dimensions: ``reachable`` (number
        of converged samples), ``workspace_dimension``, ``hull_volume`` (m³), ``hull_area``
        (m², planar), ``voxel_volume`` (m³), ``voxel_area`` (m², planar) and, with a
        compliance, ``stiffness_min``, ``stiffness_median``, ``stiffness_mean``,
        ``stiffness_max`` (N/m, ``1 / c_max`` over the workspace) and
        ``centre_periphery_ratio``.

    Raises:
        ParameterError: No ``tip_position`` in ``ds``, an unknown dimension, a bad voxel or
            axis.
    """
    import xarray as xr

    if "tip_position" not in getattr(ds, "data_vars", {}):
        raise _bad("ds", "no tip_position", "a sweep with outputs including 'tip_pose'")
    if over is None:
        over = str(ds.attrs.get("actuation_dims", "")).split()
    elif isinstance(over, str):
        over = [over]
    elif not isinstance(over, (list, tuple)) or not all(isinstance(d, str) for d in over):
        raise _bad("over", over, "a sequence of dimension names")
    over = list(over)
    for d in over:
        if d not in ds.dims:
            raise _bad("over", d, f"dimensions of ds ({', '.join(map(str, ds.dims))})")
    a = _vector("axis", axis)
    o = _vector("origin", origin)
    if a.shape != (3,) or not np.all(np.isfinite(a)) or np.linalg.norm(a) == 0:
        raise _bad("axis", axis, "a nonzero direction of 3 finite numbers")
    if o.shape != (3,) or not np.all(np.isfinite(o)):
        raise _bad("origin", origin, "3 finite numbers (m)")
    a = a / np.linalg.norm(a)
    ok = ds["status"] == 0
    tips = ds["tip_position"].where(ok)
    if voxel is None:
        p = tips.values.reshape(-1, 3)
        p = p[np.all(np.isfinite(p), axis=1)]
        diag = float(np.linalg.norm(p.max(axis=0) - p.min(axis=0))) if len(p) else 0.0
        voxel = VOXEL_FRACTION * diag if diag > 0 else 1e-3
    if isinstance(voxel, bool) or not isinstance(voxel, (int, float, np.number)):
        raise _bad("voxel", voxel, "a number (m)")
    with np.errstate(over="ignore", under="ignore"):
        cube = np.float64(voxel) ** 3
    if not (np.isfinite(voxel) and 0.0 < cube < np.inf):
        raise _bad("voxel", voxel, "> 0 m, with a finite, nonzero cube")
    cmax = _largest_compliance(ds)
    if cmax is not None:
        cmax = cmax.where(ok)
    rest = [d for d in ds["status"].dims if d not in over]
    tips_t = tips.transpose(*rest, *over, "xyz")
    shape = tuple(ds.sizes[d] for d in rest)
    n_points = int(np.prod(shape)) if shape else 1
    tip_flat = tips_t.values.reshape(n_points, -1, 3)
    c_flat = cmax.transpose(*rest, *over).values.reshape(n_points, -1) if cmax is not None else None
    names = [
        "reachable",
        "workspace_dimension",
        "hull_volume",
        "hull_area",
        "voxel_volume",
        "voxel_area",
    ]
    if c_flat is not None:
        names += [
            "stiffness_min",
            "stiffness_median",
            "stiffness_mean",
            "stiffness_max",
            "centre_periphery_ratio",
        ]
    out = {n: np.full(n_points, np.nan) for n in names}
    for i in range(n_points):
        m = workspace_measures(tip_flat[i], voxel)
        out["reachable"][i] = m["count"]
        out["workspace_dimension"][i] = m["dimension"]
        for k in ("hull_volume", "hull_area", "voxel_volume", "voxel_area"):
            out[k][i] = m[k]
        if c_flat is None:
            continue
        c = c_flat[i]
        good = np.isfinite(c) & np.all(np.isfinite(tip_flat[i]), axis=1)
        if not good.any():
            continue
        k = 1.0 / c[good]
        out["stiffness_min"][i] = k.min()
        out["stiffness_median"][i] = np.median(k)
        out["stiffness_mean"][i] = k.mean()
        out["stiffness_max"][i] = k.max()
        rel = tip_flat[i][good] - o
        r = np.linalg.norm(rel - np.outer(rel @ a, a), axis=1)
        out["centre_periphery_ratio"][i] = c[good][np.argmax(r)] / c[good][np.argmin(r)]
    attrs = {
        "reachable": {"units": "1", "long_name": "converged samples"},
        "workspace_dimension": {"units": "1", "long_name": "dimension spanned by the tips"},
        "hull_volume": {"units": "m^3", "long_name": "convex hull volume of the tips"},
        "hull_area": {"units": "m^2", "long_name": "convex hull area of planar tips"},
        "voxel_volume": {"units": "m^3", "long_name": f"occupied voxels (edge {voxel:.3g} m)"},
        "voxel_area": {
            "units": "m^2",
            "long_name": f"occupied pixels of planar tips (edge {voxel:.3g} m)",
        },
        "stiffness_min": {"units": "N/m", "long_name": "least tip stiffness 1/c_max"},
        "stiffness_median": {"units": "N/m", "long_name": "median tip stiffness 1/c_max"},
        "stiffness_mean": {"units": "N/m", "long_name": "mean tip stiffness 1/c_max"},
        "stiffness_max": {"units": "N/m", "long_name": "greatest tip stiffness 1/c_max"},
        "centre_periphery_ratio": {
            "units": "1",
            "long_name": "c_max at the tip farthest from the axis / at the nearest",
        },
    }
    coords = {d: ds[d] for d in rest if d in ds.coords}
    data = {n: (rest, out[n].reshape(shape), attrs[n]) for n in names}
    return xr.Dataset(data, coords=coords, attrs={"voxel": voxel, "over": " ".join(over)})


def _objective(name: str, value: Any) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _bad(name, value, "numbers (an array or a DataArray)") from None
    if v.ndim == 0:
        raise _bad(name, value, "an array of objective values (at least one dimension)")
    return v


class Pareto:
    """The non-dominated set of two objectives (a Pareto front).

    A point is dominated when another is at least as good in both objectives and better in
    one; points with a NaN objective take no part.

    Args:
        a: First objective, an array or an ``xarray.DataArray`` (any shape).
        b: Second objective, the same shape.
        better: For each objective, ``"min"`` or ``"max"``: which direction is better.
        names: Names of the objectives (default the DataArrays' names, or ``"a"``, ``"b"``).

    Attributes:
        mask: Whether each point is on the front (the input's shape; a DataArray for
            DataArray inputs).
        indices: Flat indices of the front's points, by the first objective (best first).
        values: The objectives on the front, shape (k, 2), in that order.
        better: The directions.
        names: The objectives' names.
    """

    def __init__(
        self,
        a: Any,
        b: Any,
        *,
        better: Sequence[str] = ("min", "min"),
        names: Sequence[str] | None = None,
    ) -> None:
        if (
            isinstance(better, str)
            or not isinstance(better, (list, tuple))
            or len(better) != 2
            or any(x not in ("min", "max") for x in better)
        ):
            raise _bad("better", better, "two of 'min' or 'max', one per objective")
        better = tuple(better)
        self._da = a if hasattr(a, "dims") and hasattr(a, "coords") else None
        av = _objective("a", a)
        bv = _objective("b", b)
        if av.shape != bv.shape:
            exc = ParameterError(
                f"invalid parameters `a` and `b`: must have the same shape, not {av.shape} "
                f"and {bv.shape}"
            )
            exc.parameter = "b"
            raise exc
        if names is None:
            names = (getattr(a, "name", None) or "a", getattr(b, "name", None) or "b")
        elif (
            isinstance(names, str)
            or not isinstance(names, (list, tuple))
            or len(names) != 2
            or not all(isinstance(n, str) for n in names)
        ):
            raise _bad("names", names, "two strings, one per objective")
        self.names = tuple(str(n) for n in names)
        self.better = better
        self._shape = av.shape
        x = av.ravel() * (1 if better[0] == "min" else -1)
        y = bv.ravel() * (1 if better[1] == "min" else -1)
        valid = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
        # Sort by x then y; a point is on the front if its y beats every y before it.
        order = valid[np.lexsort((y[valid], x[valid]))]
        front: list[int] = []
        best, best_x = np.inf, np.nan
        for i in order:
            if y[i] < best:
                front.append(i)
                best, best_x = y[i], x[i]
            elif y[i] == best and x[i] == best_x:  # a duplicate of a front point
                front.append(i)
        self.indices = np.array(front, dtype=np.int64)
        flat = np.zeros(av.size, dtype=bool)
        flat[self.indices] = True
        mask = flat.reshape(self._shape)
        self.mask = self._da.copy(data=mask).rename("pareto") if self._da is not None else mask
        self.values = np.column_stack([av.ravel()[self.indices], bv.ravel()[self.indices]])

    def __len__(self) -> int:
        return len(self.indices)

    def __repr__(self) -> str:
        return (
            f"Pareto({len(self)} of {int(np.prod(self._shape))} points, "
            f"{self.names[0]}: {self.better[0]}, {self.names[1]}: {self.better[1]})"
        )

    def table(self):
        """The front as a pandas ``DataFrame``: the two objectives and, for DataArray
        inputs, the coordinates of each point."""
        import pandas as pd

        cols: dict[str, Any] = {}
        if self._da is not None:
            idx = np.unravel_index(self.indices, self._shape)
            for dim, i in zip(self._da.dims, idx, strict=True):
                cols[dim] = self._da[dim].values[i] if dim in self._da.coords else i
        cols[self.names[0]] = self.values[:, 0]
        cols[self.names[1]] = self.values[:, 1]
        return pd.DataFrame(cols)
