"""Goal rows of `g1 bench execution` (issue 17 part 2): reaching, standing heights, the box, the
step. Every trial runs the tracking layer (walking policy + WBC, launch tracker.type layer) in
MuJoCo through the one loop builder, with seeded scenes and goals; every figure comes from the
simulator's ground truth (g1_control/report/outcomes.py), not from the goal generator's status.

  reach.left / reach.right   20 seeded points in the hand's workspace, reached one after another
                             while standing: hand within 3 cm for >= 90 % of each 1.5 s hold
                             counts; the row needs >= 90 % of the points and no fall
  height.<style>             pelvis 0.45, 0.55, 0.65, 0.75 m standing with the style's arms: the
                             mean pelvis height over the last 2 s of each within 3 cm, no fall
  box.table                  10 seeded layouts: a 2 kg, 0.3 m box on a 0.7 m table 2 m from the
                             robot, picked with both hands, carried 3 m, put on a second table:
                             placed within 10 cm and never dropped in >= 8 of 10
  box.floor (stretch)        the same with the box on the floor, set down on the floor 3 m away
  step                       10 seeded approaches to a 0.15 m platform: up (both feet on top) and
                             back down (both feet on the floor), no fall, in >= 8 of 10

Workspace of a hand (reach rows): points 0.20-0.50 m from its shoulder joint (standing), azimuth
-100..+20 degrees from straight ahead (negative: outward), 0.55-1.30 m above the floor.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from g1_control.generator.styles import ROLLOUT_STYLES
from g1_control.report.verdict import Verdict, figures
from g1_control.scene import Box, Platform, SceneConfig, Table
from g1_control.teleop.scripted import GoalEntry, Segment
from g1_control.tools.physics_trials import Trial, TrialResult

LAYER_HZ = 100.0
REACH_POINTS = 20
REACH_HOLD_FRACTION = 0.9
REACH_TOLERANCE_M = 0.03
SHOULDER_W_M = {"left": np.array([0.0, 0.100, 1.048]), "right": np.array([0.0, -0.100, 1.048])}
"""The shoulder-pitch joints of the default standing pose at the origin (robot/description.py)."""
HEIGHTS_M = (0.45, 0.55, 0.65, 0.75)
HEIGHT_TOLERANCE_M = 0.03
BOX_LAYOUTS = 10
PLACE_TOLERANCE_M = 0.10
STEP_APPROACHES = 10
STEP_HEIGHT_M = 0.15


def _layer_trial(name: str, timeline: list[Segment], scene: SceneConfig | None = None) -> Trial:
    return Trial(name, timeline, tracker="layer", tracker_hz=LAYER_HZ, scene=scene)


# -- reach ------------------------------------------------------------------------------------------
def reach_points(hand: str, seed: int, n: int = REACH_POINTS) -> list[np.ndarray]:
    """n seeded points in the hand's workspace (module docstring)."""
    rng = np.random.default_rng(1000 * seed + (0 if hand == "left" else 1) + 17)
    shoulder = SHOULDER_W_M[hand]
    outward = 1.0 if hand == "left" else -1.0
    points: list = []
    while len(points) < n:
        r = rng.uniform(0.20, 0.50)
        z = rng.uniform(0.55, 1.30)
        dz = z - shoulder[2]
        if abs(dz) >= r:
            continue
        h = math.sqrt(r * r - dz * dz)
        az = math.radians(rng.uniform(-100.0, 20.0))
        # azimuth from straight ahead, negative outward (left hand: +y is outward)
        xy = shoulder[:2] + h * np.array([math.cos(az), -outward * math.sin(az)])
        points.append(np.array([xy[0], xy[1], z]))
    return points


def reach_trials(hand: str) -> Callable[[int], list[Trial]]:
    def make(seed: int) -> list[Trial]:
        timeline = [Segment(2.0, label="stand")]
        for k, p in enumerate(reach_points(hand, seed)):
            timeline.append(Segment(4.5, label=f"point {k}", goals=[
                GoalEntry("reach", hand=hand, pos_w_m=(float(p[0]), float(p[1]), float(p[2])))]))  # type: ignore[arg-type]
        timeline.append(Segment(2.0, label="end"))
        return [_layer_trial(f"reach {hand}", timeline)]
    return make


def reach_outcome(o: dict) -> bool:
    return o.get("status") == "reached" and o.get("within_tolerance", 0.0) >= REACH_HOLD_FRACTION


