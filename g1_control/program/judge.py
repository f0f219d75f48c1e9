"""Judge a finished program step from ground truth (the simulator's pose), not from the runner's
own verdict: did the robot really walk the distance, turn the angle, reach the place?

Criteria (issue 15): a walk by a distance within 10 % of it, along the direction the walk
started in; a turn within 10 degrees (the yaw turned by ground truth, accumulated tick by tick,
so 360-degree turns count); a walk to a place within 10 % of the way there (at least 5 cm) of
its stop point; a turn to a heading or a place within 10 degrees of it; a height step within
5 cm of the height asked for (posture "normal": the walking policy's own, not judged); a goal
step (reach, pick, place, step) by the execution layer's ground-truth figures (goal_verdict, from
g1_control/report/outcomes.py: where the hand, the box and the feet really were); stands, styles
and timed walks by having run their time.
"""

from __future__ import annotations

import math

from g1_control.program.records import PlanarPose, StepRecord
from g1_control.program.runner import COMPLETED, RunnerConfig, wrap_angle
from g1_control.program.steps import Height, Parallel, Stand, Style, Turn, Walk
from g1_control.program.world import START, World
from g1_control.report.verdict import Verdict

DISTANCE_TOLERANCE = 0.10
"""Relative: a walk's distance (or the way to a place) within this fraction."""
MIN_PLACE_TOLERANCE_M = 0.05
HEADING_TOLERANCE_RAD = math.radians(10.0)
HEIGHT_TOLERANCE_M = 0.05
_REL = {"forward": 0.0, "left": math.pi / 2, "backward": math.pi, "right": -math.pi / 2}


def judge(record: StepRecord, world: World, program_start: PlanarPose | None,
          config: RunnerConfig | None = None) -> Verdict | None:
    """The ground-truth verdict on one step (None without ground truth)."""
    a, b = record.truth_start, record.truth_end
    if a is None or b is None:
        return None
    step = record.step
    main = step.main if isinstance(step, Parallel) else step
    done = record.outcome.status == COMPLETED
    if isinstance(main, Walk):
        return _walk(main, a, b, world, program_start, done)
    if isinstance(main, Turn):
        return _turn(main, record.truth_turned_rad or 0.0, a, b, world, program_start)
    if isinstance(main, Stand):
        drift = math.hypot(b.x_m - a.x_m, b.y_m - a.y_m)
        return Verdict(done, f"stood {record.outcome.ended_s - record.outcome.started_s:.1f} s, drift {drift:.2f} m",
                       {"drift_m": drift})
    if isinstance(main, Height):
        cfg = config or RunnerConfig()
        want = main.pelvis_height_m if main.pelvis_height_m is not None else cfg.posture_height_m[main.posture or ""]
        got = b.pelvis_height_m
        if want is None or got is None:
            return Verdict(done, f"{main.describe()}: pelvis {got if got is None else round(got, 3)} m (not judged)")
        err = got - want
        return Verdict(done and abs(err) <= HEIGHT_TOLERANCE_M, f"pelvis {got:.3f} m for {want:.3f} m ({err:+.3f} m)",
                       {"pelvis_height_m": got, "error_m": err})
    if isinstance(main, Style):
        return Verdict(done, f"{main.name} held {record.outcome.ended_s - record.outcome.started_s:.1f} s")
    # goal steps: the execution layer's status until its ground-truth figures replace it (goal_verdict,
    # after the run: g1_control/launch/runner.py)
    return Verdict(done, f"execution layer: {record.outcome.status}" + (f" ({record.message})" if record.message else ""))


def _place_xy(name: str, world: World, program_start: PlanarPose | None) -> tuple[float, float, float]:
    if name == START:
        assert program_start is not None  # a program that ran has a start
        return program_start.x_m, program_start.y_m, 0.0
    lm = world.get(name)
    return float(lm.pos_w_m[0]), float(lm.pos_w_m[1]), lm.stop_distance_m()


def _walk(w: Walk, a: PlanarPose, b: PlanarPose, world: World, program_start: PlanarPose | None,
          done: bool) -> Verdict:
    dx, dy = b.x_m - a.x_m, b.y_m - a.y_m
    if w.target is not None:
        px, py, stop = _place_xy(w.target, world, program_start)
        path = max(0.0, math.hypot(px - a.x_m, py - a.y_m) - stop)
        left = math.hypot(px - b.x_m, py - b.y_m) - stop
        tol = max(DISTANCE_TOLERANCE * path, MIN_PLACE_TOLERANCE_M)
        return Verdict(abs(left) <= tol, f"{left:+.2f} m from the stop point of {w.target} after {path:.2f} m "
                       f"(tolerance {tol:.2f} m)", {"stop_error_m": left, "path_m": path})
    ang = (w.heading_rad if w.heading_rad is not None else a.yaw_rad) + _REL[w.direction]
    along = dx * math.cos(ang) + dy * math.sin(ang)
    side = -dx * math.sin(ang) + dy * math.cos(ang)
    if w.distance_m is None:
        return Verdict(done, f"walked {along:.2f} m {w.direction} in its time (sideways {side:+.2f} m)",
                       {"distance_m": along, "lateral_m": side})
    err = along - w.distance_m
    rel = err / w.distance_m
    return Verdict(abs(rel) <= DISTANCE_TOLERANCE, f"walked {along:.2f} m of {w.distance_m:.3g} ({100 * rel:+.1f} %, "
                   f"sideways {side:+.2f} m)", {"distance_m": along, "error_rel": rel, "lateral_m": side})


