"""Backbones from photographs: segmentation, a sub-pixel tube fit and the ordered centreline.

:func:`extract_backbone` turns a top-view photo of an arm into a :class:`Backbone` (base to
tip, pixels or metres in the arm's frame) that :func:`softrod.backbone_distance` and the
calibration consume; :func:`plot_backbone_overlay` draws it on the photo. The image-processing
modules (SciPy, scikit-image) load on first use, so that ``import softrod`` stays quick.
"""

from importlib import import_module

from .backbone import Backbone, BackboneQuality

__all__ = ["Backbone", "BackboneQuality", "extract_backbone", "plot_backbone_overlay", "read_image"]

_LAZY = {
    "extract_backbone": ".extract",
    "plot_backbone_overlay": ".overlay",
    "read_image": ".segment",
}


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(import_module(_LAZY[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
