"""`g1 bench bottle`: a bottle picked with one Dex3-1 hand and put down upright, over drawn scenes,
judged from MuJoCo's ground truth (issue 25: objects beyond boxes; the Dex3 hands in the simulator).

Each trial is one scene drawn from the seed and the trial's index (`draw_scene`, pure): the G1 with
Dex3 hands (launch/sim_bottle.yaml's chain: the whole-body controller, its own gait) starts before a
table 0.65-0.85 m high, 0.5 x 0.9 m, its centre 0.75-1.8 m away within +-25 deg of straight ahead and
turned +-20 deg more; on it, 0.05-0.12 m in from the side facing the robot and within +-0.2 m of that
side's middle, a bottle (radius 0.03-0.04 m, 0.16-0.28 m tall, 0.2-0.8 kg, friction 0.6-1.2); the
left or right hand picks it (walking to it first when it is out of reach, goals/bottle.py; a
force-limited grasp, GoalConfig.bottle_grasp_nm) and puts it down 0.08-0.18 m across, towards the
other hand. Judged from the simulator only (not the goals' status):
  lifted    the bottle rose >= LIFT_M above where it stood
  held      it moved with the palm from the lift to the release (its height relative to the palm
            changed < DROP_M)
  placed    its base's centre ended within PLACE_TOLERANCE_M (xy) of the target, resting on the top
            (within REST_TOLERANCE_M) and upright (< UPRIGHT_DEG)
  squeeze   the grasping hand's closing motors' torque (what the motor applies, MuJoCo's actuator
            force) while the grasp was asked for: the peak, against the grasp's torque limit
  fell      the loop's fall monitor or a safety trip
With --carry the bottle goes instead onto a second table (the same ranges, its centre CARRY_DISTANCE_M
from the robot's start, CARRY_BEARING_DEG to the side of the first, facing the start +-20 deg; the
point 0.05-0.12 m in from its side facing the start): the robot walks there holding it.
A refused goal (the planner said no before moving) counts as a failure, with its reason.

    g1 bench bottle --seed 0 --trials 20 [--carry] [--jobs 2] [--json out.json]
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

if TYPE_CHECKING:
    from g1_control.generator.goals.executor import GoalGenerator
    from g1_control.sim.mujoco_backend import MujocoBackend

TABLE_HEIGHT_M = (0.65, 0.85)
TABLE_SIZE_M = (0.5, 0.9)
TABLE_DISTANCE_M = (0.75, 1.8)
TABLE_BEARING_DEG = 25.0
TABLE_TURN_DEG = 20.0
INSET_M = (0.05, 0.12)
"""The bottle's edge this far in from the table's side that faces the robot."""
ALONG_M = 0.2
RADIUS_M = (0.03, 0.04)
HEIGHT_M = (0.16, 0.28)
MASS_KG = (0.2, 0.8)
FRICTION = (0.6, 1.2)
MOVE_M = (0.08, 0.18)
LIFT_M = 0.05
DROP_M = 0.03
PLACE_TOLERANCE_M = 0.05
REST_TOLERANCE_M = 0.01
UPRIGHT_DEG = 10.0
STAND_S, PICK_S, PLACE_S, SETTLE_S = 2.0, 30.0, 12.0, 1.0
CARRY_PLACE_S = 70.0
"""--carry: the place goal's time (the walk to the second table included)."""
CARRY_DISTANCE_M = (1.0, 1.8)
CARRY_BEARING_DEG = (50.0, 110.0)
PATH_CLEAR_M = 0.2
"""--carry: the straight walk between the two stances keeps this far from both tables (redrawn otherwise)."""


def _table_xy(centre: np.ndarray, yaw: float, local: np.ndarray) -> np.ndarray:
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    return centre + rot @ local


