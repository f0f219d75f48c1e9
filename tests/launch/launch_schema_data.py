"""Launch-file data shared by the schema tests (test_launch_schema_bounds.py, test_launch_schema_paths.py)."""

from __future__ import annotations

DDS = {"type": "unitree_dds", "interface": "lo"}
"""A robot link on loopback: the backend section of a launch file that is checked as a robot's."""


def launch_data(name: str, **sections) -> dict:
    """A minimal launch file (one scripted second, no video) named `name`, `sections` replacing its own."""
    data = {"name": name, "input": {"type": "scripted", "timeline": [{"duration_s": 1.0}]}, "output": {"video": False}}
    data.update(sections)
    return data


def assert_holds(parsed, data, where: str = "") -> None:
    """Every value `data` (launch-file YAML as dicts) gives is the value the parsed launch file holds:
    sections are dataclasses (or dicts), lists hold their items in order, numbers compare equal."""
    import dataclasses

    if isinstance(data, dict):
        for key, value in data.items():
            got = parsed.get(key) if isinstance(parsed, dict) else getattr(parsed, key)
            if dataclasses.is_dataclass(got) or isinstance(value, (dict, list)):
                assert_holds(got, value, f"{where}.{key}" if where else key)
            else:
                assert got == value, f"{where}.{key}: the launch file says {value!r}, the parsed one holds {got!r}"
    elif isinstance(data, list):
        got_items = list(parsed)
        assert len(got_items) == len(data), f"{where}: {len(data)} items given, {len(got_items)} held"
        for i, (got, value) in enumerate(zip(got_items, data)):
            if dataclasses.is_dataclass(got) or isinstance(value, (dict, list)):
                assert_holds(got, value, f"{where}[{i}]")
            else:
                assert got == value, f"{where}[{i}]: {value!r} given, {got!r} held"
    else:
        assert parsed == data, f"{where}: {data!r} given, {parsed!r} held"