def _turn(t: Turn, turned: float, a: PlanarPose, b: PlanarPose, world: World,
          program_start: PlanarPose | None) -> Verdict:
    if t.angle_rad is not None:
        want = t.angle_rad if t.direction == "left" else -t.angle_rad
        err = turned - want
        return Verdict(abs(err) <= HEADING_TOLERANCE_RAD, f"turned {math.degrees(turned):+.1f} deg of "
                       f"{math.degrees(want):+.0f} ({math.degrees(err):+.1f} deg)",
                       {"turned_rad": turned, "error_rad": err})
    if t.heading_rad is not None:
        goal = t.heading_rad
        what = f"heading {math.degrees(goal):.0f} deg"
    else:
        assert t.target is not None  # a valid Turn has an angle, a heading or a target
        px, py, _ = _place_xy(t.target, world, program_start)
        goal = math.atan2(py - b.y_m, px - b.x_m)
        what = f"facing {t.target}"
    err = wrap_angle(b.yaw_rad - goal)
    return Verdict(abs(err) <= HEADING_TOLERANCE_RAD, f"{what}: off by {math.degrees(err):+.1f} deg",
                   {"error_rad": err})


REACH_TOLERANCE_M = 0.03
"""A reach: the hand's mean distance to the point over the hold (the execution layer's 3 cm)."""
PLACE_TOLERANCE_M = 0.05
PLACE_TILT_DEG = 10.0
PICK_MIN_RISE_M = 0.05


def goal_verdict(outcome: dict) -> Verdict:
    """A goal step judged from the execution layer's ground-truth figures (g1_control/report/outcomes.py:
    judge_goal): reach: mean hand error within 3 cm over the hold; pick: box lifted >= 5 cm and not
    dropped; place: box within 5 cm of where it was to go, tilted under 10 degrees, not dropped;
    step up: both feet on the platform at the end; step down: both on the floor. A goal the layer
    did not reach is missed whatever the figures."""
    kind, status = outcome.get("kind"), outcome.get("status")
    reached = status == "reached"
    why = f" ({outcome['message']})" if outcome.get("message") else ""
    if kind == "reach" and "hand_error_mean_m" in outcome:
        err = outcome["hand_error_mean_m"]
        return Verdict(reached and err <= REACH_TOLERANCE_M, f"hand {err * 1000:.0f} mm from the point (mean over "
                       f"the hold)" + why, {"hand_error_m": err})
    if kind == "pick" and "box_rise_m" in outcome:
        rise, dropped = outcome["box_rise_m"], outcome.get("dropped", False)
        return Verdict(reached and rise >= PICK_MIN_RISE_M and not dropped,
                       f"box lifted {rise * 100:.1f} cm" + (", DROPPED" if dropped else "") + why, {"box_rise_m": rise})
    if kind == "place" and "place_error_xy_m" in outcome:
        xy, z, tilt = outcome["place_error_xy_m"], outcome["place_error_z_m"], outcome["box_tilt_deg"]
        ok = reached and xy <= PLACE_TOLERANCE_M and abs(z) <= PLACE_TOLERANCE_M and tilt <= PLACE_TILT_DEG \
            and not outcome.get("dropped", False)
        return Verdict(ok, f"box {xy * 100:.1f} cm from its place (z {z * 100:+.1f} cm, tilt {tilt:.1f} deg)" + why,
                       {"place_error_xy_m": xy, "place_error_z_m": z, "box_tilt_deg": tilt})
    if kind == "step_up" and "on_top_at_end" in outcome:
        return Verdict(reached and outcome["on_top_at_end"], f"both feet on the platform {outcome['both_feet_on_top_s']:.1f} s"
                       + ("" if outcome["on_top_at_end"] else ", NOT on it at the end") + why)
    if kind == "step_down" and "on_floor_at_end" in outcome:
        return Verdict(reached and outcome["on_floor_at_end"], ("both feet on the floor" if outcome["on_floor_at_end"]
                                                                else "NOT back on the floor") + why)
    # no ground-truth figures for this goal (e.g. a reach with both hands): the layer's own status
    return Verdict(reached, f"execution layer: {status} (no ground-truth figures for this goal)" + why)


__all__ = ["DISTANCE_TOLERANCE", "HEADING_TOLERANCE_RAD", "HEIGHT_TOLERANCE_M", "goal_verdict", "judge"]