# -- heights -----------------------------------------------------------------------------------------
def height_trials(style: str) -> Callable[[int], list[Trial]]:
    def make(seed: int) -> list[Trial]:
        timeline = [Segment(2.0, label="stand", style=style)]
        timeline += [Segment(7.0 if k == 0 else 6.0, label=f"{h:.2f} m", style=style, pelvis_height_m=h)
                     for k, h in enumerate(HEIGHTS_M)]
        return [_layer_trial(f"height {style}", timeline)]
    return make


def height_figures(result: TrialResult) -> list[tuple[float, float]]:
    """(asked, measured mean over the segment's last 2 s) per height segment, ground truth."""
    out = []
    t, z = result.log["t_s"], result.log["base_pos_m"][:, 2]
    start = 0.0
    for seg in result.trial.timeline:
        end = start + seg.duration_s
        if seg.pelvis_height_m is not None:
            w = (t >= end - 2.0) & (t < end)
            out.append((seg.pelvis_height_m, float(np.nanmean(z[w])) if w.any() else float("nan")))
        start = end
    return out


# -- box ------------------------------------------------------------------------------------------------
def box_layout(seed: int, k: int, floor: bool = False) -> tuple[SceneConfig, list[GoalEntry]]:
    """A seeded layout: the box 2 m from the robot at a seeded bearing, its table turned a little;
    where it goes is 3 m from where it stands, on a second table (or the floor) facing the first."""
    rng = np.random.default_rng(7919 * seed + k + (5000 if floor else 0))
    for _ in range(100):
        bearing = math.radians(rng.uniform(-45.0, 45.0))
        box_xy = 2.0 * np.array([math.cos(bearing), math.sin(bearing)])
        toward_robot = -box_xy / np.linalg.norm(box_xy)
        normal_a = _turn(toward_robot, math.radians(rng.uniform(-20.0, 20.0)))
        psi = math.radians(rng.uniform(-70.0, 70.0))
        move = _turn(normal_a, psi)
        target_xy = box_xy + 3.0 * move
        box = Box("box", (float(box_xy[0]), float(box_xy[1])), mass_kg=2.0, size_m=(0.3, 0.3, 0.3),
                  yaw_rad=float(math.atan2(normal_a[1], normal_a[0])))
        tables, goals = [], []
        if floor:
            goals = [GoalEntry("pick", object="box"),
                     GoalEntry("place", object="box", pos_w_m=(float(target_xy[0]), float(target_xy[1]), 0.15))]
        else:
            depth_a = 0.5
            along = rng.uniform(-0.15, 0.15)
            inset = 0.15 + rng.uniform(0.0, 0.03)
            center_a = box_xy - normal_a * (depth_a / 2 - inset) - _turn(normal_a, math.pi / 2) * along
            yaw_a = math.atan2(normal_a[1], normal_a[0])
            tables.append(Table("table_a", (float(center_a[0]), float(center_a[1])), (depth_a, 0.8), 0.7, yaw_a))
            depth_b = 0.5
            center_b = target_xy + move * (depth_b / 2 - 0.18)
            yaw_b = math.atan2(move[1], move[0])
            tables.append(Table("table_b", (float(center_b[0]), float(center_b[1])), (depth_b, 0.8), 0.7, yaw_b))
            box.stands_on = "table_a"
            goals = [GoalEntry("pick", object="box"), GoalEntry("place", object="box", target="table_b")]
        scene = SceneConfig(tables=tables, boxes=[box])
        try:
            scene.validate("scene")
        except ValueError:
            continue
        if len(tables) == 2 and _tables_overlap(tables[0], tables[1]):
            continue
        return scene, goals
    raise RuntimeError(f"no valid box layout for seed {seed}, {k}")


