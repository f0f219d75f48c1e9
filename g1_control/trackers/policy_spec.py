"""Policy specs: which ONNX file, how to build its observation, how to read its action, and the
checks that refuse a policy that does not fit the robot (joint order, gains, observation size).

A spec is a YAML file. Built-in specs live in g1_control/policies/specs/ and are named by their
file stem (`holosoma_loco_ppo`); any other path to a YAML file works too. Values marked
`metadata` are read from the ONNX file's metadata (as holosoma stores kp, kd, dof_names), so a
policy travels with its own robot configuration.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Literal

import numpy as np

from g1_control import assets
from g1_control.config import from_dict, read_yaml
from g1_control.errors import PolicyMismatchError
from g1_control.robot import g1
from g1_control.trackers.envelope import Envelope, envelope_path, read_envelope
from g1_control.trackers.observation import ObservationSpec
from g1_control.types import CommandLimits

GAIN_RTOL = 0.02
"""Gains in a policy's metadata may differ from the robot's by this fraction (rounding)."""


# -- the spec file's schema (read by g1_control/config.py, the launch files' typed loader) -------------------
@dataclass
class OnnxAssetSection:
    path: str
    """Path of the ONNX file inside the asset (or, without an asset, relative to the spec file)."""
    asset: str | None = None
    """A registry asset fetched by `g1 policies fetch` (g1_control/assets.py)."""


@dataclass
class GainsSection:
    kp: list[float]
    kd: list[float]


@dataclass
class ActionSection:
    scale: float | list[float] = 1.0
    """q* = default_q + scale * action (one number, or one per joint)."""
    clip: float = 100.0


@dataclass
class ObsTermSection:
    name: str
    scale: float = 1.0


@dataclass
class ObservationSection:
    terms: list[str | ObsTermSection] = field(default_factory=list)
    """In the order the network expects them (holosoma: alphabetical by name)."""
    input: str = "obs"
    """Name of the ONNX input the observation feeds."""
    history: int = 1


@dataclass
class PhaseSection:
    period_s: float
    offsets_rad: tuple[float, float]
    stand_threshold: float = 0.01


@dataclass
class PolicySpecFile:
    """A policy spec YAML. `metadata` reads a value from the ONNX file's own metadata; `robot` takes
    the G1's (g1_control/robot/g1.py)."""

    onnx: str | OnnxAssetSection
    name: str = ""
    kind: Literal["locomotion", "tracking"] = "locomotion"
    rate_hz: float = 50.0
    variant: g1.VariantName = "g1_29dof"
    joint_names: Literal["metadata", "robot"] | list[str] = "robot"
    gains: Literal["metadata", "robot"] | GainsSection = "robot"
    default_q: Literal["robot"] | list[float] = "robot"
    action: ActionSection = field(default_factory=ActionSection)
    observation: ObservationSection = field(default_factory=ObservationSection)
    phase: PhaseSection | None = None
    command_ranges: Literal["metadata"] | dict[str, tuple[float, float]] = field(default_factory=dict)

    def validate(self, where: str) -> None:
        if not self.rate_hz > 0:
            raise PolicyMismatchError(f"{where}.rate_hz: must be > 0, got {self.rate_hz}")
        if self.observation.history < 1:
            raise PolicyMismatchError(f"{where}.observation.history must be >= 1, got {self.observation.history}")


def builtin_specs() -> dict[str, Path]:
    folder = resources.files("g1_control.policies.specs")
    return {Path(p.name).stem: Path(str(p)) for p in folder.iterdir() if p.name.endswith(".yaml")}


@dataclass
class PhaseSpec:
    period_s: float
    offsets_rad: np.ndarray
    stand_threshold: float


@dataclass
class PolicySpec:
    name: str
    kind: str
    onnx_path: Path
    rate_hz: float
    joint_names: tuple[str, ...]
    kp: np.ndarray
    kd: np.ndarray
    default_q_rad: np.ndarray
    action_scale: np.ndarray
    action_clip: float
    observation: ObservationSpec
    input_name: str
    phase: PhaseSpec | None
    command_ranges: dict[str, tuple[float, float]]
    metadata: dict[str, str]
    envelope: Envelope | None = None
    """What the tracker delivers with this policy, measured (g1 bench envelope; `<spec>.envelope.json`)."""
    spec_file: Path | None = None

    @property
    def command_limits(self) -> CommandLimits:
        """The command range the policy was trained on (holosoma: lin_vel_x, lin_vel_y, ang_vel_yaw)."""
        r = self.command_ranges
        return CommandLimits(r.get("lin_vel_x", (-1.0, 1.0)), r.get("lin_vel_y", (-1.0, 1.0)),
                             r.get("ang_vel_yaw", (-1.0, 1.0)))

    @property
    def joint_index(self) -> np.ndarray:
        """For each policy joint, its index in the robot's joint order."""
        return np.array([g1.JOINT_INDEX[n] for n in self.joint_names])