def _second_table(rng: np.random.Generator, scene: dict, radius: float) -> dict | None:
    """--carry: a second table and the point on it (None: it meets the first, or the walk between
    the two stances passes too near a table; the caller draws again)."""
    from g1_control.scene import Table

    first = scene["table"]
    a_centre, a_yaw = np.asarray(first["center_xy_m"]), first["yaw_rad"]
    side = float(rng.choice([-1.0, 1.0]))
    bearing = math.atan2(a_centre[1], a_centre[0]) + side * math.radians(float(rng.uniform(*CARRY_BEARING_DEG)))
    yaw = bearing + math.radians(float(rng.uniform(-TABLE_TURN_DEG, TABLE_TURN_DEG)))
    centre = float(rng.uniform(*CARRY_DISTANCE_M)) * np.array([math.cos(bearing), math.sin(bearing)])
    height = float(rng.uniform(*TABLE_HEIGHT_M))
    local = np.array([-TABLE_SIZE_M[0] / 2 + float(rng.uniform(*INSET_M)) + radius, float(rng.uniform(-ALONG_M, ALONG_M))])
    target = _table_xy(centre, yaw, local)
    if float(np.hypot(*(centre - a_centre))) < 1.2:
        return None
    # the stances: 0.4 m out from each point, off the table's side facing the start
    out_a = _table_xy(np.zeros(2), a_yaw, np.array([-1.0, 0.0]))
    out_b = _table_xy(np.zeros(2), yaw, np.array([-1.0, 0.0]))
    p, q = np.asarray(scene["bottle"]["xy_m"]) + 0.7 * out_a, target + 0.7 * out_b
    tables = [Table("a", tuple(a_centre), TABLE_SIZE_M, yaw_rad=a_yaw), Table("b", tuple(centre), TABLE_SIZE_M, yaw_rad=yaw)]
    for s in np.linspace(0.0, 1.0, 25):
        x = p + s * (q - p)
        if any(t.contains_xy(x, margin_m=-PATH_CLEAR_M) for t in tables):  # within PATH_CLEAR_M of its outline
            return None
    return {"table_b": {"center_xy_m": [float(centre[0]), float(centre[1])], "yaw_rad": yaw},
            "target_table": "table_b", "target_height_m": height, "target_xy_m": (float(target[0]), float(target[1]))}


def draw_scene(seed: int, index: int, carry: bool = False) -> dict:
    """The trial's scene (a pure function of seed, index and carry)."""
    rng = np.random.default_rng([seed, index])
    hand = str(rng.choice(["left", "right"]))
    side = 1.0 if hand == "left" else -1.0
    height = float(rng.uniform(*TABLE_HEIGHT_M))
    radius = float(rng.uniform(*RADIUS_M))
    bearing = math.radians(float(rng.uniform(-TABLE_BEARING_DEG, TABLE_BEARING_DEG)))
    yaw = bearing + math.radians(float(rng.uniform(-TABLE_TURN_DEG, TABLE_TURN_DEG)))
    centre = float(rng.uniform(*TABLE_DISTANCE_M)) * np.array([math.cos(bearing), math.sin(bearing)])
    rot = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
    # in the table's frame: x from its side facing the robot (-x) inwards, y along that side
    local = np.array([-TABLE_SIZE_M[0] / 2 + float(rng.uniform(*INSET_M)) + radius, float(rng.uniform(-ALONG_M, ALONG_M))])
    xy = centre + rot @ local
    # put down across, towards the other hand (the robot faces the table's x: along its -y for the left hand)
    move = rot @ np.array([float(rng.uniform(-0.03, 0.03)), -side * float(rng.uniform(*MOVE_M))])
    scene = {"seed": seed, "index": index, "hand": hand, "table_height_m": height,
             "table": {"center_xy_m": [float(centre[0]), float(centre[1])], "yaw_rad": yaw},
             "bottle": {"xy_m": (float(xy[0]), float(xy[1])), "radius_m": radius,
                        "height_m": float(rng.uniform(*HEIGHT_M)), "mass_kg": float(rng.uniform(*MASS_KG)),
                        "friction": float(rng.uniform(*FRICTION))},
             "target_xy_m": (float(xy[0] + move[0]), float(xy[1] + move[1]))}
    if carry:
        for _ in range(200):
            second = _second_table(rng, scene, radius)
            if second is not None:
                return {**scene, **second, "carry": True}
        raise RuntimeError(f"no second table for seed {seed}, trial {index}")
    return scene