def _turn(v: np.ndarray, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _tables_overlap(a: Table, b: Table, margin: float = 0.8) -> bool:
    """Too close to walk between (a robot with a box needs ~0.8 m)."""
    return any(b.distance_xy(c) < margin for c in a.corners_w()) or a.distance_xy(b.center) < margin + 0.3


def box_trials(floor: bool = False, n: int = BOX_LAYOUTS) -> Callable[[int], list[Trial]]:
    def make(seed: int) -> list[Trial]:
        trials = []
        for k in range(n):
            scene, goals = box_layout(seed, k, floor)
            timeline = [Segment(2.0, label="stand"), Segment(32.0, label="pick", goals=[goals[0]]),
                        Segment(56.0, label="carry and place", goals=[goals[1]])]
            trials.append(_layer_trial(f"box {'floor' if floor else 'table'} {k}", timeline, scene))
        return trials
    return make


def box_outcome(result: TrialResult) -> tuple[bool, float | None, str]:
    """(placed within PLACE_TOLERANCE_M and never dropped and no fall, place error, note)."""
    pick = next((o for o in result.goals if o.get("kind") == "pick"), None)
    place = next((o for o in result.goals if o.get("kind") == "place"), None)
    if result.fell:
        return False, place.get("place_error_xy_m") if place else None, f"fell: {result.fall}"
    if pick is None or pick.get("status") != "reached":
        return False, None, f"pick {pick.get('status') if pick else 'not started'}: {pick.get('message') if pick else ''}"
    if place is None or place.get("status") != "reached":
        return False, None, f"place {place.get('status') if place else 'not started'}: " \
                            f"{place.get('message') if place else ''}"
    err = place.get("place_error_xy_m")
    dropped = bool(pick.get("dropped")) or bool(place.get("dropped"))
    if err is None:
        return False, None, "place reported no position error"
    ok = err <= PLACE_TOLERANCE_M and not dropped
    return ok, err, f"placed {err * 100:.1f} cm off" + (", dropped" if dropped else "")


# -- step --------------------------------------------------------------------------------------------
def step_layout(seed: int, k: int) -> SceneConfig:
    rng = np.random.default_rng(104729 * seed + k + 3)
    dist = rng.uniform(1.2, 2.0)
    bearing = math.radians(rng.uniform(-30.0, 30.0))
    yaw = bearing + math.radians(rng.uniform(-20.0, 20.0))
    depth = 0.7
    edge_mid = dist * np.array([math.cos(bearing), math.sin(bearing)])
    center = edge_mid + depth / 2 * np.array([math.cos(yaw), math.sin(yaw)])
    return SceneConfig(platforms=[Platform("step", (float(center[0]), float(center[1])), (depth, 1.2),
                                           STEP_HEIGHT_M, float(yaw))])


def step_trials(n: int = STEP_APPROACHES) -> Callable[[int], list[Trial]]:
    def make(seed: int) -> list[Trial]:
        trials = []
        for k in range(n):
            timeline = [Segment(2.0, label="stand"),
                        Segment(24.0, label="step up", goals=[GoalEntry("step_up", target="step")]),
                        Segment(14.0, label="step down", goals=[GoalEntry("step_down")])]
            trials.append(_layer_trial(f"step {k}", timeline, step_layout(seed, k)))
        return trials
    return make


def step_outcome(result: TrialResult) -> tuple[bool, str]:
    up = next((o for o in result.goals if o.get("kind") == "step_up"), None)
    down = next((o for o in result.goals if o.get("kind") == "step_down"), None)
    if result.fell:
        return False, f"fell: {result.fall}"
    if up is None or up.get("status") != "reached" or up.get("both_feet_on_top_s", 0.0) < 1.0:
        return False, f"step up: {up.get('status') if up else 'not started'} {up.get('message') or '' if up else ''}"
    if down is None or down.get("status") != "reached" or not down.get("on_floor_at_end"):
        return False, f"step down: {down.get('status') if down else 'not started'} " \
                      f"{down.get('message') or '' if down else ''}"
    return True, f"on top {up['both_feet_on_top_s']:.1f} s"


STYLES = tuple(ROLLOUT_STYLES)

__all__ = ["box_layout", "box_outcome", "box_trials", "height_figures", "height_trials", "reach_outcome",
           "reach_points", "reach_trials", "step_layout", "step_outcome", "step_trials"]


# -- rows --------------------------------------------------------------------------------------------
def goal_behaviours(Behaviour) -> list:
    """The rows above as bench_execution.Behaviour entries (its Behaviour class is passed in:
    bench_execution imports this module)."""

    def judge_reach(result: TrialResult) -> Verdict:
        reaches = [o for o in result.goals if o.get("kind") == "reach"]
        ok = [reach_outcome(o) for o in reaches]
        errors = [o["hand_error_mean_m"] for o in reaches if "hand_error_mean_m" in o]
        missed = [f"{k}: {o.get('message') or ('%.0f %% within' % (100 * o.get('within_tolerance', 0)))}"
                  for k, (o, good) in enumerate(zip(reaches, ok)) if not good]
        n = REACH_POINTS
        success = not result.fell and sum(ok) >= math.ceil(REACH_HOLD_FRACTION * n - 1e-9)
        note = (f"fell: {result.fall}; " if result.fell else "") + f"{sum(ok)}/{n} points" + \
            (f"; missed {'; '.join(missed)}" if missed else "")
        return Verdict(success, note, figures(hand_error_m=float(np.mean(errors)) if errors else None), count=n,
                       successes=sum(ok))

    def judge_height(result: TrialResult) -> Verdict:
        figs = height_figures(result)
        ok = [not result.fell and abs(z - h) <= HEIGHT_TOLERANCE_M for h, z in figs]
        note = ", ".join(f"{h:.2f}->{z:.3f}" for h, z in figs) + (f"; fell: {result.fall}" if result.fell else "")
        worst = max((abs(z - h) for h, z in figs if np.isfinite(z)), default=None)
        return Verdict(all(ok), note, figures(height_error_m=worst), count=len(figs), successes=sum(ok))

    def judge_box(result: TrialResult) -> Verdict:
        ok, err, note = box_outcome(result)
        return Verdict(ok, note, figures(object_error_m=err))

    def judge_step(result: TrialResult) -> Verdict:
        ok, note = step_outcome(result)
        return Verdict(ok, note)

    rows = [Behaviour(f"reach.{hand}", f"{REACH_POINTS} seeded points: hand within {REACH_TOLERANCE_M * 100:.0f} cm "
                      f"for >= {REACH_HOLD_FRACTION:.0%} of each hold on >= 90 % of them, no fall",
                      reach_trials(hand), judge_reach, min_success=0.9) for hand in ("left", "right")]
    rows += [Behaviour(f"height.{style}", f"pelvis {', '.join(f'{h:.2f}' for h in HEIGHTS_M)} m standing: within "
                       f"{HEIGHT_TOLERANCE_M * 100:.0f} cm, no fall", height_trials(style), judge_height)
             for style in STYLES]
    rows.append(Behaviour("box.table", f"2 kg box, table to table 3 m, {BOX_LAYOUTS} layouts: placed within "
                          f"{PLACE_TOLERANCE_M * 100:.0f} cm, never dropped, in >= 8", box_trials(), judge_box,
                          min_success=0.8))
    rows.append(Behaviour("box.floor", "stretch: the same from the floor to the floor (3 layouts)",
                          box_trials(floor=True, n=3), judge_box, min_success=0.0))
    rows.append(Behaviour("step", f"{STEP_HEIGHT_M} m platform up and back down, {STEP_APPROACHES} approaches: "
                          ">= 8", step_trials(), judge_step, min_success=0.8))
    return rows


def layer_cpu_summary(samples: list[tuple[np.ndarray, np.ndarray]], rate_hz: float = LAYER_HZ) -> dict:
    """The tracking layer's act() thread CPU time per tick over every goal trial, by what ran
    (policy only, WBC only, both during a hand-over), and the margin to the tick at p99."""
    cpu = np.concatenate([s for s, _ in samples])
    kind = np.concatenate([k for _, k in samples])
    period_us = 1e6 / rate_hz
    out: dict = {"rate_hz": rate_hz, "ticks": int(cpu.size)}
    parts = []
    for k, name in ((0, "policy"), (1, "wbc"), (2, "both")):
        rows = cpu[kind == k] * 1e6
        if rows.size < 10:
            continue
        p50, p99 = np.percentile(rows, [50, 99])
        out[name] = {"ticks": int(rows.size), "cpu_p50_us": float(p50), "cpu_p99_us": float(p99),
                     "cpu_max_us": float(rows.max()), "margin_p99": float(period_us / p99)}
        parts.append(f"{name} {rows.size} ticks p50/p99 {p50:.0f}/{p99:.0f} us ({period_us / p99:.1f}x)")
    all99 = float(np.percentile(cpu * 1e6, 99))
    out["margin_p99"] = period_us / all99
    out["text"] = (f"tracking layer (goal rows, {rate_hz:.0f} Hz): act() thread CPU p99 {all99:.0f} us -> margin "
                   f"{period_us / all99:.1f}x to the {period_us / 1000:.0f} ms tick (goal >= 2x); " + "; ".join(parts))
    return out
