"""`g1 bench objects`: pick a box from a support and put it on another, over drawn scenes, judged
from MuJoCo's ground truth (issue 25).

Each trial is one scene drawn from the seed and the trial's index (`draw_scene`, pure):
  support   the floor, or a table 0.10-0.95 m high (buckets: floor 0, low <= 0.45, table <= 0.80,
            high <= 0.95), 1.0-1.5 m from the robot's start, turned any way
  box       0.15-0.45 m a side, 0.2-6 kg (light < 3 kg <= heavy), turned any way, near the support's
            edge that faces the robot
  target    a point on a second support drawn the same way (the floor or a table), 1.3-2.0 m from
            the box on the robot's side of the first
The robot (walking policy + whole-body controller, the tracking layer of launch/sim_box.yaml) gets
a pick and a place goal. Judged from the simulator's ground truth only (not the goals' status):
  lifted    the box rose >= 5 cm above where it stood
  held      it was still >= 5 cm up when the pick ended
  placed    its centre ended within 10 cm (xy) of the target and within 3 cm of resting on it
  upright   it ended tilted < 10 deg
  dropped   it sank > 5 cm relative to the hands between the lift and the release (the place's, or
            the set-back of a pick whose box did not come up with the hands)
  fell      the pelvis went below 0.30 m (a squat stays above ~0.40 m) or the loop's fall monitor
            tripped; reported with the stage it fell in (the running goal's kind and its walk or
            whole-body plan: approach, pick, raise, carry, place, ...)
A refused goal (the planner said no before moving) counts as a failure; its reason is listed.

--carry: the box carried between two tables 3-5 m apart (CARRY_*: both 0.60-0.85 m high, boxes 0.20-0.35 m,
1-4 kg; drawn from their own stream, the objects draws unchanged) on the whole-body controller alone
(launch/sim_wbc_carry.yaml's chain), which walks it in its own gait (handling.walk_in_gait); each trial says
how the carry walked ("gait", "steps": whole-body steps, or "not walked": the pick or the place refused
first), read from the goals' notes (the path taken, not the outcome: that is judged as above).

    g1 bench objects --seed 3 --trials 20 [--jobs 2] [--json out.json]
    g1 bench objects --carry --seed 200 --trials 10 --jobs 2
    g1 bench objects --tracker wbc --seed 3 --trials 20 --jobs 2

--tracker wbc: the objects scenes on the whole-body controller alone (250 Hz, as --carry); the default is
the tracking layer (the walking policy walks, the WBC picks and places). Both walk a held box in the WBC's
own gait where the place is on the same ground and the box is no heavier than GoalConfig.gait_carry_max_kg
(the layer, run at 250 Hz here, hands a walk holding something to its WBC, trackers/layer.py; launch files
at 100 Hz carry in whole-body steps), else in whole-body steps.

`run_trial(seed, index) -> dict` is the whole trial (a plain function of its arguments, for a
process pool or a cluster); `main` fans it out over --jobs processes and prints the tables.
"""

from __future__ import annotations

import json
import math
import re
import time
from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

from g1_control.scene import FLOOR, Box, SceneConfig, Table

if TYPE_CHECKING:
    from g1_control.generator.goals.executor import GoalGenerator
from g1_control.teleop.scripted import GoalEntry, Segment

