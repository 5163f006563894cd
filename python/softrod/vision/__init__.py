"""Backbones from photographs: segmentation, a sub-pixel tube fit and the ordered centreline.

:func:`extract_backbone` turns a top-view photo of an arm into a :class:`Backbone` (base to
tip, pixels or metres in the arm's frame) that :func:`softrod.backbone_distance` and the
calibration consume; :func:`plot_backbone_overlay` draws it on the photo.
"""

from .backbone import Backbone, BackboneQuality
from .extract import extract_backbone
from .overlay import plot_backbone_overlay
from .segment import read_image

__all__ = ["Backbone", "BackboneQuality", "extract_backbone", "plot_backbone_overlay", "read_image"]