def scene_launch(scene: dict):
    """The LaunchFile of a drawn scene: launch/sim_bottle.yaml's chain with the scene's table, bottle and goals."""
    from g1_control.launch.schema import parse_launch

    top = scene["table_height_m"]
    target, target_top = scene.get("target_table", "table"), scene.get("target_height_m", top)
    tables = [{"name": "table", **scene["table"], "size_xy_m": list(TABLE_SIZE_M), "height_m": top}]
    if "table_b" in scene:
        tables.append({"name": "table_b", **scene["table_b"], "size_xy_m": list(TABLE_SIZE_M), "height_m": target_top})
    place_s = CARRY_PLACE_S if "table_b" in scene else PLACE_S
    bottle = {"name": "bottle", "stands_on": "table", **scene["bottle"]}
    data = {
        "name": f"bench_bottle_{scene['seed']}_{scene['index']}",
        "backend": {"type": "mujoco", "mode": "lockstep", "physics_dt_s": 0.002, "hands": "dex3"},
        "rates": {"lowlevel_hz": 500, "tracker_hz": 250, "input_hz": 100, "estimator_hz": 100},
        "tracker": {"type": "wbc"}, "generator": {"type": "velocity"},
        "scene": {"tables": tables, "bottles": [bottle]},
        "input": {"type": "scripted", "timeline": [
            {"duration_s": STAND_S, "label": "stand"},
            {"duration_s": PICK_S, "label": "pick", "goals": [{"kind": "pick", "object": "bottle", "hand": scene["hand"]}]},
            {"duration_s": place_s + SETTLE_S, "label": "place",
             "goals": [{"kind": "place", "object": "bottle", "target": target,
                        "pos_w_m": [*scene["target_xy_m"], target_top]}]}]},
        "output": {"video": False, "plot": False}, "viewer": False,
    }
    return parse_launch(data, str(data["name"]))


def _tilt_deg(quat_wxyz: np.ndarray) -> float:
    _, x, y, _ = quat_wxyz
    return math.degrees(math.acos(min(1.0, max(-1.0, 1.0 - 2.0 * (x * x + y * y)))))


def run_trial(task: tuple[int, int] | tuple[int, int, bool]) -> dict:
    """One drawn scene, run and judged (a plain function of its task (seed, index[, carry]), for fan_out)."""
    return run_scene(draw_scene(*task))


def run_scene(scene: dict, *, gait: bool = True) -> dict:
    """A scene (draw_scene's form), run and judged. gait False: a carry walks in whole-body steps, as with a
    tracker that has no gait of its own (GoalConfig.walk_while_holding off)."""
    from g1_control.launch.builder import build_loop
    from g1_control.robot import dex3

    launch = scene_launch(scene)
    loop = build_loop(launch)
    loop.reset()
    sim = cast("MujocoBackend", loop.backend)
    gen = cast("GoalGenerator", loop.generator)
    gen.config.walk_while_holding = gen.config.walk_while_holding and gait
    m, d = sim.model, sim.data
    hand = scene["hand"]
    h = dex3.SIDES.index(hand)
    palm = m.body(f"{hand}_hand_palm_link").id
    closing = dex3.hand_limits(hand).closing_sign != 0
    start, _ = sim.object_pose("bottle")
    top, height = scene.get("target_height_m", scene["table_height_m"]), scene["bottle"]["height_m"]
    peak_tau, max_z, rel0, rel_dev = 0.0, -math.inf, None, 0.0
    t0 = time.perf_counter()
    end = launch.total_duration_s  # stand, pick, place and settle
    while loop.time_s < end - 1e-9 and not loop.fell:
        loop.run(0.02)
        pos, _ = sim.object_pose("bottle")
        max_z = max(max_z, float(pos[2]))
        ref = loop._kin_ref
        grasping = ref is not None and float(ref.grasp_nm[h]) > 0
        if grasping:
            tau = sim.read_fingers(hand).tau_nm
            peak_tau = max(peak_tau, float(np.abs(tau[closing]).max()))
        held = gen.ctx.held_bottle is not None
        if held and pos[2] > start[2] + 0.01:  # carried: its height against the palm's
            rel = float(pos[2] - d.xpos[palm][2])
            rel0 = rel if rel0 is None else rel0
            rel_dev = max(rel_dev, abs(rel - rel0))
    pos, quat = sim.object_pose("bottle")
    wall = time.perf_counter() - t0
    statuses = dict(gen.goal_status)
    messages = dict(gen.goal_messages)
    refused = "; ".join(f"{k}: {v}" for k, v in messages.items())
    lifted = max_z >= start[2] + LIFT_M
    base_xy_err = float(np.hypot(*(pos[:2] - np.asarray(scene["target_xy_m"]))))
    resting = abs(float(pos[2]) - (top + height / 2)) <= REST_TOLERANCE_M
    tilt = _tilt_deg(quat)
    placed = lifted and base_xy_err <= PLACE_TOLERANCE_M and resting and tilt < UPRIGHT_DEG
    trip = next((e for e in loop.events if e.trips), None)
    limit = float(gen.ctx.config.bottle_grasp_nm)
    sim.close()
    return {**scene, "lifted": bool(lifted), "held": bool(lifted and rel_dev < DROP_M), "placed": bool(placed),
            "place_error_m": base_xy_err, "tilt_deg": tilt, "resting": bool(resting), "rise_m": float(max_z - start[2]),
            "slip_m": rel_dev, "peak_squeeze_nm": peak_tau, "torque_limit_nm": limit, "fell": bool(loop.fell),
            "trip": str(trip) if trip else "", "goals": statuses, "refused": refused, "sim_s": float(loop.time_s),
            "wall_s": wall, "log": [f"{t:.2f} {text}" for t, text in gen.log]}