HEIGHT_BUCKETS_M = {"floor": (0.0, 0.0), "low": (0.10, 0.45), "table": (0.45, 0.80), "high": (0.80, 0.95)}
BOX_SIDE_M = (0.15, 0.45)
BOX_MASS_KG = (0.2, 6.0)
HEAVY_KG = 3.0
SOURCE_DISTANCE_M = (1.0, 1.5)
TARGET_DISTANCE_M = (1.3, 2.0)
LIFT_M = 0.05
PLACE_TOLERANCE_M = 0.10
REST_TOLERANCE_M = 0.03
UPRIGHT_DEG = 10.0
DROP_M = 0.05
FALL_PELVIS_M = 0.30
CARRY_HEIGHT_M = (0.60, 0.85)
CARRY_BOX_SIDE_M = (0.20, 0.35)
CARRY_MASS_KG = (1.0, 4.0)
CARRY_DISTANCE_M = (3.0, 5.0)
"""--carry: both supports tables of these heights, boxes of these sides and masses, the target this far from
the box; the whole-body controller is the tracker, its own gait carries (GoalConfig.walk_while_holding)."""
TRACKERS = ("layer", "wbc")
"""--tracker: the objects scenes' tracker (run_trial)."""
TRIAL_LIMIT_S = 110.0
"""Simulated time a trial may take (walk, pick, carry, place): a cap, trials stop when both goals end."""
SETTLE_S = 2.0
"""After the place goal ends, the box is judged this much later (it settles on the support)."""


def height_bucket(height_m: float) -> str:
    if height_m <= 0.0:
        return "floor"
    for name in ("low", "table", "high"):
        if height_m <= HEIGHT_BUCKETS_M[name][1] + 1e-9:
            return name
    return "high"


