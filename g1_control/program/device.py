"""A behaviour program as the control loop's input: an InputDevice that steps a ProgramRunner.

    device = ProgramInput(program, world)              # pose from the robot's own estimate
    loop = build_loop(launch, input_device=device)     # the loop feeds it back (observe) before each poll
    ... loop runs; device.records: one StepRecord per step, judged against ground truth

What the runner steers by is what the robot itself has (pose="estimator", the default): the loop's
world pose estimate where it runs one (ExecutionFeedback.pose: leg odometry anchored at the stance
feet, fused with an external pose where configured; estimation/localiser.py), else the state
estimator's yaw (IMU) and its base velocity integrated into a planar position (Odometry below). On the robot there is nothing else; in simulation the same holds, so
a program behaves in MuJoCo as it would on the robot, odometry drift included. pose="ground_truth"
steers by the simulator's pose instead (for comparing the two). Either way, in simulation every
step is also *judged* from ground truth (StepRecord.truth_*, g1_control/program/judge.py): the
runner's own verdict ("completed") says only that odometry thinks it is there.

Goal steps (reach, pick, place, step up/down) are handed to the execution layer through
Command.tasks (GoalRequest.to_task_goal, the one mapping); their status comes back through the
loop's feedback record (ExecutionFeedback: the generator's goal_status, goal_messages and phase,
the estimate, ground truth), which the loop gives the device before every poll (observe).

With an `operator` device (g1 deploy: the remote or keyboard with the e-stop), buttons and loss
come from the operator and motion from the program.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from g1_control.interfaces import InputDevice
from g1_control.program.judge import judge
from g1_control.program.program import Program
from g1_control.program.records import PlanarPose, StepRecord
from g1_control.program.runner import ProgramProgress, ProgramRunner, RunnerConfig, wrap_angle
from g1_control.program.world import World
from g1_control.rotations import yaw_of
from g1_control.types import PHASE_LOCOMOTION, Command, EstimatedState, ExecutionFeedback, RobotState

POSE_SOURCES = ("estimator", "ground_truth")
HAND_BACK_SETTLE_S = 0.5
"""After the execution layer hands the robot back to the walking policy (its 0.3 s blend), a
locomotion step that was waiting for it starts this much later."""


def truth_pose(state: RobotState) -> PlanarPose | None:
    """The simulator's ground truth (None on a robot: no base position in its state)."""
    if state.base_pos_w_m is None:
        return None
    x, y, z = state.base_pos_w_m.tolist()
    return PlanarPose(x, y, yaw_of(state.imu_quat_wxyz), z)


class Odometry:
    """Planar pose from the state estimator: yaw from the IMU, position by integrating the
    estimator's world-frame base velocity (leg kinematics + accelerometer) over its own time
    stamps. Starts at (0, 0): the robot's start, which is also the world origin of a scene."""

    def __init__(self, x_m: float = 0.0, y_m: float = 0.0) -> None:
        self.x_m, self.y_m = x_m, y_m
        self._last_t: float | None = None

    def pose(self, est: EstimatedState) -> PlanarPose:
        """The pose after `est` (the estimator's latest output; an estimate seen before adds nothing)."""
        if self._last_t is not None and est.t_s > self._last_t:
            dt = est.t_s - self._last_t
            vx, vy, _ = est.base_linvel_w_mps.tolist()
            self.x_m += vx * dt
            self.y_m += vy * dt
        self._last_t = est.t_s
        return PlanarPose(self.x_m, self.y_m, est.yaw_rad, est.pelvis_height_m)


@dataclass
class _Open:
    truth_start: PlanarPose | None
    turned: float = 0.0
    goal_id: str | None = None