def resolve_spec_path(name_or_path: str | Path) -> Path:
    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml"):
        if not path.is_file():
            raise PolicyMismatchError(f"policy spec file {path} does not exist")
        return path
    specs = builtin_specs()
    if str(name_or_path) not in specs:
        raise PolicyMismatchError(
            f"unknown policy '{name_or_path}'; built-in: {', '.join(sorted(specs))}, or a path to a spec .yaml"
        )
    return specs[str(name_or_path)]


def _onnx_path(onnx: str | OnnxAssetSection, spec_file: Path, fetch: bool) -> Path:
    if isinstance(onnx, str):
        path = Path(onnx)
        return path if path.is_absolute() else (spec_file.parent / path)
    if onnx.asset is not None:
        if not assets.is_fetched(onnx.asset) and not fetch:
            raise PolicyMismatchError(f"{spec_file}: asset '{onnx.asset}' is not fetched; run `g1 policies fetch`")
        return assets.fetch(onnx.asset) / onnx.path
    return spec_file.parent / onnx.path


def read_spec_file(spec_file: Path) -> PolicySpecFile:
    """The spec file, validated by the typed loader (unknown keys, types, ranges named by key)."""
    data = read_yaml(spec_file, PolicyMismatchError)  # duplicate keys and binary files refused too
    return from_dict(PolicySpecFile, data, spec_file.name, error=PolicyMismatchError)


def load_spec(name_or_path: str | Path, *, fetch: bool = True) -> PolicySpec:
    """Read and check a spec and its ONNX file against the robot; raise PolicyMismatchError if off."""
    import onnxruntime as ort

    spec_file = resolve_spec_path(name_or_path)
    d = read_spec_file(spec_file)
    onnx_path = _onnx_path(d.onnx, spec_file, fetch)
    if not onnx_path.is_file():
        raise PolicyMismatchError(f"{spec_file}: ONNX file {onnx_path} does not exist")
    meta = dict(ort.InferenceSession(str(onnx_path), providers=["CPUExecutionProvider"])
                .get_modelmeta().custom_metadata_map)
    try:
        spec = _build(d, spec_file, onnx_path, meta)
    except KeyError as exc:
        raise PolicyMismatchError(f"{spec_file}: missing key {exc}") from None
    except (TypeError, ValueError) as exc:
        raise PolicyMismatchError(f"{spec_file}: {' '.join(str(exc).split())}") from None
    check_against_robot(spec)
    check_against_onnx(spec)
    return spec


def _from_meta(value, key: str, meta: dict, spec_file: Path):
    if value != "metadata":
        return value
    if key not in meta:
        raise PolicyMismatchError(f"{spec_file}: the spec reads '{key}' from the ONNX metadata, which has no '{key}'")
    return json.loads(meta[key])


def _build(d: PolicySpecFile, spec_file: Path, onnx_path: Path, meta: dict) -> PolicySpec:
    if d.joint_names == "robot":
        joint_names = g1.JOINT_NAMES
    elif d.joint_names == "metadata":
        joint_names = tuple(_from_meta("metadata", "dof_names", meta, spec_file))
    else:
        joint_names = tuple(d.joint_names)
    if d.gains == "metadata":
        kp, kd = (np.asarray(_from_meta("metadata", k, meta, spec_file), dtype=float) for k in ("kp", "kd"))
    elif d.gains == "robot":
        idx = [g1.JOINT_INDEX.get(n, 0) for n in joint_names]
        kp, kd = g1.KP_DEFAULT[idx].copy(), g1.KD_DEFAULT[idx].copy()
    else:
        kp, kd = np.asarray(d.gains.kp, dtype=float), np.asarray(d.gains.kd, dtype=float)
    default_q = g1.DEFAULT_Q_RAD.copy() if d.default_q == "robot" else np.asarray(d.default_q, dtype=float)
    scale = np.asarray(d.action.scale, dtype=float)
    if scale.ndim and scale.shape != (len(joint_names),):
        raise PolicyMismatchError(f"{spec_file.name}.action.scale: {scale.size} values for {len(joint_names)} joints")
    scale = np.broadcast_to(scale, (len(joint_names),)).copy()
    phase = None
    if d.phase is not None:
        phase = PhaseSpec(d.phase.period_s, np.asarray(d.phase.offsets_rad, dtype=float), d.phase.stand_threshold)
    ranges = d.command_ranges
    if ranges == "metadata":
        ranges = _from_meta("metadata", "command_ranges", meta, spec_file) or {}
    ranges = {k: (float(v[0]), float(v[1])) for k, v in ranges.items()}
    obs = d.observation
    terms = [t if isinstance(t, str) else {"name": t.name, "scale": t.scale} for t in obs.terms]
    return PolicySpec(
        name=d.name or spec_file.stem, kind=d.kind, onnx_path=onnx_path, rate_hz=d.rate_hz, joint_names=joint_names,
        kp=kp, kd=kd, default_q_rad=default_q, action_scale=scale, action_clip=d.action.clip,
        observation=ObservationSpec.from_dict({"terms": terms, "history": obs.history},
                                              f"{spec_file.name}: observation"),
        input_name=obs.input, phase=phase, command_ranges=ranges, metadata=meta,
        envelope=read_envelope(envelope_path(spec_file)), spec_file=spec_file,
    )


