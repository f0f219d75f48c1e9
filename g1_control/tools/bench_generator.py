"""`g1 bench generator`: the in-betweening benchmark and the generator's speed, with baselines
measured in the same run.

1. Harvey et al. protocol on held-out clips (evaluation.py): L2P, L2Q, NPSS for 15- and
   30-frame gaps, plus foot skating / penetration, for interpolation, motion matching and the
   backbone; ratios backbone / baseline.
2. Partial keyframes: targets giving only the root and the right hand: keyframe success (within
   10 cm) and distance to goal.
3. Tokenisation floor: the error left if poses were snapped to a 512-code k-means codebook.
4. Speed: latency per replan (p50/p99, one plan = primitives + model + stabilization) and
   batched throughput in frames/s, against the interpolation baseline.
5. A 10-minute autoregressive rollout of the runtime under random commands and styles:
   NaN, pelvis height range, joint limits, tilt.
"""

from __future__ import annotations

import json
import os
import time

import numpy as np

from g1_control.generator import evaluation as E
from g1_control.generator import features as F


def _load(library_root=None):
    from g1_control.training.train import load_split

    return load_split(library_root, "train"), load_split(library_root, "test")


def _partial_keyframes(method, windows: E.Windows) -> tuple[float, float, float]:
    """(success rate within 10 cm, mean hand distance m, mean root distance m) with targets
    giving only the root and the right hand position."""
    mask = np.zeros((len(windows.frames), F.DIM), dtype=bool)
    mask[:, F.ROOT] = True
    k = F.EFFECTOR_BODIES.index("right_wrist_yaw_link")
    mask[:, 38 + 3 * k:41 + 3 * k] = True
    pred = method.infill(windows.context, windows.target, mask, windows.gap, windows.style)
    last = F.fix_effectors(pred[:, -1:])[:, 0]
    hand = np.linalg.norm(last[:, 38 + 3 * k:41 + 3 * k] - windows.target[:, 38 + 3 * k:41 + 3 * k], axis=1)
    root = np.linalg.norm(last[:, :2] - windows.target[:, :2], axis=1)
    return float((hand < 0.10).mean()), float(hand.mean()), float(root.mean())


def effector_goals_through_ik(generator_factory, goals: int = 12, seconds: float = 2.0, seed: int = 0) -> dict:
    """Right-hand goals in front of a standing robot, given as Command effector goals: the
    generator passes them as a partial keyframe and a frame target, the IK retargeter solves
    (as in the loop, 50 Hz). Returns success within 10 cm and the mean final hand distance."""
    from g1_control import rotations as quat
    from g1_control.generator.fk import fk_numpy
    from g1_control.generator.retarget import GeneratorRetargeter
    from g1_control.motion.kinematics import default_body_names
    from g1_control.robot import g1
    from g1_control.types import Command, EffectorGoal, RobotState

    rng = np.random.default_rng(seed)
    hand = default_body_names().index("right_wrist_yaw_link")
    dists = []
    for _ in range(goals):
        gen = generator_factory()
        ik = GeneratorRetargeter()
        state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]))
        gen.reset(state)
        goal = np.array([rng.uniform(0.25, 0.45), rng.uniform(-0.4, -0.1), g1.DEFAULT_PELVIS_HEIGHT_M + rng.uniform(0.0, 0.35)])
        cmd = Command(goals=[EffectorGoal("right_wrist_yaw_link", goal)])
        q = state.q_rad
        for i in range(int(seconds * 50)):
            state.t_s = i / 50
            out = ik.solve(gen.update(cmd, state), q)
            q = out.q_rad
        pos, _ = fk_numpy(out.root_pos_w_m, quat.to_matrix(out.root_quat_wxyz), out.q_rad)
        dists.append(float(np.linalg.norm(pos[hand] - goal)))
    d = np.array(dists)
    return {"goals": goals, "success": float((d < 0.10).mean()), "mean_m": float(d.mean()), "max_m": float(d.max())}


