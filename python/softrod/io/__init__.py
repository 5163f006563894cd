"""File input and output: backbones from CSV, solution samples to CSV or JSON-ready dicts."""

from .tables import (
    read_backbone_csv,
    solution_to_dict,
    statics_to_dict,
    write_samples_csv,
    write_statics_csv,
)

__all__ = [
    "read_backbone_csv",
    "solution_to_dict",
    "statics_to_dict",
    "write_samples_csv",
    "write_statics_csv",
]