def check_against_robot(spec: PolicySpec) -> None:
    """Joint order, gains and default pose must fit the G1."""
    names = spec.joint_names
    if tuple(names) != g1.JOINT_NAMES:
        unknown = [n for n in names if n not in g1.JOINT_INDEX]
        if unknown:
            raise PolicyMismatchError(f"policy '{spec.name}' names joints the G1 does not have: {unknown}")
        first = next((i for i, (a, b) in enumerate(zip(names, g1.JOINT_NAMES)) if a != b), len(names))
        raise PolicyMismatchError(
            f"policy '{spec.name}' joint order differs from the G1's at index {first}: "
            f"policy has {names[first] if first < len(names) else '<none>'}, robot has "
            f"{g1.JOINT_NAMES[first] if first < len(g1.JOINT_NAMES) else '<none>'} "
            f"({len(names)} policy joints, {g1.NUM_JOINTS} robot joints)"
        )
    for label, arr in (("kp", spec.kp), ("kd", spec.kd), ("default_q", spec.default_q_rad)):
        if arr.shape != (g1.NUM_JOINTS,):
            raise PolicyMismatchError(f"policy '{spec.name}' {label} must be {g1.NUM_JOINTS} finite numbers, got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            j = int(np.argmax(~np.isfinite(arr)))
            raise PolicyMismatchError(f"policy '{spec.name}' {label} must be {g1.NUM_JOINTS} finite numbers; "
                                      f"{g1.JOINT_NAMES[j]} is {arr[j]}")
    if np.any(spec.kp < 0) or np.any(spec.kd < 0):
        raise PolicyMismatchError(f"policy '{spec.name}' has negative gains")
    outside = np.nonzero((spec.default_q_rad < g1.Q_MIN_RAD) | (spec.default_q_rad > g1.Q_MAX_RAD))[0]
    if outside.size:
        j = outside[0]
        raise PolicyMismatchError(f"policy '{spec.name}' default pose puts {g1.JOINT_NAMES[j]} outside its limits")


def check_against_onnx(spec: PolicySpec) -> None:
    """The spec's observation size and gains must match what the network and its metadata say."""
    import onnxruntime as ort

    session = ort.InferenceSession(str(spec.onnx_path), providers=["CPUExecutionProvider"])
    inputs = {i.name: i.shape for i in session.get_inputs()}
    if spec.input_name not in inputs:
        raise PolicyMismatchError(
            f"policy '{spec.name}': ONNX has no input '{spec.input_name}' (inputs: {sorted(inputs)})"
        )
    width = inputs[spec.input_name][-1]
    if isinstance(width, int) and width != spec.observation.dim:
        raise PolicyMismatchError(
            f"policy '{spec.name}': observation spec builds {spec.observation.dim} values "
            f"({', '.join(t.name for t in spec.observation.terms)} x history {spec.observation.history}) "
            f"but the ONNX input '{spec.input_name}' takes {width}"
        )
    out_width = session.get_outputs()[0].shape[-1]
    if isinstance(out_width, int) and out_width != len(spec.joint_names):
        raise PolicyMismatchError(f"policy '{spec.name}': ONNX outputs {out_width} actions for {len(spec.joint_names)} joints")
    for key, arr in (("kp", spec.kp), ("kd", spec.kd)):
        if key in spec.metadata:
            meta_val = np.asarray(json.loads(spec.metadata[key]), dtype=float)
            if meta_val.shape != arr.shape or not np.allclose(meta_val, arr, rtol=GAIN_RTOL):
                raise PolicyMismatchError(
                    f"policy '{spec.name}': {key} in the spec differs from the {key} the policy was trained with "
                    "(ONNX metadata)"
                )
    # Gains the robot runs must be the gains the policy was trained with.
    if not np.allclose(spec.kp, g1.KP_DEFAULT, rtol=GAIN_RTOL) or not np.allclose(spec.kd, g1.KD_DEFAULT, rtol=GAIN_RTOL):
        j = int(np.argmax(np.abs(spec.kp - g1.KP_DEFAULT) / g1.KP_DEFAULT + np.abs(spec.kd - g1.KD_DEFAULT) / g1.KD_DEFAULT))
        raise PolicyMismatchError(
            f"policy '{spec.name}': gains for {g1.JOINT_NAMES[j]} (kp {spec.kp[j]:.2f}, kd {spec.kd[j]:.3f}) do not match "
            f"the G1's (kp {g1.KP_DEFAULT[j]:.2f}, kd {g1.KD_DEFAULT[j]:.3f})"
        )
