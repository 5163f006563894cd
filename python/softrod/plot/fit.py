"""Material-fit figure: a tensile curve against fitted laws, with residuals."""

from __future__ import annotations

import numpy as np

from ._figure import figure_style, new_figure

__all__ = ["plot_fit"]


def _model_stress(law, stretch: np.ndarray, measure: str) -> np.ndarray:
    """Stress of ``law`` at ``stretch`` in ``measure`` ("nominal" or "true"), Pa."""
    if measure == "true":
        return law.true_stress(stretch)
    return law.nominal_stress(stretch)


def plot_fit(
    curve,
    fits,
    *,
    labels=None,
    title: str | None = None,
    stretch_max=None,
    size: tuple[float, float] | None = None,
    dpi: float | None = None,
    style=None,
):
    """Measured tensile curve against fitted laws, with a residual panel.

    Args:
        curve: The data, a :class:`softrod.materials.TensileCurve` (e.g. from
            :func:`softrod.read_tensile_csv`).
        fits: A :class:`softrod.UniaxialFit` (from :func:`softrod.fit_uniaxial` or
            ``curve.fit(...)``) or a sequence of them, fitted to ``curve``.
        labels: One legend label per fit (default: model name, RMS error and R²).
        title: Figure title (default: the curve's name).
        stretch_max: Largest stretch shown (default: the whole curve, or 1.5 times the largest
            fitted strain when the fits used only part of it).
        size: Figure size (width, height) in inches.
        dpi: Resolution (dots per inch).
        style: A matplotlib style name or file.

    Returns:
        The matplotlib figure: stress (kPa, in the curve's stress measure) against engineering
        strain (%) on top, each law solid on its fitted range and dashed beyond it; residuals
        model - data (kPa) at the fitted points below. Points no fit used are grey.
    """
    with figure_style(style):
        return _fit_figure(curve, fits, labels, title, stretch_max, size, dpi)


def _fit_figure(curve, fits, labels, title, stretch_max, size, dpi):
    import matplotlib.pyplot as plt

    fits = [fits] if hasattr(fits, "model") else list(fits)
    stretch = np.asarray(curve.stretch, dtype=float)
    stress = np.asarray(curve.stress, dtype=float)
    measure = curve.stress_measure
    fitted_max = max((f.stretch_range[1] for f in fits), default=stretch.max())
    if stretch_max is None:
        stretch_max = min(stretch.max(), 1.0 + 1.5 * (fitted_max - 1.0))
        stretch_max = max(stretch_max, fitted_max)
    shown = stretch <= stretch_max
    fig = new_figure(size, (7.0, 6.2), dpi)
    ax, ax_r = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": (2.4, 1)})
    used = np.zeros(stretch.shape, dtype=bool)
    for fit in fits:
        lo, hi = fit.stretch_range
        used |= (stretch >= lo) & (stretch <= hi)
    strain_pct = (stretch - 1.0) * 100
    name = curve.name or "data"
    sel = used & shown
    ax.plot(strain_pct[sel], stress[sel] / 1e3, "o", ms=3, color="0.15", label=name)
    sel = ~used & shown
    if sel.any():
        ax.plot(strain_pct[sel], stress[sel] / 1e3, "o", ms=3, color="0.75", label="not fitted")
    cmap = plt.get_cmap("tab10")
    for i, fit in enumerate(fits):
        color = cmap(i % 10)
        law = fit.model
        lo, hi = fit.stretch_range
        label = (
            labels[i]
            if labels
            else f"{law.model_name} (RMS {fit.rms / 1e3:.3g} kPa, R² {fit.r_squared:.4f})"
        )
        inside = np.linspace(min(lo, 1.0), hi, 300)
        ax.plot(
            (inside - 1) * 100, _model_stress(law, inside, measure) / 1e3, color=color, label=label
        )
        if hi < stretch_max:
            beyond = np.linspace(hi, stretch_max, 200)
            ax.plot(
                (beyond - 1) * 100,
                _model_stress(law, beyond, measure) / 1e3,
                "--",
                color=color,
                lw=1,
            )
        mask = (stretch >= lo) & (stretch <= hi)
        residual = _model_stress(law, stretch[mask], measure) - stress[mask]
        ax_r.plot(strain_pct[mask], residual / 1e3, ".-", ms=3, lw=0.8, color=color)
    if fitted_max < stretch_max:
        ax.axvline((fitted_max - 1) * 100, color="0.5", ls=":", lw=1)
    # Keep diverging extrapolations from squashing the data.
    lo_y, hi_y = stress[shown].min() / 1e3, stress[shown].max() / 1e3
    pad = 0.08 * (hi_y - lo_y)
    ax.set_ylim(lo_y - pad, hi_y + pad)
    ax.set_xlim(min(strain_pct[shown].min(), 0.0), (stretch_max - 1) * 100)
    ax_r.axhline(0.0, color="0.3", lw=0.8)
    ax.set_ylabel(f"{measure} stress (kPa)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize="small")
    ax_r.set_xlabel("engineering strain (%)")
    ax_r.set_ylabel("model - data (kPa)")
    ax_r.grid(alpha=0.3)
    fig.suptitle(title or f"Uniaxial fit: {name}")
    return fig
