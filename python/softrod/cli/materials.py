"""``softrod materials`` and ``softrod fit``: the silicone library and tensile-curve fits."""

from __future__ import annotations

import json

from .._core import ParameterError
from ._common import add_figure_options, figure_options, files, save_figure

_TERMS_MODELS = ("yeoh", "ogden")


def _fmt_parameters(parameters: dict) -> str:
    """``c10 = 21589.8 Pa, ...``; Ogden exponents and reference strains are dimensionless."""
    parts = []
    for name, value in parameters.items():
        unit = "" if name in ("alpha", "reference_strain") else " Pa"
        if isinstance(value, list):
            parts.append(f"{name} = [{', '.join(f'{v:.6g}' for v in value)}]{unit}")
        else:
            parts.append(f"{name} = {value:.6g}{unit}")
    return ", ".join(parts)


def _cmd_materials(args) -> int:
    from .._core import SILICONES, silicone

    entries = [silicone(name) for name in SILICONES]
    if args.json:
        out = []
        for e in entries:
            mr = e.mooney_rivlin
            out.append(
                {
                    "name": e.name,
                    "neo_hookean": e.neo_hookean.parameters,
                    "mooney_rivlin": mr.parameters if mr is not None else None,
                    "yeoh": e.yeoh.parameters,
                    "fit_stretch_range": e.fit_stretch_range,
                    "source": e.source,
                }
            )
        print(json.dumps(out, indent=2))
        return 0
    import textwrap

    sources: list[str] = []
    cols = ("NH mu", "MR c10", "MR c01", "Yeoh c10", "Yeoh c20", "Yeoh c30", "E0 Yeoh")
    head = f"{'material':<15}" + "".join(f"  {c:>9}" for c in cols)
    head += f"  {'fitted stretch':>14}  source"
    print("softrod silicone library: parameters in kPa (E0 = small-strain Young's modulus)")
    print(head)
    print("-" * len(head))
    for e in entries:
        if e.source not in sources:
            sources.append(e.source)
        mr, y = e.mooney_rivlin, e.yeoh
        values = [e.neo_hookean.mu, None, None, y.c10, y.c20, y.c30, y.small_strain_modulus]
        if mr is not None:
            values[1:3] = [mr.c10, mr.c01]
        cells = "".join(f"  {v / 1e3:9.4g}" if v is not None else f"  {'-':>9}" for v in values)
        rng = e.fit_stretch_range
        rng_text = f"{rng[0]:g} to {rng[1]:g}" if rng is not None else "-"
        print(f"{e.name:<15}{cells}  {rng_text:>14}  [{sources.index(e.source) + 1}]")
    for i, text in enumerate(sources, start=1):
        print(textwrap.fill(text, width=100, initial_indent=f"[{i}] ", subsequent_indent="    "))
    return 0