def _rot(v: np.ndarray, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def _extent_along(size_xy: np.ndarray, yaw: float, direction: np.ndarray) -> float:
    ax = np.array([[math.cos(yaw), math.sin(yaw)], [-math.sin(yaw), math.cos(yaw)]])
    return float(abs(ax[0] @ direction) * size_xy[0] + abs(ax[1] @ direction) * size_xy[1])


def _support(rng: np.random.Generator, name: str, bucket: str, edge_xy: np.ndarray, outward: np.ndarray,
             item_size_xy: np.ndarray, item_yaw: float, heights: dict[str, tuple[float, float]] = HEIGHT_BUCKETS_M
             ) -> tuple[Table | None, np.ndarray]:
    """A table (None for the floor) with an item of the given footprint near the edge at edge_xy whose
    outward normal is `outward`; returns the table and where the item's centre stands."""
    depth = _extent_along(item_size_xy, item_yaw, outward)
    inset = depth / 2 + rng.uniform(0.02, 0.06)
    center = edge_xy - inset * outward
    if bucket == "floor":
        return None, center
    lo, hi = heights[bucket]
    height = float(rng.uniform(lo, hi))
    across = _extent_along(item_size_xy, item_yaw, _rot(outward, math.pi / 2))
    size = (max(0.5, depth + 0.15 + rng.uniform(0.0, 0.3)), max(0.6, across + 0.2 + rng.uniform(0.0, 0.5)))
    along = rng.uniform(-1.0, 1.0) * max(0.0, size[1] / 2 - across / 2 - 0.05)
    # the table's own x axis along `outward`, or across it (its yaw is any: a quarter turn swaps sides)
    quarter = int(rng.integers(0, 4))
    yaw = math.atan2(outward[1], outward[0]) + quarter * math.pi / 2
    if quarter % 2:
        size = (size[1], size[0])
    half_depth = (size[0] if quarter % 2 == 0 else size[1]) / 2
    table_center = edge_xy - half_depth * outward + along * _rot(outward, math.pi / 2)
    table = Table(name, (float(table_center[0]), float(table_center[1])), (float(size[0]), float(size[1])),
                  height, float(math.atan2(math.sin(yaw), math.cos(yaw))))
    return table, center


def draw_scene(seed: int, index: int, carry: bool = False) -> dict:
    """The trial's scene and goals, drawn from (seed, index) alone (module docstring); carry: from the
    --carry ranges (CARRY_*). Returns {scene, goals, target_xyz_m, source, target, mass_kg, size_m,
    carry_m}."""
    rng = np.random.default_rng([seed, index, 25] if not carry else [seed, index, 25, 23])
    heights = {"table": CARRY_HEIGHT_M} if carry else HEIGHT_BUCKETS_M
    buckets = list(heights)
    sides, masses = (CARRY_BOX_SIDE_M, CARRY_MASS_KG) if carry else (BOX_SIDE_M, BOX_MASS_KG)
    distances = CARRY_DISTANCE_M if carry else TARGET_DISTANCE_M
    for _ in range(200):
        src_bucket = buckets[int(rng.integers(0, len(buckets)))]
        dst_bucket = buckets[int(rng.integers(0, len(buckets)))]
        size = rng.uniform(*sides, size=3)
        mass = float(rng.uniform(*masses))
        box_yaw = float(rng.uniform(-math.pi, math.pi))
        bearing = math.radians(rng.uniform(-35.0, 35.0))
        dist = rng.uniform(*SOURCE_DISTANCE_M)
        toward_robot = -np.array([math.cos(bearing), math.sin(bearing)])
        edge_normal = _rot(toward_robot, math.radians(rng.uniform(-30.0, 30.0)))
        edge_xy = dist * np.array([math.cos(bearing), math.sin(bearing)])
        table_a, box_xy = _support(rng, "table_a", src_bucket, edge_xy, edge_normal, size[:2], box_yaw, heights)
        # the target: on the robot's side of the first support, its near edge facing the box
        move = _rot(edge_normal, math.radians(rng.uniform(-70.0, 70.0)))
        to_edge = rng.uniform(*distances)
        edge_b = box_xy + to_edge * move
        table_b, target_xy = _support(rng, "table_b", dst_bucket, edge_b, -move, size[:2], box_yaw, heights)
        box = Box("box", (float(box_xy[0]), float(box_xy[1])), stands_on=table_a.name if table_a else FLOOR,
                  size_m=(float(size[0]), float(size[1]), float(size[2])), mass_kg=mass, yaw_rad=box_yaw)
        tables = [t for t in (table_a, table_b) if t is not None]
        scene = SceneConfig(tables=tables, boxes=[box])
        try:
            scene.validate("scene")
        except ValueError:
            continue
        if not _paths_clear(tables, box_xy, edge_normal, target_xy, move):
            continue
        if float(np.hypot(*target_xy)) < 0.8:
            continue
        top = table_b.height_m if table_b is not None else 0.0
        place = GoalEntry("place", object="box", target=table_b.name if table_b else None,
                          pos_w_m=(float(target_xy[0]), float(target_xy[1]), float(top + size[2] / 2)))
        return {"scene": scene, "goals": [GoalEntry("pick", object="box"), place],
                "target_xyz_m": [float(target_xy[0]), float(target_xy[1]), float(top + size[2] / 2)],
                "source": {"bucket": src_bucket, "height_m": table_a.height_m if table_a else 0.0,
                           "yaw_deg": math.degrees(table_a.yaw_rad) if table_a else None},
                "target": {"bucket": dst_bucket, "height_m": top},
                "mass_kg": mass, "size_m": [float(s) for s in size], "box_yaw_deg": math.degrees(box_yaw),
                "carry_m": float(np.hypot(*(target_xy - box_xy)))}
    raise RuntimeError(f"no valid scene for seed {seed}, trial {index}")


def _paths_clear(tables: list[Table], box_xy: np.ndarray, normal: np.ndarray, target_xy: np.ndarray,
                 move: np.ndarray) -> bool:
    """The robot walks straight from its start to the box's stance, and from there (backed off) to the
    target's: neither path may cross a table, and the tables keep a walkway between them."""
    stance_a = box_xy + 0.55 * normal
    stance_b = target_xy - 0.45 * move
    for a, b in ((np.zeros(2), stance_a), (stance_a + 0.3 * normal, stance_b)):
        for s in np.linspace(0.0, 1.0, 25):
            p = a + s * (b - a)
            if any(t.distance_xy(p) < 0.25 for t in tables):
                return False
    if len(tables) == 2 and any(tables[1].distance_xy(c) < 0.7 for c in tables[0].corners_w()):
        return False
    return True


def _timeline(goals: list[GoalEntry]) -> list[Segment]:
    return [Segment(1.0, label="stand"), Segment(TRIAL_LIMIT_S, label="pick and place", goals=list(goals))]


def run_trial(seed: int, index: int, carry: bool = False, gait: bool = True, tracker: str = "layer") -> dict:
    """One trial, start to verdict (module docstring): a plain function of its arguments. carry: a --carry
    scene on the whole-body controller (launch/sim_wbc_carry.yaml's chain); tracker: an objects scene's
    ("layer": launch/sim_box.yaml's tracking layer, run at 250 Hz so that its WBC's gait carries; "wbc": the
    whole-body controller alone, 250 Hz, as --carry); gait False: a carry walks in whole-body steps, as with
    a tracker that has no gait (GoalConfig.walk_while_holding off)."""
    if tracker not in TRACKERS:
        raise ValueError(f"tracker {tracker!r}: one of {', '.join(TRACKERS)}")
    from g1_control.launch.builder import build_loop
    from g1_control.report.outcomes import GoalWatcher
    from g1_control.tools.physics_trials import Trial, trial_launch

    drawn = draw_scene(seed, index, carry)
    tracker = "wbc" if carry else tracker
    trial = Trial(f"{'carry' if carry else 'objects'} {seed}.{index}", _timeline(drawn["goals"]), tracker=tracker,
                  tracker_hz=250.0, scene=drawn["scene"])
    loop = build_loop(trial_launch(trial))
    loop.reset()
    watcher = GoalWatcher(loop)
    gen = loop.generator
    if not gait:
        cast("GoalGenerator", gen).config.walk_while_holding = False
    t0 = time.perf_counter()
    pelvis_min = math.inf
    ended_at: float | None = None
    try:
        while loop.time_s < TRIAL_LIMIT_S:
            loop.run(1.0, progress=watcher.tick)
            pelvis_min = min(pelvis_min, float(loop.backend.data.qpos[2]))  # type: ignore[attr-defined]
            if loop.fell or pelvis_min < FALL_PELVIS_M:
                break
            status = getattr(gen, "goal_status", {})
            if ended_at is None and len(status) == 2:
                ended_at = loop.time_s
            if ended_at is not None and loop.time_s >= ended_at + SETTLE_S:
                break
    finally:
        wall = time.perf_counter() - t0
        loop.backend.close()
    notes = [text for _, text in getattr(getattr(gen, "ctx", None), "log", [])]
    walked = "gait" if any(text.startswith("stand holding") for text in notes) else \
        "steps" if any(text.startswith("place stance") for text in notes) else None
    return judge(drawn, watcher.arrays(), dict(gen.goal_info), dict(gen.goal_messages), pelvis_min,
                 loop.fall is not None, seed=seed, index=index, carry=carry, gait=gait, walked=walked, tracker=tracker,
                 sim_s=float(loop.time_s), wall_s=wall)


def judge(drawn: dict, a: dict[str, np.ndarray], info: dict, messages: dict, pelvis_min_m: float, fall: bool,
          **extra) -> dict:
    """The trial's verdict from ground truth (module docstring)."""
    t, box = a["t_s"], a["box_box"]
    z0 = float(box[0, 2]) if len(box) else math.nan
    rise = box[:, 2] - z0 if len(box) else np.zeros(0)
    pick: dict = next((i for i in info.values() if i.get("kind") == "pick"), {})
    place: dict = next((i for i in info.values() if i.get("kind") == "place"), {})
    lifted = bool(len(rise) and rise.max() >= LIFT_M)
    held = False
    if lifted and pick.get("end_s") is not None:
        k = min(int(np.searchsorted(t, pick["end_s"])), len(t) - 1)
        held = bool(rise[k] >= LIFT_M)
    target = np.asarray(drawn["target_xyz_m"])
    final = box[-1] if len(box) else np.full(7, math.nan)
    err_xy = float(np.hypot(*(final[:2] - target[:2])))
    err_z = float(final[2] - target[2])
    qx, qy = final[4], final[5]
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (qx * qx + qy * qy)))))
    dropped = False
    if lifted:
        start = int(np.argmax(rise >= LIFT_M))
        # the hands let go at the place's release, or where a pick whose box did not come up set it
        # back down (handling.pick's lift check): after that the hands leave the box on purpose
        end_s = place.get("released_s", place.get("end_s")) if place else pick.get("released_s")
        end = len(t) if end_s is None else max(start + 1, int(np.searchsorted(t, end_s)))
        rel = box[start:end, 2] - a["hands_w_m"][start:end, :, 2].mean(axis=1)
        dropped = bool(len(rel) and rel.min() < rel[0] - DROP_M)
    fell = fall or pelvis_min_m < FALL_PELVIS_M
    placed = err_xy <= PLACE_TOLERANCE_M and abs(err_z) <= REST_TOLERANCE_M
    upright = tilt <= UPRIGHT_DEG
    refusals = [f"{i.get('kind')}: {messages.get(g)}" for g, i in info.items() if i.get("status") == "failed"]
    success = lifted and held and placed and upright and not dropped and not fell
    # where a fall happened: the stage (walk, or the whole-body plan's name) of the goal that was running
    running = [i for i in info.values() if i.get("end_s") is None]
    fell_in = ""
    if fell:
        fell_in = f"{running[-1].get('kind')}: {running[-1].get('stage', 'start')}" if running else "no goal running"
    place_s = place["end_s"] - place["start_s"] if place.get("end_s") is not None else None
    return {**extra, "source": drawn["source"], "target": drawn["target"], "mass_kg": drawn["mass_kg"],
            "carry_m": drawn.get("carry_m"), "place_s": place_s,
            "weight": "heavy" if drawn["mass_kg"] >= HEAVY_KG else "light", "size_m": drawn["size_m"],
            "box_yaw_deg": drawn["box_yaw_deg"], "lifted": lifted, "held": held, "placed": placed,
            "upright": upright, "dropped": dropped, "fell": fell, "fell_in": fell_in, "success": success,
            "place_error_xy_m": err_xy, "place_error_z_m": err_z, "tilt_deg": tilt, "pelvis_min_m": pelvis_min_m,
            "refused": refusals, "pick_status": pick.get("status"), "place_status": place.get("status"),
            "pick_stance": pick.get("stance")}


