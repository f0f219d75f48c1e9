"""The 131 s dance clip stored inside holosoma's WBT policy (docs/robot_facts.md), as a MotionClip.

The ONNX graph holds the reference motion as constants indexed by its `time_step` input
(policy steps at 50 Hz); its outputs joint_pos, ref_pos_xyz and ref_quat_xyzw are the
reference pelvis pose and joints at that step. Reading them through onnxruntime needs no extra
package. Past the last step the outputs repeat, which is how the clip's length is found.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from g1_control.motion.clip import MotionClip
from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.interpolation import interpolate_positions, interpolate_quaternions
from g1_control.robot import g1

POLICY_RATE_HZ = 50.0
STANCE_ANKLE_HEIGHT_M = 0.034
"""Ankle-roll-link origin height of a stance foot in the physics rollouts (measured, median)."""
MAX_STEPS = 20000


def default_dance_onnx() -> Path:
    from g1_control.assets import fetch

    return fetch("holosoma-policies") / "holosoma_inference" / "models" / "wbt" / "ppo_g1_29dof_dancing.onnx"


def extract_dance(onnx_path: str | Path | None = None, fps: float = 30.0) -> MotionClip:
    import onnxruntime as ort

    path = Path(onnx_path) if onnx_path else default_dance_onnx()
    if not path.is_file():
        raise MotionFormatError(f"{path}: no such ONNX file")
    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    names = {o.name for o in sess.get_outputs()}
    needed = {"joint_pos", "ref_pos_xyz", "ref_quat_xyzw"}
    if not needed <= names or "time_step" not in {i.name for i in sess.get_inputs()}:
        raise MotionFormatError(f"{path}: not a WBT policy with a stored clip (needs input time_step and "
                                f"outputs {sorted(needed)}; has {sorted(names)})")
    obs_in = sess.get_inputs()[0]
    obs = np.zeros((1, int(obs_in.shape[1])), np.float32)
    joints: list[np.ndarray] = []
    pos: list[np.ndarray] = []
    quat_xyzw: list[np.ndarray] = []
    for step in range(MAX_STEPS):
        j, p, q = sess.run(["joint_pos", "ref_pos_xyz", "ref_quat_xyzw"],
                           {obs_in.name: obs, "time_step": np.array([[step]], np.float32)})
        if step > 0 and np.array_equal(j, joints[-1][None]) and np.array_equal(p, pos[-1][None]):
            break  # clamped past the end
        joints.append(j[0].astype(float))
        pos.append(p[0].astype(float))
        quat_xyzw.append(q[0].astype(float))
    joints_a, pos_a = np.array(joints), np.array(pos)
    quat_wxyz = np.array(quat_xyzw)[:, [3, 0, 1, 2]]
    quat_wxyz /= np.linalg.norm(quat_wxyz, axis=1, keepdims=True)
    # Measured: in this reference the lowest ankle sits 4-5 cm higher than a stance ankle in our
    # MuJoCo scene (its training used another URDF/scene). Level it so that the lower quartile
    # of the lowest ankle height matches our stance height; nothing else is changed.
    lowest = np.array([_lowest_ankle_z(p_, q_, j_) for p_, q_, j_ in
                       zip(pos_a[::25], quat_wxyz[::25], joints_a[::25])])
    pos_a[:, 2] -= np.percentile(lowest, 25) - STANCE_ANKLE_HEIGHT_M
    times = np.arange(int((len(joints) - 1) / POLICY_RATE_HZ * fps) + 1) / fps
    joints_r = np.clip(interpolate_positions(joints_a, POLICY_RATE_HZ, times), g1.Q_MIN_RAD, g1.Q_MAX_RAD)
    return MotionClip.from_joint_trajectory(
        fps, interpolate_positions(pos_a, POLICY_RATE_HZ, times), interpolate_quaternions(quat_wxyz, POLICY_RATE_HZ, times),
        joints_r, source="holosoma_wbt_dance", style="dance", tags=("wbt", "dance"))


def _lowest_ankle_z(root_pos: np.ndarray, root_quat: np.ndarray, joints: np.ndarray) -> float:
    from g1_control.motion.kinematics import forward_kinematics

    pos, _ = forward_kinematics(root_pos[None], root_quat[None], joints[None], g1.FOOT_BODIES)
    return float(pos[0, :, 2].min())