class ProgramInput(InputDevice):
    """See the module docstring. `on_record(record)` is called as each step finishes."""

    def __init__(self, program: Program, world: World | None = None, config: RunnerConfig | None = None, *,
                 pose: str = "estimator", start_delay_s: float = 1.0, operator: InputDevice | None = None,
                 on_record: Callable[[StepRecord], None] | None = None) -> None:
        if pose not in POSE_SOURCES:
            raise ValueError(f"pose: {pose!r} is not one of {', '.join(POSE_SOURCES)}")
        self.runner = ProgramRunner(program, world, config)
        self.program = self.runner.program
        self.world = self.runner.world
        self.pose_source = pose
        self.start_delay_s = start_delay_s
        """Stand this long (loop clock) before the first step: the walking policy settles."""
        self.operator = operator
        self.on_record = on_record
        self.program_clock: Callable[[], float] | None = None
        """The program's own clock (g1 deploy: seconds since control started, 0 before); None: the
        loop's. The operator device is always polled with the loop's clock."""
        self.records: list[StepRecord] = []
        self.truth_start: PlanarPose | None = None
        self.started_s: float | None = None
        self.ended_s: float | None = None
        self._feedback: ExecutionFeedback | None = None
        self._odometry = Odometry()
        self._handed_back_s: float | None = None
        self._restart_label: str | None = None
        self._open: dict[str, _Open] = {}
        self._last_truth_yaw: float | None = None
        self._t0: float | None = None

    # -- wiring ---------------------------------------------------------------------------------
    def observe(self, feedback: ExecutionFeedback) -> None:
        """The loop's feedback record (the same instance every tick): the estimate it steers by,
        ground truth where the backend gives it, the generator's goal verdicts and phase."""
        self._feedback = feedback
        if self.operator is not None:
            self.operator.observe(feedback)

    @property
    def done(self) -> bool:
        return self.runner.done

    @property
    def lost(self) -> bool:
        return self.operator.lost if self.operator is not None else False

    @property
    def lost_reason(self) -> str | None:
        return self.operator.lost_reason if self.operator is not None else None

    def button_chords(self, action: str) -> list[str]:
        """The operator device's (g1 deploy names its keys); [] without one."""
        return self.operator.button_chords(action) if self.operator is not None else []

    def close(self) -> None:
        if self.operator is not None:
            self.operator.close()

    # -- the tick -------------------------------------------------------------------------------
    def _truth(self) -> PlanarPose | None:
        fb = self._feedback
        return truth_pose(fb.truth) if fb is not None and fb.truth is not None else None

    def _pose(self, truth: PlanarPose | None) -> PlanarPose:
        if self.pose_source == "ground_truth":
            if truth is None:
                raise RuntimeError("pose 'ground_truth' needs a simulator (the robot's state has no base position)")
            return truth
        if self._feedback is None:
            raise RuntimeError("ProgramInput is not attached to a loop: it steers by the loop's feedback "
                               "(ControlLoop gives it before every poll, InputDevice.observe)")
        fb = self._feedback
        if fb.pose is not None:  # the loop's localiser (leg odometry, fused): a robot link, or steer_by estimate
            p = fb.pose
            return PlanarPose(p.x_m, p.y_m, p.yaw_rad, fb.estimate.pelvis_height_m)
        return self._odometry.pose(fb.estimate)

    def poll(self, now_s: float) -> Command:
        op = self.operator.poll(now_s) if self.operator is not None else None
        if self.program_clock is not None:
            now_s = self.program_clock()
        truth = self._truth()
        pose = self._pose(truth)
        if truth is not None and self._last_truth_yaw is not None:
            d = wrap_angle(truth.yaw_rad - self._last_truth_yaw)
            for o in self._open.values():
                o.turned += d
        self._last_truth_yaw = truth.yaw_rad if truth is not None else None
        if self._t0 is None:
            self._t0 = now_s
        if now_s - self._t0 < self.start_delay_s or self.runner.done:
            command = self.runner.hold_command()
        else:
            if self.started_s is None:
                self.started_s, self.truth_start = now_s, truth
            command = self._step(now_s, pose, truth)
        if op is not None:
            command.buttons = op.buttons
        return command

    def _step(self, now_s: float, pose: PlanarPose, truth: PlanarPose | None) -> Command:
        runner = self.runner
        n = len(runner.outcomes)
        goals = runner.active_goals
        fb = self._feedback
        verdicts = fb.goal_status if fb is not None else {}
        status = {g.goal_id: verdicts[g.goal_id] for g in goals if g.goal_id in verdicts}
        progress = ProgramProgress(pose.x_m, pose.y_m, pose.yaw_rad, status, pose.pelvis_height_m)
        self._after_hand_back(now_s, progress, truth)
        command = runner.update(now_s, progress)
        for outcome in runner.outcomes[n:]:
            opened = self._open.pop(outcome.label, None) or _Open(truth)
            record = StepRecord(outcome, runner.step_of(outcome.label), opened.truth_start, truth,
                                opened.turned if truth is not None else None, opened.goal_id,
                                fb.goal_messages.get(opened.goal_id) if opened.goal_id and fb is not None else None)
            if truth is not None:
                record.verdict = judge(record, self.world, self.truth_start)
            self.records.append(record)
            if self.on_record is not None:
                self.on_record(record)
        label = runner.current_label
        if label is not None and label not in self._open:
            active = runner.active_goals
            self._open[label] = _Open(truth, goal_id=active[0].goal_id if active else None)
        if runner.done and self.ended_s is None:
            self.ended_s = now_s
        return command

    def _after_hand_back(self, now_s: float, progress: ProgramProgress, truth: PlanarPose | None) -> None:
        """A walk, turn or wait that starts while the execution layer still holds the robot in a
        whole-body phase (after a reach, a place, a step down) commands motion, which makes the layer
        hand back to the walking policy; the step then starts over HAND_BACK_SETTLE_S after the
        policy has it, so its distance, heading and time are the walk's, not the hand-over's."""
        label = self.runner.current_label
        if label is None or not self.runner.active_is_locomotion:
            self._restart_label = None
            return
        phase = self._feedback.phase if self._feedback is not None else PHASE_LOCOMOTION
        if phase != PHASE_LOCOMOTION:
            self._restart_label, self._handed_back_s = label, None
            return
        if self._restart_label != label:
            return
        if self._handed_back_s is None:
            self._handed_back_s = now_s
        if now_s - self._handed_back_s >= HAND_BACK_SETTLE_S:
            self.runner.restart_active(now_s, progress)
            self._open[label] = _Open(truth)
            self._restart_label = None

    def summary(self) -> str:
        return "\n".join(describe_record(r) for r in self.records)


