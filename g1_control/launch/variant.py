"""The G1 variant a launch file is for (backend.expected_variant), and whether its tracker fits it.

The simulator builds that variant (sim/mujoco_backend.py: the joints it lacks are not in the
model), the model-based controller models it (robot/dynamics.py), and a learned policy must
command exactly the joints it has: a 29-DoF policy on the 23-DoF G1 would command six joints that
are not there (and its observation would hold six joints that never move), a 23-DoF policy on the
29-DoF G1 would leave six motors without a command. Both are refused by name, before anything runs:
`g1 launch` (when the loop is built) and `g1 launch --check`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from g1_control.errors import PolicyMismatchError
from g1_control.robot import g1

if TYPE_CHECKING:
    from g1_control.launch.schema import LaunchFile
    from g1_control.trackers.policy_spec import PolicySpec

POLICY_TRACKERS = ("policy", "layer")
"""tracker.type values that run tracker.policy (a learned walking policy)."""


def robot_variant(launch: LaunchFile) -> g1.Variant:
    """The G1 the launch file is for: what the simulator builds and the model-based controller models."""
    return g1.variant_named(launch.backend.expected_variant)


def check_policy_fits(spec: PolicySpec, launch: LaunchFile) -> None:
    """PolicyMismatchError naming the joints when the policy's joints are not the robot variant's."""
    variant = robot_variant(launch)
    missing = g1.missing_joints(variant, spec.joint_names)
    if missing:
        raise PolicyMismatchError(
            f"tracker.policy: policy '{spec.name}' commands {len(spec.joint_names)} joints, and the "
            f"{variant.name} G1 (backend.expected_variant, {variant.num_dof} DoF) has no {', '.join(missing)}; "
            f"use a policy made for {variant.name}, or tracker.type wbc (the model-based controller runs "
            "every variant from its own model)")
    uncommanded = [g1.JOINT_NAMES[i] for i in variant.active_joints if g1.JOINT_NAMES[i] not in spec.joint_names]
    if uncommanded:
        raise PolicyMismatchError(
            f"tracker.policy: policy '{spec.name}' commands {len(spec.joint_names)} joints and leaves "
            f"{', '.join(uncommanded)} of the {variant.name} G1 (backend.expected_variant) without a command; "
            f"use a policy made for {variant.name}")


def check_tracker_fits(launch: LaunchFile, spec: PolicySpec | None = None) -> None:
    """The launch file's tracker must fit its robot variant (see the module docstring). spec: the
    loaded tracker.policy when the caller has it (else it is loaded here, for the policy trackers)."""
    variant = robot_variant(launch)
    kind = launch.tracker.type
    if kind == "wbt" and variant.num_dof != g1.NUM_JOINTS:
        lacking = [g1.JOINT_NAMES[i] for i in range(g1.NUM_JOINTS) if i not in variant.active_joints]
        raise PolicyMismatchError(
            f"tracker.type wbt: holosoma's whole-body-tracking policy commands all {g1.NUM_JOINTS} joints of the "
            f"29-DoF G1, and the {variant.name} G1 (backend.expected_variant) has no {', '.join(lacking)}; "
            "use tracker.type wbc")
    if kind in POLICY_TRACKERS:
        if spec is None:
            from g1_control.trackers.policy_spec import load_spec

            spec = load_spec(launch.tracker.policy)
        check_policy_fits(spec, launch)