def _codebook_floor(train_feats, windows: E.Windows, stats: E.PositionStats, codes: int = 512) -> E.Scores:
    from scipy.cluster.vq import kmeans2

    poses = np.concatenate([f[:, F.JOINTS] for f in train_feats])
    rng = np.random.default_rng(0)
    sample = poses[rng.choice(len(poses), size=min(20000, len(poses)), replace=False)]
    book, _ = kmeans2(sample, codes, iter=15, seed=0, minit="++")
    truth = windows.truth.copy()
    flat = truth[..., F.JOINTS].reshape(-1, 29)
    d = ((flat[:, None, :] - book[None]) ** 2).sum(-1) if len(flat) < 5000 else None
    if d is None:
        from scipy.spatial import cKDTree

        _, idx = cKDTree(book).query(flat)
    else:
        idx = d.argmin(1)
    truth[..., F.JOINTS] = book[idx].reshape(truth[..., F.JOINTS].shape)
    return E.score_predictions(f"codebook{codes}", F.fix_effectors(truth), windows, stats, 30.0)


def _latency(gen_factory, n: int = 300) -> tuple[np.ndarray, np.ndarray]:
    from g1_control.types import Command

    gen = gen_factory()
    rng = np.random.default_rng(1)
    times, cpu = [], []
    for _ in range(n):
        cmd = Command(vx_mps=float(rng.uniform(-0.3, 0.8)), wz_radps=float(rng.uniform(-0.5, 0.5)),
                      style=str(rng.choice(["default", "carry", "wave", "guard"])))
        gen._t += 1.0 / 30
        gen._advance(gen._t)
        t0, c0 = time.perf_counter(), time.thread_time()
        gen._replan(cmd, "bench")
        times.append(time.perf_counter() - t0)
        cpu.append(time.thread_time() - c0)
    return np.array(times) * 1e3, np.array(cpu) * 1e3


def _throughput(method, windows: E.Windows, batch: int = 256, repeats: int = 3) -> float:
    ctx, tgt = windows.context[:batch], windows.target[:batch]
    mask = np.ones_like(tgt, dtype=bool)
    method.infill(ctx, tgt, mask, windows.gap, windows.style[:batch])
    t0 = time.perf_counter()
    for _ in range(repeats):
        method.infill(ctx, tgt, mask, windows.gap, windows.style[:batch])
    return len(ctx) * windows.gap * repeats / (time.perf_counter() - t0)


def long_rollout(generator, seconds: float = 600.0, fps: float = 30.0, seed: int = 0) -> dict:
    """Drive the generator with random commands (velocity, turns, stops, styles) every 2-6 s for
    `seconds` of generator time; return the health figures of the whole rollout."""
    from g1_control.robot import g1
    from g1_control.types import Command, RobotState

    rng = np.random.default_rng(seed)
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]))
    generator.reset(state)
    walk_styles = ["default", "carry", "arms_out", "wave", "guard", "arm_swing", "reach_up", "look_around", "dance"]
    n = int(seconds * fps)
    z = np.empty(n)
    tilt = np.empty(n)
    q = np.empty((n, 29))
    next_change, cmd = 0.0, Command()
    for i in range(n):
        state.t_s = i / fps
        if state.t_s >= next_change:
            stop = rng.random() < 0.2
            cmd = Command(vx_mps=0.0 if stop else float(rng.uniform(-0.3, 0.8)),
                          vy_mps=0.0 if stop else float(rng.uniform(-0.3, 0.3)),
                          wz_radps=0.0 if stop else float(rng.uniform(-0.8, 0.8)),
                          style=str(rng.choice(walk_styles)))
            next_change = state.t_s + float(rng.uniform(2.0, 6.0))
        ref = generator.update(cmd, state)
        z[i] = ref.root_pos_w_m[2]
        _w, x, y, _ = ref.root_quat_wxyz
        tilt[i] = np.arccos(np.clip(1 - 2 * (x * x + y * y), -1, 1))
        q[i] = ref.q_rad
    finite = bool(np.isfinite(z).all() and np.isfinite(q).all())
    # Collapse shows as motion dying out (a frozen or jittering pose): compare leg joint speed
    # (rad/s, mean over joints) in the first and the last minute.
    minute = int(60 * fps)
    legs = list(g1.LEG_JOINTS)
    speed_first = float(np.abs(np.diff(q[:minute, legs], axis=0)).mean() * fps)
    speed_last = float(np.abs(np.diff(q[-minute:, legs], axis=0)).mean() * fps)
    return {"seconds": seconds, "finite": finite, "pelvis_min_m": float(np.nanmin(z)), "pelvis_max_m": float(np.nanmax(z)),
            "tilt_max_deg": float(np.degrees(np.nanmax(tilt))),
            "joint_limit_violations": int(((q < g1.Q_MIN_RAD - 1e-6) | (q > g1.Q_MAX_RAD + 1e-6)).sum()),
            "replans": generator.stats.replans, "fallbacks": generator.stats.fallbacks,
            "leg_speed_first_min_radps": speed_first, "leg_speed_last_min_radps": speed_last}


