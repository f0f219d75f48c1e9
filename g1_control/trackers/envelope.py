"""A tracker's measured envelope: the command range it delivers (within a tolerance, every style,
no fall), as `g1 bench envelope` measured it in physics. Shipped next to the policy spec
(`<spec>.envelope.json`); the loop builder's command limits come from it (Tracker.command_limits),
so stick scaling and launch limits ask only for what the tracking layer delivers.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

from g1_control.errors import PolicyMismatchError
from g1_control.types import CommandLimits

AXES = ("vx_mps", "vy_mps", "wz_radps")


@dataclass
class Envelope:
    vx_mps: tuple[float, float]
    vy_mps: tuple[float, float]
    wz_radps: tuple[float, float]
    pelvis_height_m: tuple[float, float]
    tolerance_pct: float
    """Achieved within this much of the command (gait-cycle mean, steady state) counts as delivered."""
    per_style: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)
    """Each style's own range; the limits above hold for every style."""
    measured_with: str = ""
    """The command that measured it, and where."""

    @property
    def command_limits(self) -> CommandLimits:
        return CommandLimits(self.vx_mps, self.vy_mps, self.wz_radps, self.pelvis_height_m)

    def write(self, path: Path) -> None:
        Path(path).write_text(json.dumps(asdict(self), indent=1) + "\n")


def envelope_path(spec_file: Path) -> Path:
    """Where a spec's envelope lives: next to it, `<stem>.envelope.json`."""
    return spec_file.with_name(spec_file.stem + ".envelope.json")


def read_envelope(path: Path) -> Envelope | None:
    """The envelope at `path`, or None when none was measured."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        d = json.loads(path.read_text())
        return Envelope(
            **{k: (float(d[k][0]), float(d[k][1])) for k in AXES + ("pelvis_height_m",)},
            tolerance_pct=float(d["tolerance_pct"]),
            per_style={s: {k: (float(v[0]), float(v[1])) for k, v in r.items()} for s, r in d.get("per_style", {}).items()},
            measured_with=str(d.get("measured_with", "")),
        )
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise PolicyMismatchError(f"{path}: not a valid envelope ({type(exc).__name__}: {exc}); "
                                  "measure it again with `g1 bench envelope --write`") from None
