"""`g1 bench odometry`: drift of the world pose estimates against the simulator's ground truth over
10 seeded random command timelines (launch/sim_random.yaml: stands, walks, turns, sidesteps,
mixes; the walking policy in lockstep MuJoCo), in the run's start frame.

Estimates from the same robot state (no ground truth given to the robot's side of any):
  leg odometry   estimation/pose.py: IMU + contact-aided leg kinematics (stance feet anchored)
  external       leg odometry fused with a motion-capture pose (estimation/external_pose.py) that
                 sim/mocap.py plays from ground truth: MOCAP below (noise, latency, dropouts)
  uncompensated  the same fusion taking each pose as if measured when it arrived (no latency
                 compensation): what the compensation is worth
  velocity       program/device.py Odometry: the estimator's velocity integrated (the baseline)
  drifting IMU   leg odometry, alone and fused, fed an IMU whose heading drifts IMU_YAW_BIAS_DEGPS (the
                 simulated IMU is exact; a real one's heading drifts): what the external pose corrects

Drift is attributed per command segment: the growth of the position error vector over a segment,
against the metres walked and the degrees turned in it (ground truth), fitted as
|growth| = a * metres + b * (degrees / 90) by non-negative least squares over every segment of
every timeline. Also printed: final error / path length per timeline. Heading: the simulated IMU
reports the true orientation, so yaw drift is not measured here (a real IMU's yaw drifts).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time

import numpy as np

TIMELINES = 10
MOCAP = dict(rate_hz=100.0, noise_m=0.02, noise_rad=math.radians(3.0), latency_s=0.1, dropout=0.1)
"""The external pose: 100 Hz, 2 cm / 3 deg noise, 100 ms latency, 10 % dropouts (the issue's perception figures)."""
IMU_YAW_BIAS_DEGPS = 0.05
"""Heading drift given to the drifting-IMU estimates: 3 deg per minute (an assumption for the comparison,
not a G1 measurement)."""
ESTIMATES = (("legs", "leg odometry (IMU + contact-aided leg kinematics)"),
             ("external", "leg odometry + external pose (latency compensated)"),
             ("uncompensated", "leg odometry + external pose (no latency compensation)"),
             ("velocity", "velocity integration (baseline)"),
             ("legs_drift", f"leg odometry, IMU heading drifting {IMU_YAW_BIAS_DEGPS * 60:g} deg/min"),
             ("external_drift", f"leg odometry + external pose, IMU heading drifting {IMU_YAW_BIAS_DEGPS * 60:g} deg/min"))


def _start_frame(yaw0: float) -> np.ndarray:
    c, s = math.cos(-yaw0), math.sin(-yaw0)
    return np.array([[c, -s], [s, c]])


def run_timeline(seed: int, seconds: float) -> dict:
    """One seeded random timeline: per estimator tick the truth and both estimates (start frame)."""
    from g1_control.estimation.external_pose import ExternalPoseConfig, Planar, PoseFusion, PoseSample
    from g1_control.estimation.pose import LegOdometry
    from g1_control.launch.builder import build_loop, make_sim_backend, timeline_of
    from g1_control.launch.schema import load_launch
    from g1_control.program.device import Odometry
    from g1_control.resources import resolve_launch
    from g1_control.rotations import yaw_of
    from g1_control.sim.mocap import MocapConfig, SimulatedMocap

    launch = load_launch(resolve_launch("sim_random")[0])
    launch.input.random.seed = seed
    launch.duration_s = seconds
    launch.output.video = False
    segments = timeline_of(launch)
    loop = build_loop(launch, backend=make_sim_backend(launch))
    state = loop.reset()
    assert state.base_pos_w_m is not None  # MuJoCo: ground truth, for judging only
    blind = dataclasses.replace(state, base_pos_w_m=None, base_linvel_w_mps=None)
    legs = LegOdometry()
    legs.reset(blind)
    drifting = LegOdometry()
    drifting.reset(blind)
    velocity = Odometry()
    # motion capture calibrated to the start frame (frame: scene, the robot starting at the scene's origin)
    fusion_config = ExternalPoseConfig(interface="lo", max_age_s=0.5, max_jump_m=0.5, frame="scene")
    fused, uncompensated = PoseFusion(fusion_config), PoseFusion(fusion_config)
    fused_drift = PoseFusion(fusion_config)
    bias = math.radians(IMU_YAW_BIAS_DEGPS)
    t_start = state.t_s
    mocap = SimulatedMocap(MocapConfig(**MOCAP, seed=1000 + seed))
    velocity.pose(legs.estimator.estimate)
    p0, yaw0, rot0 = state.base_pos_w_m[:2].copy(), yaw_of(state.imu_quat_wxyz), _start_frame(yaw_of(state.imu_quat_wxyz))
    every = max(1, round(loop.rates.lowlevel_hz / loop.rates.estimator_hz))
    rows: list[list[float]] = []

    def tick(i: int) -> None:
        if i % every:
            return
        s = loop.state
        assert s.base_pos_w_m is not None
        pose = legs.update(dataclasses.replace(s, base_pos_w_m=None, base_linvel_w_mps=None))
        v = velocity.pose(legs.estimator.estimate)
        odo = Planar(s.t_s, pose.x_m, pose.y_m, pose.yaw_rad)
        turn = bias * (s.t_s - t_start) / 2
        c, sn = math.cos(turn), math.sin(turn)
        w, x, y, z = s.imu_quat_wxyz.tolist()  # the IMU's heading turned by bias * t
        quat = np.array([c * w - sn * z, c * x - sn * y, c * y + sn * x, c * z + sn * w])
        dp = drifting.update(dataclasses.replace(s, base_pos_w_m=None, base_linvel_w_mps=None, imu_quat_wxyz=quat))
        fused_drift.update(Planar(s.t_s, dp.x_m, dp.y_m, dp.yaw_rad))
        fused.update(odo)
        uncompensated.update(odo)
        for stamp, pos, quat in mocap.sample(s.t_s, s.base_pos_w_m, s.imu_quat_wxyz):
            x, y = rot0 @ (pos[:2] - p0)
            yaw = yaw_of(quat) - yaw0
            fused.measure(PoseSample(stamp, float(x), float(y), yaw))
            fused_drift.measure(PoseSample(stamp, float(x), float(y), yaw))
            uncompensated.measure(PoseSample(s.t_s, float(x), float(y), yaw))
        f, u, fd = fused.fused, uncompensated.fused, fused_drift.fused
        assert f is not None and u is not None and fd is not None
        vxy = rot0 @ np.array([v.x_m, v.y_m])
        truth = rot0 @ (s.base_pos_w_m[:2] - p0)
        rows.append([s.t_s, *truth, yaw_of(s.imu_quat_wxyz) - yaw0, pose.x_m, pose.y_m, *vxy,
                     f.x_m, f.y_m, u.x_m, u.y_m, dp.x_m, dp.y_m, fd.x_m, fd.y_m, dp.yaw_rad, fd.yaw_rad])

    loop.run(seconds, progress=tick)
    a = np.array(rows)
    return {"seed": seed, "t_s": a[:, 0], "truth": a[:, 1:3], "yaw": np.unwrap(a[:, 3]), "legs": a[:, 4:6],
            "velocity": a[:, 6:8], "external": a[:, 8:10],
            "uncompensated": a[:, 10:12], "legs_drift": a[:, 12:14], "external_drift": a[:, 14:16],
            "heading_error_drift": np.column_stack([(a[:, 16] - a[:, 3] + np.pi) % (2 * np.pi) - np.pi,
                                                    (a[:, 17] - a[:, 3] + np.pi) % (2 * np.pi) - np.pi]),
            "fell": loop.fell, "refused": fused.counters.rejected,
            "segment_ends_s": np.cumsum([s.duration_s for s in segments]).tolist()}


SWAY_S = 0.5
"""Path length and turning are summed over steps this long (the pelvis' gait sway, ~1 Hz, left out)."""


def walked_and_turned(run: dict) -> tuple[np.ndarray, np.ndarray]:
    """Cumulative metres walked and radians turned (ground truth) at every sample, over SWAY_S steps."""
    t, truth, yaw = run["t_s"], run["truth"], run["yaw"]
    dt = float(np.median(np.diff(t)))
    k = max(1, round(SWAY_S / dt))
    idx = np.unique(np.append(np.arange(0, len(t), k), len(t) - 1))
    path_k = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(truth[idx], axis=0), axis=1))])
    turn_k = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(yaw[idx])))])
    return np.interp(t, t[idx], path_k), np.interp(t, t[idx], turn_k)


