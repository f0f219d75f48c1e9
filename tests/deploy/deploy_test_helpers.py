"""Shared pieces of the deploy tests: launch files derived from launch/sim2sim.yaml, DDS
partitions (concurrent runs on this host never see each other), emulated robots on lo/domain 1."""

from __future__ import annotations

import os
import uuid
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
SIM2SIM = ROOT / "launch" / "sim2sim.yaml"
SIM2SIM_GENERATOR = ROOT / "launch" / "sim2sim_generator.yaml"


def new_partition() -> str:
    return f"g1deploy-{os.getpid()}-{uuid.uuid4().hex[:8]}"


def write_launch(folder: Path, changes: dict | None = None, name: str = "launch.yaml", base: Path = SIM2SIM) -> Path:
    """launch/sim2sim.yaml with `changes` merged in (nested dicts merge; None deletes a key)."""
    data = yaml.safe_load(base.read_text())

    def merge(target: dict, update: dict) -> None:
        for key, value in update.items():
            if value is None:
                target.pop(key, None)
            elif isinstance(value, dict) and isinstance(target.get(key), dict):
                merge(target[key], value)
            else:
                target[key] = value

    merge(data, changes or {})
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


FAST = {"deploy": {"state_window_s": 0.3, "input_check_s": 0.1}, "backend": {"connect_timeout_s": 2.0}}
"""Shorter listening windows for tests that only need the checklist's verdict."""