def main(args) -> int:
    from g1_control.fanout import fan_out

    n, seed = int(args.trials if args.trials is not None else 10), int(args.seed)
    carry = bool(getattr(args, "carry", False))
    print(f"g1 bench bottle: seed {seed}, {n} drawn scenes (one Dex3 hand, whole-body controller; ground truth)"
          + ("; carried to a second table" if carry else ""))
    print(f"{'trial':>5} {'hand':>5} {'table':>6} {'r':>6} {'h':>5} {'kg':>5}  {'lifted':>6} {'held':>5} {'placed':>6} "
          f"{'err cm':>6} {'tilt':>5} {'squeeze/limit':>13}  detail")
    rows = []
    for r in fan_out(run_trial, [(seed, i, carry) for i in range(n)], jobs=getattr(args, "jobs", 1) or 1,
                     ray=getattr(args, "ray", None)):
        rows.append(r)
        b = r["bottle"]
        detail = "FELL " + r["trip"] if r["fell"] else (r["refused"] or r["trip"])
        table = f"{r['table_height_m']:.2f}" + (f">{r['target_height_m']:.2f}" if "target_height_m" in r else "")
        print(f"{r['index']:>5} {r['hand']:>5} {table:>6} {b['radius_m']:6.3f} {b['height_m']:5.2f} "
              f"{b['mass_kg']:5.2f}  {'yes' if r['lifted'] else 'no':>6} {'yes' if r['held'] else 'no':>5} "
              f"{'yes' if r['placed'] else 'no':>6} {r['place_error_m'] * 100:6.1f} {r['tilt_deg']:5.1f} "
              f"{r['peak_squeeze_nm']:6.2f}/{r['torque_limit_nm']:.2f}  {detail[:90]}", flush=True)
    placed = sum(r["placed"] for r in rows)
    falls = sum(r["fell"] for r in rows)
    over = sum(r["peak_squeeze_nm"] > r["torque_limit_nm"] for r in rows)
    squeezes = [r["peak_squeeze_nm"] for r in rows if r["lifted"]]
    print(f"bottle: placed {placed}/{n} (within {PLACE_TOLERANCE_M * 100:.0f} cm, upright < {UPRIGHT_DEG:.0f} deg, "
          f"resting), lifted {sum(r['lifted'] for r in rows)}/{n}, held {sum(r['held'] for r in rows)}/{n}, "
          f"falls {falls}; peak squeeze over the limit in {over}/{n}"
          + (f" (peak {max(squeezes):.2f} N m)" if squeezes else ""))
    if args.json:
        Path(args.json).write_text(json.dumps({"seed": seed, "carry": carry, "trials": rows, "placed": placed, "falls": falls}, indent=1))
    return 1 if falls else 0


__all__ = ["draw_scene", "main", "run_scene", "run_trial", "scene_launch"]