def _cmd_fit(args) -> int:
    from pathlib import Path

    from .._core import ConvergenceError
    from ..analysis.materials import _bad, check_fit, read_tensile_csv
    from . import one_line

    if not Path(args.file).is_file():
        raise _bad("FILE", repr(args.file), "an existing file")
    curve = read_tensile_csv(
        args.file,
        columns=args.columns,
        strain_measure=args.strain_measure,
        stress_measure=args.stress_measure,
        strain_unit=args.strain_unit,
        stress_unit=args.stress_unit,
    )
    stretch = curve.stretch
    stretch_range = None
    if args.stretch_min is not None or args.stretch_max is not None:
        stretch_range = (
            args.stretch_min if args.stretch_min is not None else float(stretch.min()),
            args.stretch_max if args.stretch_max is not None else float(stretch.max()),
        )
    print(
        f"data: {args.file}: {len(curve)} points, {curve.strain_measure} strain, "
        f"{curve.stress_measure} stress, stretch {stretch.min():.4g} to {stretch.max():.4g}, "
        f"initial slope {curve.initial_slope() / 1e3:.4g} kPa"
    )
    fits, rows = [], []
    for model in args.model:
        key = model.lower().replace("_", "-")
        terms = args.terms if (len(args.model) == 1 or key in _TERMS_MODELS) else None
        try:
            fit = curve.fit(
                model, terms=terms, nonnegative=args.nonnegative, stretch_range=stretch_range
            )
        except (ParameterError, ConvergenceError) as exc:
            if len(args.model) == 1:
                if getattr(exc, "parameter", None) != "data":
                    raise
                err = ParameterError(f"{args.file}: {one_line(exc)}")  # the data, named
                err.parameter = "FILE"
                raise err from exc
            print(f"\n{model}: fit failed: {one_line(exc)}")
            rows.append({"model": model, "ok": False, "error": one_line(exc)})
            continue
        fits.append(fit)
        law = fit.model
        lo, hi = fit.stretch_range
        check = check_fit(curve, fit)
        print(f"\n{law.model_name}: {_fmt_parameters(fit.parameters)}")
        print(f"  small-strain modulus E0 = {law.small_strain_modulus:.6g} Pa")
        print(f"  fitted points: {fit.points}, stretch {lo:.4g} to {hi:.4g}")
        print(
            f"  {fit.stress_measure} stress error: RMS {fit.rms / 1e3:.4g} kPa, "
            f"max |residual| {fit.max_abs_residual / 1e3:.4g} kPa, R^2 {fit.r_squared:.6f}"
        )
        try:
            law.check_stable(lo, hi)
            stable = True
            print("  stable on the fitted range (dP/dstretch > 0): yes")
        except ParameterError as exc:
            stable = False
            print(f"  stable on the fitted range (dP/dstretch > 0): no ({one_line(exc)})")
        print(f"  {check.summary()}")
        rows.append(
            {
                "model": law.model_name,
                "ok": True,
                "parameters": fit.parameters,
                "small_strain_modulus": law.small_strain_modulus,
                "initial_slope": check.initial_slope,
                "modulus_ratio": check.modulus_ratio,
                "stable": stable,
                "tangent_positive": check.tangent_positive,
                "plausible": check.plausible,
                "rms": fit.rms,
                "r_squared": fit.r_squared,
                "max_abs_residual": fit.max_abs_residual,
                "points": fit.points,
                "stretch_range": [lo, hi],
            }
        )
    if not fits:
        raise ParameterError(f"no model could be fitted to {args.file} (see the lines above)")
    if args.csv:
        from ._common import write_csv

        header = [
            "model",
            "ok",
            "small_strain_modulus",
            "initial_slope",
            "modulus_ratio",
            "plausible",
            "stable",
            "rms",
            "r_squared",
            "parameters",
            "error",
        ]
        write_csv(
            args.csv,
            header,
            [
                [
                    r["model"],
                    int(r["ok"]),
                    *(r.get(k, "") for k in header[2:5]),
                    int(r.get("plausible", False)),
                    int(r.get("stable", False)),
                    r.get("rms", ""),
                    r.get("r_squared", ""),
                    json.dumps(r.get("parameters", {})),
                    r.get("error", ""),
                ]
                for r in rows
            ],
        )
    if args.json:
        from ._common import write_json

        write_json(args.json, {"data": str(args.file), "fits": rows})
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from ..plot import plot_fit

        fig = plot_fit(curve, fits, **figure_options(args))
        save_figure(fig, args.plot, args=args)
    return 0


def register(sub) -> None:
    """Adds the subcommands of this module to the ``softrod`` parser."""
    ma = sub.add_parser("materials", help="the silicone library: parameters and sources")
    ma.add_argument("--json", action="store_true", help="print the library as JSON on stdout")
    ma.set_defaults(func=_cmd_materials)
    fi = sub.add_parser("fit", help="fit material laws to a uniaxial tensile curve (CSV)")
    fi.add_argument(
        "file",
        metavar="FILE",
        help="Soft Robotics Materials Database CSV, or a plain two-column CSV (strain, stress)",
    )
    fi.add_argument(
        "-m",
        "--model",
        nargs="+",
        default=["yeoh"],
        metavar="MODEL",
        help="neo-hookean, mooney-rivlin, yeoh, ogden or linearised; several to compare "
        "(default: yeoh)",
    )
    fi.add_argument("--terms", type=int, help="Yeoh coefficients (1-3, default 3) or Ogden terms")
    fi.add_argument("--nonnegative", action="store_true", help="constrain coefficients >= 0")
    fi.add_argument("--stretch-min", type=float, help="fit only points with stretch >= this")
    fi.add_argument("--stretch-max", type=float, help="fit only points with stretch <= this")
    fi.add_argument(
        "--columns",
        default="engineering",
        help="database files: engineering (default) or true columns",
    )
    fi.add_argument(
        "--strain-measure",
        default="engineering",
        help="plain files: engineering (default), stretch or logarithmic",
    )
    fi.add_argument(
        "--stress-measure", default="nominal", help="plain files: nominal (default) or true"
    )
    fi.add_argument(
        "--strain-unit", default="fraction", help="plain files: fraction (default) or percent"
    )
    fi.add_argument(
        "--stress-unit", default="Pa", help="plain files: Pa (default), kPa, MPa or GPa"
    )
    fi.add_argument("--plot", metavar="FILE", help="figure of data, fitted curves and residuals")
    fi.add_argument("--csv", metavar="FILE", help="write one row per model to CSV")
    fi.add_argument("--json", metavar="FILE", help="write every fit to JSON")
    files(fi, inputs=("file",), outputs=("csv", "json", "plot"), figures=("plot",))
    fi.set_defaults(func=_cmd_fit)
    add_figure_options(fi, "plot")