def _why(r: dict) -> str:
    if r["success"]:
        return f"ok ({r['place_error_xy_m'] * 100:.1f} cm)"
    if r["refused"]:
        return "refused: " + " | ".join(r["refused"])
    fell = f"fell ({r['fell_in']})" if r.get("fell_in") else "fell"
    parts = [name for name, bad in ((fell, r["fell"]), ("not lifted", not r["lifted"]),
                                    ("not held", r["lifted"] and not r["held"]), ("dropped", r["dropped"]),
                                    ("not placed", not r["placed"]), ("tilted", not r["upright"])) if bad]
    return ", ".join(parts) + f" (box {r['place_error_xy_m'] * 100:.0f} cm from target, z {r['place_error_z_m'] * 100:+.0f} cm)"


def summary(results: list[dict]) -> dict:
    rows: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    for r in results:
        for key in (f"from {r['source']['bucket']}", f"to {r['target']['bucket']}", r["weight"], "all"):
            rows[key][0] += int(r["success"])
            rows[key][1] += 1
    order = [f"from {b}" for b in HEIGHT_BUCKETS_M] + [f"to {b}" for b in HEIGHT_BUCKETS_M] + ["light", "heavy", "all"]
    return {k: {"success": rows[k][0], "trials": rows[k][1]} for k in order if k in rows}


