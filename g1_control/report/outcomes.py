"""Goals judged from the simulator's ground truth: where the hands, the boxes and the feet really
were, against what each goal asked (not against the generator's own status).

    watcher = GoalWatcher(loop)          # a loop built from a launch file with a scene or goals
    loop.run(T, progress=watcher.tick)   # records at `record_hz`
    watcher.outcomes()                   # one dict per goal (see judge_goal)

Figures per goal kind:
  reach      hand point (wrist-yaw link + 0.1 m, the controller's hand frame) vs the point over the
             goal's hold window: mean and max error, fraction of the hold within REACH_TOLERANCE_M
  pick       box rise above where it stood (held), slip (box sinking relative to the hands while
             held), dropped (box more than DROP_M below its held height, or back on a surface
             before a place)
  place      box centre at the end vs where it was to go (horizontal and vertical), box tilt
  step_up    time with both soles on the platform's top; step_down: both soles on the floor at the end
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from g1_control.interfaces import Generator
    from g1_control.loop.control_loop import ControlLoop
    from g1_control.types import TaskGoal

REACH_TOLERANCE_M = 0.03
DROP_M = 0.05


class GoalWatcher:
    """Records ground truth while a loop runs (MuJoCo backends only) and judges its goals."""

    def __init__(self, loop: ControlLoop, record_hz: float = 50.0):
        from g1_control.sim.ground_truth import GroundTruthRecorder
        from g1_control.sim.mujoco_backend import MujocoBackend

        sim = loop.backend
        if not isinstance(sim, MujocoBackend):
            raise TypeError(f"GoalWatcher records MuJoCo's ground truth; the loop's backend is {sim.describe()}")
        self.loop, self.sim = loop, sim
        self.every = max(1, round(loop.rates.lowlevel_hz / record_hz))
        self.recorder = GroundTruthRecorder(sim)

    def tick(self, i: int) -> None:
        if i % self.every:
            return
        self.recorder.sample(float(self.sim.data.time))

    def arrays(self) -> dict[str, np.ndarray]:
        return self.recorder.arrays()

    def outcomes(self) -> list[dict]:
        gen = self.loop.generator  # what it recorded per goal (Generator.goal_info, goal_messages)
        info, messages = gen.goal_info, gen.goal_messages
        a = self.arrays()
        return [dict(judge_goal(gid, dict(i), a), message=messages.get(gid)) for gid, i in info.items()]


def judge_goal(goal_id: str, info: dict, a: dict[str, np.ndarray]) -> dict:
    """Ground-truth figures for one goal (module docstring); `info` from GoalGenerator.goal_info."""
    out = {"goal_id": goal_id, "kind": info.get("kind"), "describe": info.get("describe"),
           "status": info.get("status") or "unfinished", "start_s": info.get("start_s"), "end_s": info.get("end_s")}
    t = a["t_s"]
    if len(t) == 0:
        return out
    kind = info.get("kind")
    # the object handled: a box (both hands) or a bottle (one hand), its ground truth under its kind's key
    what = "bottle" if info.get("bottle") else "box"
    key = f"{what}_{info.get(what)}" if info.get(what) else None
    if key is not None:
        out["object_kind"] = what
    holding = [0, 1] if what == "box" else [{"left": 0, "right": 1}[info.get("hand", "right")]]  # hands it is in
    if kind == "reach" and "hold_s" in info:
        t0, t1 = info["hold_s"]
        rows = (t >= t0) & (t <= t1)
        target = np.asarray(info["target_w_m"])
        hands = {"left": [0], "right": [1], "both": [0, 1]}[info.get("hand", "right")]
        if rows.any() and info.get("hand") != "both":
            err = np.linalg.norm(a["hands_w_m"][rows][:, hands[0]] - target, axis=1)
            out.update(hand_error_mean_m=float(err.mean()), hand_error_max_m=float(err.max()),
                       within_tolerance=float((err <= REACH_TOLERANCE_M).mean()), hold_samples=int(rows.sum()))
    elif kind == "pick" and key is not None and key in a:
        box = a[key][:, :3]
        start = np.asarray(info.get("object_start_w_m", info.get("box_start_w_m")))
        held = t >= info.get("held_from_s", np.inf)
        end = t <= (info.get("end_s") or t[-1])
        rows = held & end
        if rows.any():
            rise = box[rows, 2] - start[2]
            hands_z = a["hands_w_m"][rows][:, holding, 2].mean(axis=1)
            rel = (box[rows, 2] - hands_z) - (box[rows, 2][0] - hands_z[0])
            out.update(box_rise_m=float(rise.mean()), slip_m=float(max(0.0, -rel.min())),
                       dropped=bool(rise.min() < info.get("lift_m", 0.1) - DROP_M))
    elif kind == "place" and key is not None and key in a:
        rows = a[key]
        final, target = rows[-1], np.asarray(info["target_w_m"])
        qx, qy = final[4], final[5]
        up = 1.0 - 2.0 * (qx * qx + qy * qy)  # the box's z axis against the world's
        out.update(place_error_xy_m=float(np.linalg.norm(final[:2] - target[:2])),
                   place_error_z_m=float(final[2] - target[2]),
                   box_tilt_deg=float(math.degrees(math.acos(max(-1.0, min(1.0, up))))),
                   box_final_w_m=final[:3].tolist())
        if "start_s" in info:
            carried = (t >= info["start_s"]) & (t <= info.get("released_s", t[-1]))
            if carried.any():
                hands_z = a["hands_w_m"][carried][:, holding, 2].mean(axis=1)
                rel = rows[carried, 2] - hands_z
                out["dropped"] = bool(rel.min() < rel[0] - DROP_M)
    elif kind in ("step_up", "step_down"):
        soles = a["soles_w_m"]
        h = info.get("height_m", 0.15)
        window = (t >= (out["start_s"] or 0.0)) & (t <= (out["end_s"] or t[-1]))
        up = np.asarray((soles[:, :, 2] > h - 0.015).all(axis=1))
        if kind == "step_up":
            out["both_feet_on_top_s"] = float(up[window].sum() * np.median(np.diff(t))) if window.any() else 0.0
            out["on_top_at_end"] = bool(up[window][-1]) if window.any() else False
        else:
            down = np.asarray((soles[:, :, 2] < 0.015).all(axis=1))
            out["on_floor_at_end"] = bool(down[window][-1]) if window.any() else False
    return out


def goal_reports(generator: Generator, planned: Sequence[TaskGoal] = ()) -> list[dict]:
    """Every goal's status and message as the execution layer (GoalGenerator) reports them, without
    ground truth (the robot path): the goals that started, in order, then those `planned` (a launch
    file's timeline) that never started, as 'not started'. Each dict as judge_goal's, plus message and,
    for a goal that started, `record`: the execution layer's record of it (GoalGenerator.goal_info: its
    times, target, box), from which judge_goal judges it against a simulator's ground truth later
    (g1_control/tools/judge_sim2sim.py)."""
    info, messages = generator.goal_info, generator.goal_messages
    out = [dict(judge_goal(gid, dict(i), {"t_s": np.zeros(0)}), message=messages.get(gid), record=_plain(i))
           for gid, i in info.items()]
    for goal in planned:
        if goal.goal_id not in info:
            out.append({"goal_id": goal.goal_id, "kind": goal.kind, "describe": goal.describe(),
                        "status": "not started", "start_s": None, "end_s": None,
                        "message": "control ended before the goal's turn came"})
    return out


def _plain(value):
    """A goal record as JSON holds it (arrays and tuples as lists)."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def outcome_line(o: dict) -> str:
    """One line per goal for a run summary."""
    text = f"goal {o['goal_id']} ({o.get('describe')}): {o['status']}"
    msg = o.get("message")
    if o.get("kind") == "reach" and "hand_error_mean_m" in o:
        text += (f"; hand within {REACH_TOLERANCE_M * 100:.0f} cm {100 * o['within_tolerance']:.0f} % of the hold, "
                 f"mean error {o['hand_error_mean_m'] * 1000:.0f} mm")
    what = o.get("object_kind", "box")
    if "box_rise_m" in o:
        text += f"; {what} lifted {o['box_rise_m'] * 100:.1f} cm, slip {o['slip_m'] * 1000:.0f} mm" + \
            (", DROPPED" if o["dropped"] else "")
    if "place_error_xy_m" in o:
        text += (f"; {what} {o['place_error_xy_m'] * 100:.1f} cm from where it was to go (z {o['place_error_z_m'] * 100:+.1f} cm, "
                 f"tilt {o['box_tilt_deg']:.1f} deg)") + (", DROPPED on the way" if o.get("dropped") else "")
    if "both_feet_on_top_s" in o:
        text += f"; both feet on the platform {o['both_feet_on_top_s']:.1f} s"
    if "on_floor_at_end" in o:
        text += "; both feet on the floor at the end" if o["on_floor_at_end"] else "; NOT back on the floor"
    if msg:
        text += f" ({msg})"
    return text


__all__ = ["GoalWatcher", "goal_reports", "judge_goal", "outcome_line"]
