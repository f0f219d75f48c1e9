"""What a physics bench ran on: the versions of the packages that decide its numbers, Python and the CPU.

The whole-body controller is chaotic near its limits, so the same code and seeds can end differently
when the floating-point environment changes. Stop 45 ran on a fresh install that pulled MuJoCo 4.0.0
(pyproject asks for mujoco>=3.2): `g1 bench locomotion --only wbc/push` survived 10 of 20 pushes where
stop 44 had measured 9, and two tests that name cases that fall without a part saw one of them walk
on (with MuJoCo 3.17.0 one of the two came back). A figure in a note is comparable with another only
on the same environment: the physics benches print this line and write it into their --json.
"""

from __future__ import annotations

import platform
from importlib import metadata
from pathlib import Path

PACKAGES = ("mujoco", "pin", "numpy", "scipy", "proxsuite", "daqp", "onnxruntime")
"""Distributions whose versions go into the record (pin is pinocchio's)."""


def _cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def environment() -> dict[str, str]:
    """{distribution: version ('absent' when not installed), python, machine, cpu}."""
    out: dict[str, str] = {}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "absent"
    out.update(python=platform.python_version(), machine=platform.machine(), cpu=_cpu())
    return out


def describe(env: dict[str, str] | None = None) -> str:
    """One line: 'mujoco 4.0.0, pin 4.1.0, ..., python 3.11.7 on x86_64 (CPU model)'."""
    env = environment() if env is None else env
    packages = ", ".join(f"{name} {env[name]}" for name in PACKAGES if name in env)
    return f"environment: {packages}, python {env.get('python')} on {env.get('machine')} ({env.get('cpu')})"


__all__ = ["PACKAGES", "describe", "environment"]