def refusal_reason(text: str) -> str:
    """A refusal's reason, numbers written as '#' so that alike reasons count together: without the
    box's description, the "no stance can ..." lead and the closest or planned pose ("pick: box 'box'
    (...): no stance can pick it up (22 tried, ...): the hands get only within 4.5 cm; closest: ..." ->
    "pick: the hands get only within # cm")."""
    kind, _, rest = text.partition(": ")
    rest = re.sub(r"^box '[^']*'( \([^)]*\))?:? ", "", rest)
    rest = re.sub(r"^no stance can [^(:]*( \([^)]*\))?: ", "", rest)
    rest = rest.split("; closest")[0].split(" (planned:")[0]
    return f"{kind}: " + re.sub(r"-?\d+(\.\d+)?", "#", rest).strip()


def refusal_table(results: list[dict]) -> dict[str, dict[str, int]]:
    """Per bucket (a pick's by where the box stood, a place's by where it was to go), how often each
    refusal reason (`refusal_reason`) ended a trial; "place: holding no box" after a refused or failed
    pick is left out (the pick's reason is counted)."""
    table: dict[str, dict[str, int]] = defaultdict(lambda: defaultdict(int))
    for r in results:
        for text in r["refused"]:
            reason = refusal_reason(text)
            if reason == "place: holding no box":
                continue
            bucket = r["source" if reason.startswith("pick") else "target"]["bucket"]
            table[f"{'from' if reason.startswith('pick') else 'to'} {bucket}"][reason] += 1
    return {k: dict(sorted(v.items(), key=lambda kv: -kv[1])) for k, v in sorted(table.items())}