def main(args) -> int:
    from g1_control.generator.baselines import InterpolationInbetweener, MotionMatchingInbetweener
    from g1_control.generator.learned import SHIPPED_DIR, OnnxInbetweener
    from g1_control.generator.runtime import InbetweeningGenerator
    from g1_control.generator.style_stats import load_style_stats

    t_start = time.perf_counter()
    (train_f, train_s), (test_f, test_s) = _load(getattr(args, "library", None))
    model_path = os.environ.get("G1_GENERATOR_ONNX") or SHIPPED_DIR / "backbone.onnx"
    backbone = OnnxInbetweener(model_path)
    interp = InterpolationInbetweener()
    mm = MotionMatchingInbetweener(train_f)
    figures: dict = {"load": os.getloadavg()[0], "model": str(model_path), "quality": [], "partial": {}}
    print(f"g1 bench generator: {len(test_f)} held-out clips, {len(train_f)} training clips; model {model_path}")
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2 cores shared: timings are noisy)\n")
    header = f"{'method':<16} {'gap':>3} {'L2P':>7} {'L2Q':>7} {'NPSS':>8} {'skate m/s':>9} {'penetr.':>8}"
    print(header)
    print("-" * len(header))
    windows = {}
    for gap in (15, 30):
        w = E.make_windows(test_f, test_s, gap)
        windows[gap] = w
        stats = E.PositionStats.from_windows(E.make_windows(train_f, train_s, gap))
        truth = E.foot_quality(w.truth, 30.0)
        rows = [E.score(m, w, stats) for m in (interp, mm, backbone)]
        rows.append(_codebook_floor(train_f, w, stats))
        for r in rows:
            print(f"{r.method:<16} {gap:>3} {r.l2p:>7.3f} {r.l2q:>7.3f} {r.npss:>8.5f} {r.skate_mps:>9.3f} {r.penetration:>8.3f}")
            figures["quality"].append(r.__dict__)
        print(f"{'(ground truth)':<16} {gap:>3} {'':>7} {'':>7} {'':>8} {truth[0]:>9.3f} {truth[1]:>8.3f}")
        b, i, mr = rows[2], rows[0], rows[1]
        print(f"  backbone / interpolation: L2P {b.l2p / i.l2p:.2f}x, L2Q {b.l2q / i.l2q:.2f}x;  "
              f"backbone / motion matching: L2P {b.l2p / mr.l2p:.2f}x, L2Q {b.l2q / mr.l2q:.2f}x "
              f"({'beats both' if b.l2p < min(i.l2p, mr.l2p) and b.l2q < min(i.l2q, mr.l2q) else 'DOES NOT beat both'})\n")
    # the root module's duration head: how many frames a transition to this keyframe takes
    errs = []
    for gap, w in windows.items():
        n = min(256, len(w.frames))
        backbone.infill(w.context[:n], w.target[:n], np.ones((n, F.DIM), bool), gap, w.style[:n])
        assert backbone.last_duration is not None  # infill just set it
        errs.append(np.abs(backbone.last_duration - gap))
    mae = float(np.concatenate(errs).mean())
    figures["duration_mae_frames"] = mae
    print(f"duration head on held-out 15- and 30-frame transitions: mean error {mae:.1f} frames "
          f"(a constant guess of 22.5 frames: 7.5)\n")
    print("partial keyframes (root + right hand only), 30-frame gap: success within 10 cm, hand / root distance")
    for m in (interp, mm, backbone):
        s, hd, rd = _partial_keyframes(m, windows[30])
        figures["partial"][m.name] = {"success": s, "hand_m": hd, "root_m": rd}
        print(f"  {m.name:<16} success {100 * s:5.1f} %   hand {hd:.3f} m   root {rd:.3f} m")
    styles = load_style_stats(SHIPPED_DIR / "style_stats.json")
    eff = effector_goals_through_ik(lambda: InbetweeningGenerator(backbone, styles))
    figures["effector_goals_ik"] = eff
    print(f"  runtime + IK, right-hand goals in front of a standing robot: success {100 * eff['success']:.0f} % "
          f"of {eff['goals']}, distance to goal mean {eff['mean_m']:.3f} m, max {eff['max_m']:.3f} m")
    print("\nspeed (this CPU, 1 inference thread)")
    for m in (interp, backbone):
        lat, cpu = _latency(lambda m=m: _fresh(InbetweeningGenerator(m, styles)))
        figures[f"replan_ms_{m.name}"] = {"wall_p50": float(np.percentile(lat, 50)), "wall_p99": float(np.percentile(lat, 99)),
                                          "cpu_p50": float(np.percentile(cpu, 50)), "cpu_p99": float(np.percentile(cpu, 99))}
        print(f"  replan latency {m.name:<14} wall p50 {np.percentile(lat, 50):6.2f} ms  p99 {np.percentile(lat, 99):6.2f} ms"
              f"   | CPU time p50 {np.percentile(cpu, 50):6.2f} ms  p99 {np.percentile(cpu, 99):6.2f} ms")
    tb = _throughput(backbone, windows[30])
    ti = _throughput(interp, windows[30])
    figures["throughput_fps"] = {"backbone": tb, "interpolation": ti}
    print(f"  batched throughput (256 x 30 frames): backbone {tb:,.0f} frames/s; interpolation {ti:,.0f} frames/s "
          f"(ratio {tb / ti:.2f}); goals: p50 <= 2 ms, >= 15,000 frames/s")
    print("\n10-minute autoregressive rollout under random commands and styles (backbone)")
    t0 = time.perf_counter()
    roll = long_rollout(_fresh(InbetweeningGenerator(backbone, styles)), 600.0)
    figures["rollout"] = roll
    print(f"  finite {roll['finite']}; pelvis {roll['pelvis_min_m']:.3f}-{roll['pelvis_max_m']:.3f} m; "
          f"max tilt {roll['tilt_max_deg']:.1f} deg; joint-limit violations {roll['joint_limit_violations']}; "
          f"{roll['replans']} replans, {roll['fallbacks']} fallbacks; mean leg joint speed first/last minute "
          f"{roll['leg_speed_first_min_radps']:.2f}/{roll['leg_speed_last_min_radps']:.2f} rad/s; {time.perf_counter() - t0:.1f} s wall "
          f"({600.0 / (time.perf_counter() - t0):.0f}x real time)")
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    if getattr(args, "json", None):
        with open(args.json, "w") as fh:
            json.dump(figures, fh, indent=1)
    return 0


def _fresh(gen):
    from g1_control.robot import g1
    from g1_control.types import RobotState

    gen.reset(RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M])))
    return gen