def segment_growth(run: dict, key: str) -> list[tuple[float, float, float]]:
    """(metres walked, degrees turned / 90, |error growth|) per command segment."""
    t, truth = run["t_s"], run["truth"]
    err = run[key] - truth
    path, turned = walked_and_turned(run)
    out, start = [], 0
    for end_s in run["segment_ends_s"]:
        end = int(np.searchsorted(t, end_s + t[0]))
        end = min(end, len(t) - 1)
        if end > start:
            out.append((float(path[end] - path[start]), float(np.degrees(turned[end] - turned[start]) / 90.0),
                        float(np.linalg.norm(err[end] - err[start]))))
        start = end
    return out


def fit_drift(samples: list[tuple[float, float, float]]) -> tuple[float, float]:
    """(m per m walked, m per 90 deg turned): non-negative least squares of growth on (metres, turns)."""
    from scipy.optimize import nnls

    a = np.array([[m, q] for m, q, _ in samples])
    b = np.array([g for _, _, g in samples])
    coef, _ = nnls(a, b)
    return float(coef[0]), float(coef[1])


def main(args) -> int:
    seconds = float(args.seconds) if args.seconds and args.seconds != 20.0 else 40.0
    first = int(getattr(args, "seed", 0) or 0)
    t0 = time.perf_counter()
    runs = [run_timeline(first + k, seconds) for k in range(TIMELINES)]
    wall = time.perf_counter() - t0
    figures: dict = {"timelines": TIMELINES, "seconds_each": seconds, "seeds": [r["seed"] for r in runs],
                     "falls": sum(bool(r["fell"]) for r in runs), "wall_s": wall, "per_timeline": []}
    print(f"odometry drift vs ground truth: {TIMELINES} seeded random timelines x {seconds:.0f} s "
          f"(seeds {first}..{first + TIMELINES - 1}; {wall:.0f} s wall; falls: {figures['falls']})")
    print(f"external pose: {MOCAP['rate_hz']:.0f} Hz, noise {MOCAP['noise_m'] * 100:.0f} cm / "
          f"{math.degrees(MOCAP['noise_rad']):.0f} deg, latency {MOCAP['latency_s'] * 1000:.0f} ms, "
          f"dropouts {MOCAP['dropout'] * 100:.0f} %")
    keys = [k for k, _ in ESTIMATES]
    print(f"{'seed':>4} {'walked m':>9} {'turned deg':>10} " + " ".join(f"{k + ' end err m':>22}" for k in keys)
          + "  refused (external)")
    for r in runs:
        walked, turns = walked_and_turned(r)
        path, turned = float(walked[-1]), float(np.degrees(turns[-1]))
        row = {"seed": r["seed"], "walked_m": path, "turned_deg": turned, "refused": dict(r["refused"])}
        for k in keys:
            row[f"{k}_end_error_m"] = float(np.linalg.norm(r[k][-1] - r["truth"][-1]))
            row[f"{k}_max_error_m"] = float(np.linalg.norm(r[k] - r["truth"], axis=1).max())
        figures["per_timeline"].append(row)
        refused = ", ".join(f"{n} {why}" for why, n in r["refused"].items() if n) or "none"
        print(f"{r['seed']:>4} {path:9.2f} {turned:10.0f} " + " ".join(f"{row[k + '_end_error_m']:22.3f}" for k in keys)
              + f"  {refused}")
    for key, name in ESTIMATES:
        samples = [g for r in runs for g in segment_growth(r, key)]
        per_m, per_90 = fit_drift(samples)
        rows = figures["per_timeline"]
        ratio = np.array([p[f"{key}_end_error_m"] / max(p["walked_m"], 1e-6) for p in rows])
        worst = max(p[f"{key}_max_error_m"] for p in rows)
        figures[key] = {"drift_m_per_m": per_m, "drift_m_per_90deg": per_90, "max_error_m": worst,
                        "end_error_per_path_mean": float(ratio.mean()), "end_error_per_path_max": float(ratio.max())}
        print(f"{name}: drift {per_m * 100:.1f} cm per metre walked, {per_90 * 100:.1f} cm per 90 deg turned "
              f"(segment fit over {len(samples)} segments); end error / path length mean {ratio.mean() * 100:.1f} %, "
              f"max {ratio.max() * 100:.1f} %; largest error at any time {worst * 100:.1f} cm")
    ends = np.degrees(np.abs(np.array([r["heading_error_drift"][-1] for r in runs])))
    figures["heading_end_error_deg_drifting_imu"] = {"legs": float(ends[:, 0].mean()), "external": float(ends[:, 1].mean())}
    print(f"heading with the drifting IMU, end error mean over the timelines: leg odometry {ends[:, 0].mean():.1f} deg, "
          f"fused with the external pose {ends[:, 1].mean():.1f} deg (the exact simulated IMU: 0)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(figures, fh, indent=2)
    return 0