def main(args) -> int:
    n, seed = int(args.trials if args.trials is not None else 10), int(args.seed)
    from g1_control.fanout import fan_out
    from g1_control.tools.environment import describe, environment

    env = environment()
    print(describe(env), flush=True)
    t0 = time.perf_counter()
    carry = bool(getattr(args, "carry", False))
    if carry and getattr(args, "tracker", None) not in (None, "wbc"):
        raise ValueError("--carry runs on the whole-body controller (--tracker wbc)")
    tracker = "wbc" if carry else getattr(args, "tracker", None) or "layer"
    results: list[dict] = []
    for r in fan_out(_trial, [(seed, i, carry, True, tracker) for i in range(n)], jobs=args.jobs, ray=args.ray):
        results.append(r)
        _print_trial(r)
    table = summary(results)
    flags = " --carry" if carry else " --tracker wbc" if tracker == "wbc" else ""
    print(f"\ng1 bench objects{flags} --seed {seed} --trials {n}: {time.perf_counter() - t0:.0f} s wall")
    print(f"{'bucket':14s} {'success':>8s}")
    for k, v in table.items():
        print(f"{k:14s} {v['success']:>3d}/{v['trials']:<3d}")
    refused = [(r["index"], x) for r in results for x in r["refused"]]
    if refused:
        print("refusals:")
        for i, x in refused:
            print(f"  trial {i}: {x}")
    reasons = refusal_table(results)
    if reasons:
        print("refusal reasons per bucket:")
        for bucket, counts in reasons.items():
            for reason, count in counts.items():
                print(f"  {bucket:11s} {count:3d}  {reason}")
    if args.json:
        Path(args.json).write_text(json.dumps({"seed": seed, "trials": n, "carry": carry, "tracker": tracker,
                                               "environment": env, "table": table,
                                               "reasons": reasons, "results": results},
                                              indent=1, default=float))
    return 0


def _trial(task: tuple[int, int, bool, bool, str]) -> dict:
    """One trial for fan_out (--jobs processes or a Ray cluster): run_trial(seed, index, carry, gait, tracker)."""
    return run_trial(*task)


def _print_trial(r: dict) -> None:
    s, d = r["source"], r["target"]
    carried = f" carried {r['carry_m']:.1f} m ({r.get('walked') or 'not walked'})" if r.get("carry") else ""
    print(f"trial {r['index']:3d}: {s['bucket']:5s} {s['height_m']:.2f} m -> {d['bucket']:5s} {d['height_m']:.2f} m, "
          f"box {'x'.join(f'{v:.2f}' for v in r['size_m'])} m {r['mass_kg']:.1f} kg{carried}: {_why(r)}  "
          f"[{r['sim_s']:.0f} s sim, {r['wall_s']:.0f} s wall]", flush=True)


__all__ = ["draw_scene", "judge", "main", "refusal_reason", "refusal_table", "run_trial", "summary"]
