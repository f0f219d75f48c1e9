"""Launch-file data shared by the schema tests (test_launch_schema_bounds.py, test_launch_schema_paths.py)."""

from __future__ import annotations

DDS = {"type": "unitree_dds", "interface": "lo"}
"""A robot link on loopback: the backend section of a launch file that is checked as a robot's."""


def launch_data(name: str, **sections) -> dict:
    """A minimal launch file (one scripted second, no video) named `name`, `sections` replacing its own."""
    data = {"name": name, "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}, "output": {"video": False}}
    data.update(sections)
    return data
