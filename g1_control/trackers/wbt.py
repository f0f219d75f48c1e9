"""The comparison baseline: holosoma's whole-body-tracking policy (ppo_g1_29dof_dancing.onnx)
fed our references, as a Tracker.

The policy was trained on one dance clip; its observation still carries the reference it should
follow, so new references go in through the same terms (docs/robot_facts.md). Actor observation, the terms
concatenated in alphabetical order of their names (154 values):
  actions (29, last action), base_ang_vel (3, pelvis gyro), dof_pos (29, q - default),
  dof_vel (29), motion_command (58: reference joint positions then velocities),
  motion_ref_ori_b (6: first two columns of R_robot_torso^T R_reference_torso, row-major).
Action: q* = default + 0.25 * effort_limit / kp * action (the config's
action_scales_by_effort_limit_over_p_gain), at 50 Hz with the kp/kd stored in the ONNX.
`time_step` only indexes the stored clip; it is passed as the tick count.
"""

from __future__ import annotations

import json

import numpy as np

from g1_control.errors import PolicyMismatchError
from g1_control.interfaces import Tracker
from g1_control.robot import g1
from g1_control.types import JointReference, MotorCommand, RobotState

POLICY_FILE = "holosoma_inference/models/wbt/ppo_g1_29dof_dancing.onnx"
RATE_HZ = 50.0


class WbtPolicyTracker(Tracker):
    def __init__(self) -> None:
        import pinocchio as pin

        from g1_control.assets import fetch
        from g1_control.robot.dynamics import build_model
        from g1_control.trackers.onnx_runner import OnnxRunner

        path = fetch("holosoma-policies") / POLICY_FILE
        self._time_step = np.zeros((1, 1), dtype=np.float32)
        self.runner = OnnxRunner(path, "obs", {"time_step": self._time_step})
        meta = self.runner.session.get_modelmeta().custom_metadata_map
        names = tuple(json.loads(meta["dof_names"]))
        if names != g1.JOINT_NAMES:
            raise PolicyMismatchError(f"{path.name}: joint order {names} differs from g1.JOINT_NAMES")
        cfg = json.loads(meta["experiment_config"])
        self.kp = np.array(json.loads(meta["kp"]))
        self.kd = np.array(json.loads(meta["kd"]))
        defaults = cfg["robot"]["init_state"]["default_joint_angles"]
        self.default_q = np.array([defaults[n] for n in g1.JOINT_NAMES])
        effort = np.array(cfg["robot"]["dof_effort_limit_list"])
        self.action_scale = cfg["robot"]["control"]["action_scale"] * effort / self.kp
        size = self.runner.session.get_inputs()[0].shape[1]
        if size != 154:
            raise PolicyMismatchError(f"{path.name}: observation size {size}; this adapter builds 154")
        self._pin = pin
        self.model = build_model()
        self.data = self.model.createData()
        self._torso = self.model.getFrameId(g1.TORSO_BODY)
        self._q = np.zeros(self.model.nq)
        self._obs = np.zeros((1, 154), dtype=np.float32)
        self.last_action = np.zeros(g1.NUM_JOINTS)
        self._command = MotorCommand(q_rad=self.default_q.copy(), kp=self.kp.copy(), kd=self.kd.copy())
        self._ticks = 0

    def reset(self, state: RobotState | None = None) -> None:
        self.last_action[:] = 0.0
        self._ticks = 0

    def _torso_rot(self, quat_wxyz: np.ndarray, q_rad: np.ndarray) -> np.ndarray:
        q = self._q
        q[3:7] = (quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0])
        q[7:] = q_rad
        self._pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self._torso].rotation.copy()

    def act(self, reference: JointReference, state: RobotState) -> MotorCommand:
        rel = self._torso_rot(state.imu_quat_wxyz, state.q_rad).T @ self._torso_rot(reference.root_quat_wxyz,
                                                                                      reference.q_rad)
        obs = np.concatenate([self.last_action, state.imu_gyro_radps, state.q_rad - self.default_q, state.dq_radps,
                              reference.q_rad, reference.dq_radps, rel[:, :2].reshape(6)])
        self._obs[0] = obs
        self._time_step[0, 0] = self._ticks
        self._ticks += 1
        action = np.asarray(self.runner(self._obs), dtype=float)
        self.last_action = action
        self._command.q_rad[:] = self.default_q + self.action_scale * action
        return self._command
