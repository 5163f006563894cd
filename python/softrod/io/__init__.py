"""File input and output: robot description files (schema, reading, writing), backbones from
CSV, solution samples to CSV or JSON-ready dicts."""

from .robot_file import (
    FieldError,
    RobotFile,
    dump_robot_toml,
    read_robot_toml,
    robot_file_json_schema,
    validate_robot_dict,
)
from .tables import (
    contacts_to_list,
    read_backbone_csv,
    solution_to_dict,
    statics_to_dict,
    write_samples_csv,
    write_statics_csv,
)

__all__ = [
    "FieldError",
    "RobotFile",
    "contacts_to_list",
    "dump_robot_toml",
    "read_backbone_csv",
    "read_robot_toml",
    "robot_file_json_schema",
    "solution_to_dict",
    "statics_to_dict",
    "validate_robot_dict",
    "write_samples_csv",
    "write_statics_csv",
]
