"""Domain randomisation of the simulated G1: what the real robot will differ in from the model.

A seeded draw, per run, of
  link masses      each robot body's mass (and inertia) scaled by a factor in `mass_scale`;
  CoM offsets      each robot body's centre of mass moved by up to `com_offset_m` (uniform in
                   that ball, in the body's frame);
  motor strength   each motor's torque scaled by a factor in `motor_strength` (the whole driver
                   law's output, gains and feed-forward alike, and its torque limit);
  command latency  every motor command reaches the drivers this late (one value per run, rounded
                   to physics steps);
  foot friction    the sliding friction of the feet's contacts (the feet's value is used against
                   the floor and platforms, whatever theirs is).
The controllers keep the nominal model (pinocchio's URDF, the policies' training): only the
simulated robot changes. The draw is a pure function of the seed and the robot's body names, so a
run is reproduced from its seed; `RobotDraw.summary()` / `as_dict()` record it.

    backend: {type: mujoco, randomize: {seed: 3}}          # a launch file (defaults below)
    g1 sim-robot --randomize 3                              # the emulated robot (g1 deploy's path)

g1_control/sim/mujoco_backend.py applies a draw to its model (MujocoConfig.randomize).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.errors import LaunchFileError

RANGE_BOUNDS: dict[str, tuple[float, float, str]] = {
    "mass_scale": (0.5, 2.0, "a factor on each link's mass"),
    "motor_strength": (0.3, 1.2, "a factor on each motor's torque"),
    "latency_s": (0.0, 0.1, "seconds of command latency"),
    "foot_friction": (0.05, 3.0, "a sliding friction coefficient"),
}
"""Range field -> (lowest, highest allowed, what it is): [low, high] must lie inside."""
MAX_COM_OFFSET_M = 0.1


@dataclass
class RandomizeConfig:
    """What is drawn and from which ranges ([low, high], uniform); a launch file's backend.randomize."""

    seed: int = 0
    mass_scale: tuple[float, float] = (0.9, 1.1)
    com_offset_m: float = 0.02
    """Largest CoM offset (m): each body's is drawn uniformly in the ball of this radius."""
    motor_strength: tuple[float, float] = (0.85, 1.0)
    latency_s: tuple[float, float] = (0.005, 0.015)
    foot_friction: tuple[float, float] = (0.5, 1.2)

    def validate(self, where: str) -> None:
        if self.seed < 0:
            raise LaunchFileError(f"{where}.seed: {self.seed} must be >= 0")
        for name, (lowest, highest, what) in RANGE_BOUNDS.items():
            low, high = getattr(self, name)
            if not lowest <= low <= high <= highest:
                raise LaunchFileError(f"{where}.{name}: [{low:g}, {high:g}] must be [low, high] with "
                                      f"{lowest:g} <= low <= high <= {highest:g} ({what})")
        if not 0.0 <= self.com_offset_m <= MAX_COM_OFFSET_M:
            raise LaunchFileError(f"{where}.com_offset_m: {self.com_offset_m:g} is outside [0, {MAX_COM_OFFSET_M:g}] m")


@dataclass(frozen=True)
class RobotDraw:
    """One draw: the values a randomised robot runs with."""

    seed: int
    bodies: tuple[str, ...]
    mass_scale: np.ndarray
    """(len(bodies),) factors."""
    com_offset_m: np.ndarray
    """(len(bodies), 3) in each body's frame."""
    motor_strength: np.ndarray
    """(29,) factors in g1.JOINT_NAMES order (drawn for every slot, so a variant's draw is the 29-DoF's)."""
    latency_s: float
    foot_friction: float

    def summary(self) -> str:
        offsets = np.linalg.norm(self.com_offset_m, axis=1)
        return (f"seed {self.seed}: link mass x{self.mass_scale.min():.3f}..{self.mass_scale.max():.3f}, "
                f"CoM offsets up to {100 * offsets.max():.1f} cm, motor strength "
                f"{self.motor_strength.min():.3f}..{self.motor_strength.max():.3f}, command latency "
                f"{1000 * self.latency_s:.1f} ms, foot friction {self.foot_friction:.2f}")

    def as_dict(self) -> dict:
        return {"seed": self.seed, "latency_s": self.latency_s, "foot_friction": self.foot_friction,
                "motor_strength": [round(float(v), 6) for v in self.motor_strength],
                "bodies": {name: {"mass_scale": round(float(s), 6), "com_offset_m": [round(float(v), 6) for v in o]}
                           for name, s, o in zip(self.bodies, self.mass_scale, self.com_offset_m)}}


def draw(config: RandomizeConfig, bodies: tuple[str, ...], num_joints: int) -> RobotDraw:
    """The draw of `config.seed` for a robot of `bodies` (names, in model order) and `num_joints` motors."""
    rng = np.random.default_rng(config.seed)
    n = len(bodies)
    # Fixed order of draws: the same seed gives the same robot (latency and friction first, so they
    # do not depend on how many bodies the variant has).
    latency = float(rng.uniform(*config.latency_s))
    friction = float(rng.uniform(*config.foot_friction))
    strength = rng.uniform(*config.motor_strength, size=num_joints)
    mass = rng.uniform(*config.mass_scale, size=n)
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    com = direction * (config.com_offset_m * np.cbrt(rng.uniform(size=n)))[:, None]  # uniform in the ball
    return RobotDraw(config.seed, tuple(bodies), mass, com, strength, latency, friction)


__all__ = ["MAX_COM_OFFSET_M", "RANGE_BOUNDS", "RandomizeConfig", "RobotDraw", "draw"]