def record_dict(record: StepRecord) -> dict:
    """A StepRecord as plain data (run summaries, JSON)."""
    o = record.outcome
    out: dict = {"label": o.label, "kind": o.kind, "description": o.description, "status": o.status,
                 "started_s": o.started_s, "ended_s": o.ended_s, "measured": dict(o.measured)}
    for name, pose in (("truth_start", record.truth_start), ("truth_end", record.truth_end)):
        out[name] = None if pose is None else [pose.x_m, pose.y_m, pose.yaw_rad, pose.pelvis_height_m]
    out["truth_turned_rad"] = record.truth_turned_rad
    if record.goal_id is not None:
        out["goal_id"] = record.goal_id
    if record.message:
        out["message"] = record.message
    if record.verdict is not None:
        v = record.verdict
        out["verdict"] = {"ok": v.ok, "text": v.text, "values": dict(v.values)}
    return out


def describe_record(record: StepRecord) -> str:
    """'2. turn left 90 deg: completed after 3.1 s (turned_rad 1.55, ...) | ground truth: turned 88.9 deg
    of 90 (-1.1 deg) OK'."""
    line = record.outcome.describe()
    if record.verdict is not None:
        line += f" | ground truth: {record.verdict.text} {'OK' if record.verdict.ok else 'MISSED'}"
    return line


__all__ = ["POSE_SOURCES", "Odometry", "PlanarPose", "ProgramInput", "StepRecord", "describe_record", "record_dict",
           "truth_pose"]
