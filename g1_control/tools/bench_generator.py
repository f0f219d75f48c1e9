"""`g1 bench generator`: the in-betweening benchmark and the generator's speed, with baselines
measured in the same run.

1. Harvey et al. protocol on held-out clips (evaluation.py), 29-DoF G1: L2P, L2Q, NPSS for 15-
   and 30-frame gaps, foot skating, memory and per-frame cost, for interpolation, motion matching,
   learned motion matching, the backbone, and the backbone with reference-guided feedback.
2. Joint-level goals, model only (the runtime's reference before any IK): WANDR-style hand goals
   sampled in a cylinder around the robot from unseen (held-out) start poses - success within
   5 cm and distance to goal, with and without the feedback; a 10-minute sequence of goals
   (success, foot skating, drift); and the older partial-keyframe and through-the-IK checks.
3. One model for every variant: held-out figures per skeleton (29-DoF, 23-DoF, with hands) for
   the shared model against a model trained on that variant alone (runs/gen_<skeleton>/).
4. Tokenisation floor: the error left if poses were snapped to a 512-code k-means codebook.
5. Speed: replan latency (p50/p99, one plan = primitives + model + feedback + stabilization) and
   batched throughput in frames/s, wall clock and CPU time, as ratios against interpolation.
6. A 10-minute autoregressive rollout of the runtime under random commands and styles.

Models: G1_GENERATOR_ONNX (backbone, default the shipped one), G1_GENERATOR_LMM (folder, default
policies/generator/lmm), G1_GENERATOR_VARIANT_RUNS (folder holding gen_<skeleton>/backbone.onnx,
default runs/). G1_BENCH_SECTIONS=quality,goals,variants,models,codebook,speed,rollout picks sections.
"""

from __future__ import annotations

import json
import os
import time

import numpy as np

from g1_control.generator import evaluation as E
from g1_control.generator import features as F


def _load(library_root=None, skeleton: str = "g1_29dof"):
    from g1_control.generator.data import load_split

    return load_split(library_root, "train", skeleton), load_split(library_root, "test", skeleton)


def _partial_keyframes(method, windows: E.Windows) -> tuple[float, float, float]:
    """(success rate within 10 cm, mean hand distance m, mean root distance m) with targets
    giving only the root and the right hand position."""
    mask = np.zeros((len(windows.frames), F.DIM), dtype=bool)
    mask[:, F.ROOT] = True
    cols = F.effector_slice("right_wrist_yaw_link")
    mask[:, cols] = True
    pred = method.infill(windows.context, windows.target, mask, windows.gap, windows.style)
    last = F.fix_effectors(pred[:, -1:])[:, 0]
    hand = np.linalg.norm(last[:, cols] - windows.target[:, cols], axis=1)
    root = np.linalg.norm(last[:, :2] - windows.target[:, :2], axis=1)
    return float((hand < 0.10).mean()), float(hand.mean()), float(root.mean())


def effector_goals_through_ik(generator_factory, goals: int = 12, seconds: float = 2.0, seed: int = 0) -> dict:
    """Right-hand goals in front of a standing robot, given as Command effector goals: the
    generator passes them as a partial keyframe and a frame target, the IK stage solves (as in the
    loop: a launch file's default `ik:` section, 50 Hz). Returns success within 10 cm and the mean
    final hand distance."""
    from g1_control import rotations as quat
    from g1_control.generator.fk import fk_numpy
    from g1_control.launch.builder import make_ik
    from g1_control.launch.schema import LaunchFile
    from g1_control.motion.kinematics import default_body_names
    from g1_control.robot import g1
    from g1_control.types import Command, EffectorGoal, RobotState

    rng = np.random.default_rng(seed)
    hand = default_body_names().index("right_wrist_yaw_link")
    dists = []
    for _ in range(goals):
        gen = generator_factory()
        ik = make_ik(LaunchFile("bench_generator"))
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


def _throughput(method, windows: E.Windows, batch: int = 256, repeats: int = 5) -> tuple[float, float]:
    """Batched frames per second: (wall clock, CPU time of this thread - what one core does
    when other jobs share it)."""
    ctx, tgt = windows.context[:batch], windows.target[:batch]
    mask = np.ones_like(tgt, dtype=bool)
    method.infill(ctx, tgt, mask, windows.gap, windows.style[:batch])
    walls, cpus = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.thread_time()
        method.infill(ctx, tgt, mask, windows.gap, windows.style[:batch])
        walls.append(time.perf_counter() - t0)
        cpus.append(time.thread_time() - c0)
    frames = len(ctx) * windows.gap
    return frames / float(np.median(walls)), frames / float(np.median(cpus))


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


def _memory_bytes(method) -> int:
    """What a method keeps in memory to generate: its database or its network weights."""
    from pathlib import Path

    name = method.name
    if name == "motion_matching":
        total = sum(c.nbytes for c in method.clips)
        for tree, scale, keys, mean in method._db.values():
            total += tree.data.nbytes + tree.indices.nbytes + keys.nbytes + scale.nbytes + mean.nbytes
        return total
    if name == "learned_motion_matching":
        return (Path(method.folder) / "lmm.onnx").stat().st_size
    if name.startswith("backbone"):
        layers = [method]  # wrappers (feedback, foot lock) hold the network in .inner
        while hasattr(layers[-1], "inner"):
            layers.append(layers[-1].inner)
        path = Path(layers[-1].path)
        size = path.stat().st_size
        if any(hasattr(m, "feedback") for m in layers):
            size += (path.parent / "feedback.npz").stat().st_size
        return size
    return 0


def _start_frames(test_f, rng, n: int):
    """n unseen start poses: 10 consecutive frames of random held-out clips (world frame)."""
    from g1_control.generator.inbetween import CONTEXT_FRAMES

    out = []
    for _ in range(n):
        c = test_f[int(rng.integers(len(test_f)))]
        k = int(rng.integers(0, len(c) - CONTEXT_FRAMES))
        out.append(c[k:k + CONTEXT_FRAMES])
    return out


def _cylinder_goal(rng, frame, r=(0.25, 1.5), z=(0.8, 1.25)):
    """A goal point in a cylinder around a robot frame (uniform over the annulus' area, any
    direction around the robot, height in z)."""
    radius = np.sqrt(rng.uniform(r[0] ** 2, r[1] ** 2))
    yaw = float(F.heading(frame)) + rng.uniform(-np.pi, np.pi)
    return np.array([frame[0] + radius * np.cos(yaw), frame[1] + radius * np.sin(yaw), rng.uniform(*z)])


class _HandProbe:
    """Model-only effector positions of the runtime's reference (FK of its root + joints)."""

    def __init__(self):
        from g1_control.motion.kinematics import default_body_names

        names = default_body_names()
        self.idx = {b: names.index(b) for b in ("left_wrist_yaw_link", "right_wrist_yaw_link",
                                                 "left_ankle_roll_link", "right_ankle_roll_link")}

    def __call__(self, ref):
        from g1_control import rotations as quat
        from g1_control.generator.fk import fk_numpy

        pos, _ = fk_numpy(ref.root_pos_w_m, quat.to_matrix(ref.root_quat_wxyz), ref.q_rad)
        return {b: pos[i] for b, i in self.idx.items()}


def wandr_goals(gen_factory, test_f, episodes: int = 40, seconds: float = 8.0, seed: int = 0,
                threshold_m: float = 0.05) -> dict:
    """Hand goals in a cylinder around the robot from unseen start poses, model only (no IK): success
    = the reference's hand (FK) within threshold at some time; DTG at the end and at the closest."""
    from g1_control.types import Command, EffectorGoal

    rng = np.random.default_rng(seed)
    probe = _HandProbe()
    final_l: list[float] = []
    closest_l: list[float] = []
    reach_t: list[float] = []
    for frames in _start_frames(test_f, rng, episodes):
        gen = gen_factory()
        gen.reset_from_frames(frames, 0.0)
        hand = ("left_wrist_yaw_link", "right_wrist_yaw_link")[int(rng.integers(2))]
        goal = _cylinder_goal(rng, frames[-1])
        cmd = Command(goals=[EffectorGoal(hand, goal)])
        best, t_hit = np.inf, None
        from g1_control.types import RobotState

        state = RobotState()
        for i in range(int(seconds * 30)):
            state.t_s = i / 30
            d = float(np.linalg.norm(probe(gen.update(cmd, state))[hand] - goal))
            if d < threshold_m and t_hit is None:
                t_hit = state.t_s
            best = min(best, d)
        final_l.append(d)
        closest_l.append(best)
        reach_t.append(t_hit if t_hit is not None else np.nan)
    final, closest = np.array(final_l), np.array(closest_l)
    return {"episodes": episodes, "success": float((closest < threshold_m).mean()),
            "dtg_final_m": float(final.mean()), "dtg_final_median_m": float(np.median(final)),
            "dtg_closest_m": float(closest.mean()), "held_at_end": float((final < threshold_m).mean()),
            "time_to_reach_s": float(np.nanmedian(reach_t)) if np.isfinite(reach_t).any() else None}


def goal_sequence(gen, feedback_ref, minutes: float = 10.0, per_goal_s: float = 8.0, seed: int = 1,
                  threshold_m: float = 0.05) -> dict:
    """One continuous session of hand goals (a new one every per_goal_s, in a cylinder around where
    the robot is): success rate, foot skating of the reference, and drift - the pose's distance to
    the default style's reference mixture and the pelvis height, first vs last minute."""
    from g1_control.robot import g1
    from g1_control.types import Command, EffectorGoal, RobotState

    rng = np.random.default_rng(seed)
    probe = _HandProbe()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M]))
    gen.reset(state)
    n = int(minutes * 60 * 30)
    per = int(per_goal_s * 30)
    hits, z, dist, feet = [], np.empty(n), np.empty(n), np.empty((n, 2, 3))
    cmd, hit, hand, goal = None, False, None, None
    frame = np.zeros(F.DIM)
    for i in range(n):
        state.t_s = i / 30
        if i % per == 0:
            if cmd is not None:
                hits.append(hit)
            hand = ("left_wrist_yaw_link", "right_wrist_yaw_link")[int(rng.integers(2))]
            goal = _cylinder_goal(rng, gen.history[-1])
            cmd, hit = Command(goals=[EffectorGoal(hand, goal)]), False
        ref = gen.update(cmd, state)
        pts = probe(ref)
        hit = hit or float(np.linalg.norm(pts[hand] - goal)) < threshold_m
        feet[i] = [pts["left_ankle_roll_link"], pts["right_ankle_roll_link"]]
        z[i] = ref.root_pos_w_m[2]
        frame[2] = ref.root_pos_w_m[2]
        frame[F.JOINTS] = ref.q_rad
        if ref.hand_q_rad is not None:
            frame[F.FINGERS] = ref.hand_q_rad
        dist[i] = feedback_ref.distance(frame[None])[0]
    hits.append(hit)
    speed = np.linalg.norm(np.diff(feet[..., :2], axis=0), axis=-1) * 30
    contact = feet[1:, :, 2] < E.STANCE_ANKLE_Z_M + E.CONTACT_BAND_M
    minute = 60 * 30
    return {"goals": len(hits), "success": float(np.mean(hits)), "skate_mps": float(speed[contact].mean()),
            "manifold_first_min": float(dist[:minute].mean()), "manifold_last_min": float(dist[-minute:].mean()),
            "pelvis_first_min_m": float(z[:minute].mean()), "pelvis_last_min_m": float(z[-minute:].mean()),
            "finite": bool(np.isfinite(z).all())}


def _sections() -> set[str]:
    raw = os.environ.get("G1_BENCH_SECTIONS")
    all_ = {"quality", "goals", "variants", "models", "codebook", "speed", "rollout"}
    return all_ if not raw else {s.strip() for s in raw.split(",")} & all_


def _models_table(model_path, lmm_dir, runs_dir, figures: dict) -> None:
    """Training time (wall and CPU) and file sizes of every model the bench uses."""
    from pathlib import Path

    from g1_control.generator import skeleton as S

    print("models: training time on this CPU and shipped sizes")
    rows = [("backbone (shared)", Path(model_path).parent, ("backbone.onnx", "feedback.npz")),
            ("learned motion matching", Path(lmm_dir), ("lmm.onnx",))]
    rows += [(f"backbone {sk} only", Path(runs_dir) / f"gen_{sk}", ("backbone.onnx", "backbone.pt"))
             for sk in S.SKELETONS]
    figures["models"] = {}
    for label, folder, files in rows:
        cfg = folder / "train_config.json"
        if not cfg.is_file():
            continue
        res = json.loads(cfg.read_text()).get("result", {})
        sizes = {f: (folder / f).stat().st_size for f in files if (folder / f).is_file()}
        figures["models"][label] = {"result": res, "bytes": sizes}
        cpu = f"{res['cpu_s'] / 60:.1f} CPU-min" if "cpu_s" in res else "CPU time not recorded"
        load = f", load average {res['load_average']:.1f}" if "load_average" in res else ""
        print(f"  {label:<28} {res.get('wall_s', float('nan')) / 60:5.1f} min wall, {cpu}{load}; "
              + ", ".join(f"{f} {b / 2**20:.2f} MB" for f, b in sizes.items()))
    print()


def _variant_table(shared_path, runs_dir, figures: dict) -> None:
    from pathlib import Path

    from g1_control.generator import skeleton as S
    from g1_control.generator.baselines import InterpolationInbetweener
    from g1_control.generator.learned import OnnxInbetweener

    print("one backbone for every G1 variant: held-out figures per skeleton, shared model vs a model trained on "
          "that variant alone")
    header = (f"{'skeleton':<20} {'model':<14} {'L2P@15':>7} {'L2Q@15':>7} {'NPSS@15':>8} {'L2P@30':>7} {'L2Q@30':>7} "
              f"{'NPSS@30':>8} {'fingers rad':>11}")
    print(header)
    print("-" * len(header))
    figures["variants"] = {}
    for sk in S.SKELETONS:
        try:
            (train_f, train_s), (test_f, test_s) = _load(None, sk)
        except Exception as exc:  # library not built
            print(f"{sk:<20} (no library: {exc})")
            continue
        own = Path(runs_dir) / f"gen_{sk}" / "backbone.onnx"
        methods = [("interpolation", InterpolationInbetweener()), ("shared", OnnxInbetweener(shared_path, skeleton=sk))]
        if own.is_file():
            methods.append((f"{sk} only", OnnxInbetweener(own, skeleton=sk)))
        rows = {}
        for label, m in methods:
            row = []
            fing = []
            for gap in (15, 30):
                w = E.make_windows(test_f, test_s, gap)
                stats = E.PositionStats.from_windows(E.make_windows(train_f, train_s, gap))
                r = E.score(m, w, stats)
                row += [r.l2p, r.l2q, r.npss]
                if S.skeleton(sk).has_fingers:
                    pred = m.infill(w.context, w.target, np.ones((len(w.frames), F.DIM), bool), gap, w.style)
                    fing.append(float(np.abs(pred[..., F.FINGERS] - w.truth[..., F.FINGERS]).mean()))
            rows[label] = row + ([float(np.mean(fing))] if fing else [])
            fs = f"{rows[label][-1]:>11.4f}" if fing else f"{'':>11}"
            print(f"{sk:<20} {label:<14} {row[0]:>7.3f} {row[1]:>7.3f} {row[2]:>8.5f} {row[3]:>7.3f} {row[4]:>7.3f} "
                  f"{row[5]:>8.5f} {fs}")
        if not own.is_file():
            print(f"{sk:<20} ({own}: no per-variant model; scripts/retrain_generator.sh trains it)")
        figures["variants"][sk] = rows
    print()


def main(args) -> int:
    from pathlib import Path

    from g1_control.generator.baselines import InterpolationInbetweener, MotionMatchingInbetweener
    from g1_control.generator.feedback import FeedbackInbetweener, ReferenceFeedback
    from g1_control.generator.foot_lock import FootLockedInbetweener
    from g1_control.generator.learned import SHIPPED_DIR, OnnxInbetweener
    from g1_control.generator.lmm import SHIPPED_LMM_DIR, LearnedMotionMatchingInbetweener
    from g1_control.generator.runtime import InbetweeningGenerator
    from g1_control.generator.style_stats import load_style_stats

    sections = _sections()
    t_start = time.perf_counter()
    (train_f, train_s), (test_f, test_s) = _load(getattr(args, "library", None))
    model_path = Path(os.environ.get("G1_GENERATOR_ONNX") or SHIPPED_DIR / "backbone.onnx")
    lmm_dir = Path(os.environ.get("G1_GENERATOR_LMM") or SHIPPED_LMM_DIR)
    runs_dir = Path(os.environ.get("G1_GENERATOR_VARIANT_RUNS") or "runs")
    backbone = OnnxInbetweener(model_path)
    fb_path = model_path.parent / "feedback.npz"
    feedback = ReferenceFeedback.load(fb_path, "g1_29dof")
    with_fb = FeedbackInbetweener(backbone, feedback, "backbone+feedback")
    interp = InterpolationInbetweener()
    mm = MotionMatchingInbetweener(train_f)
    lmm = LearnedMotionMatchingInbetweener(lmm_dir) if (lmm_dir / "lmm.onnx").is_file() else None
    styles = load_style_stats(model_path.parent / "style_stats.json")
    figures: dict = {"load": os.getloadavg()[0], "model": str(model_path), "lmm": str(lmm_dir), "quality": [],
                     "partial": {}}
    print(f"g1 bench generator: {len(test_f)} held-out clips, {len(train_f)} training clips (29-DoF); model {model_path}; "
          f"LMM {lmm_dir if lmm else '(none: g1 train lmm)'}")
    print(f"load average at start: {os.getloadavg()[0]:.2f} (2 cores shared: wall timings are noisy; CPU-time "
          "figures count this process' own core time)\n")
    methods: list = [interp, mm] + ([lmm] if lmm else []) + [backbone, with_fb, FootLockedInbetweener(backbone),
                                                              FootLockedInbetweener(with_fb)]
    windows = {gap: E.make_windows(test_f, test_s, gap) for gap in (15, 30)}
    if "quality" in sections:
        table: dict = {}
        stats = {gap: E.PositionStats.from_windows(E.make_windows(train_f, train_s, gap)) for gap in (15, 30)}
        judged = {}  # foot skating on the ground truth's stance frames, from the same gap-30 predictions
        for m in methods:
            pred30 = E.predict(m, windows[30])
            r15, r30 = E.score(m, windows[15], stats[15]), E.score_predictions(m.name, pred30, windows[30], stats[30], 30.0)
            if m.name in ("motion_matching", "backbone", "backbone+foot lock", "backbone+feedback+foot lock"):
                judged[m.name] = E.skate_on_true_stance(pred30, windows[30].truth, 30.0)
            _, cps = _throughput(m, windows[30])
            table[m.name] = {"15": r15.__dict__, "30": r30.__dict__, "memory_bytes": _memory_bytes(m),
                             "cpu_us_per_frame": 1e6 / cps}
            figures["quality"] += [r15.__dict__, r30.__dict__]
        truth = E.foot_quality(windows[30].truth, 30.0)
        header = (f"{'method':<28} {'L2P@15':>7} {'L2Q@15':>7} {'NPSS@15':>8} {'L2P@30':>7} {'L2Q@30':>7} {'NPSS@30':>8} "
                  f"{'skate@30':>9} {'memory':>9} {'us/frame':>9}")
        print("held-out in-betweening (Harvey et al. protocol), 29-DoF G1; skate = stance-foot speed m/s (gap 30); "
              "memory = database or weights; us/frame = CPU time per frame, batched 256 x 30")
        print(header)
        print("-" * len(header))
        for name, row in table.items():
            a, b = row["15"], row["30"]
            print(f"{name:<28} {a['l2p']:>7.3f} {a['l2q']:>7.3f} {a['npss']:>8.5f} {b['l2p']:>7.3f} {b['l2q']:>7.3f} "
                  f"{b['npss']:>8.5f} {b['skate_mps']:>9.3f} {row['memory_bytes'] / 2**20:>7.2f}MB "
                  f"{row['cpu_us_per_frame']:>9.2f}")
        print(f"{'(ground truth)':<28} {'':>7} {'':>7} {'':>8} {'':>7} {'':>7} {'':>8} {truth[0]:>9.3f}")
        figures["quality_table"] = table
        bb, ip, mt = table["backbone"], table["interpolation"], table["motion_matching"]
        for key in ("15", "30"):
            print(f"  gap {key}: backbone / interpolation L2P {bb[key]['l2p'] / ip[key]['l2p']:.2f}x, / motion matching "
                  f"{bb[key]['l2p'] / mt[key]['l2p']:.2f}x" + (
                      f"; learned MM / motion matching L2P {table['learned_motion_matching'][key]['l2p'] / mt[key]['l2p']:.2f}x"
                      if lmm else ""))
        if lmm:
            print(f"  learned motion matching keeps {table['learned_motion_matching']['memory_bytes'] / 2**20:.2f} MB of "
                  f"weights against motion matching's {mt['memory_bytes'] / 2**20:.1f} MB database "
                  f"({mt['memory_bytes'] / table['learned_motion_matching']['memory_bytes']:.0f}x less)")
        figures["skate_on_true_stance_30"] = judged
        print("  foot skating at gap 30 on the ground truth's stance frames (m/s): " + ", ".join(
            f"{k} {v:.3f}" for k, v in judged.items()) + f", ground truth {truth[0]:.3f}")
        errs = []
        for gap, w in windows.items():
            n = min(256, len(w.frames))
            backbone.infill(w.context[:n], w.target[:n], np.ones((n, F.DIM), bool), gap, w.style[:n])
            assert backbone.last_duration is not None  # infill just set it
            errs.append(np.abs(backbone.last_duration - gap))
        figures["duration_mae_frames"] = float(np.concatenate(errs).mean())
        print(f"  duration head on held-out 15- and 30-frame transitions: mean error {figures['duration_mae_frames']:.1f} "
              "frames (a constant guess of 22.5 frames: 7.5)\n")

    def runtime(inbetweener, fb=None, goal_error: bool = True, foot_lock: bool = True):
        from g1_control.generator.runtime import RuntimeConfig

        config = RuntimeConfig(foot_lock=foot_lock) if goal_error else RuntimeConfig(goal_error_gain=0.0,
                                                                                      foot_lock=foot_lock)
        return InbetweeningGenerator(inbetweener, styles, config, feedback=fb)

    if "goals" in sections:
        print("joint-level goals, model only (FK of the runtime's reference, no IK): hand goals in a cylinder "
              "r 0.25-1.5 m, z 0.8-1.25 m around the robot, from unseen held-out start poses, 8 s each.\n"
              "single shot: the network's plans alone; the other rows add the runtime's goal-error feedback (the "
              "remaining error of the model's own last frame, by FK, added to the goal it is given)")
        header = f"{'runtime':<24} {'success<5cm':>11} {'held at end':>11} {'DTG end m':>9} {'DTG best m':>10} {'t reach s':>9}"
        print(header)
        print("-" * len(header))
        figures["goals"] = {}
        for label, factory in (("interpolation", lambda: runtime(interp)),
                               ("backbone, single shot", lambda: runtime(backbone, goal_error=False)),
                               ("backbone", lambda: runtime(backbone)),
                               ("backbone+feedback", lambda: runtime(backbone, ReferenceFeedback.load(fb_path, "g1_29dof")))):
            r = wandr_goals(factory, test_f)
            figures["goals"][label] = r
            t = f"{r['time_to_reach_s']:>9.2f}" if r["time_to_reach_s"] is not None else f"{'-':>9}"
            print(f"{label:<24} {100 * r['success']:>10.1f}% {100 * r['held_at_end']:>10.1f}% {r['dtg_final_m']:>9.3f} "
                  f"{r['dtg_closest_m']:>10.3f} {t}")
        print("\n10-minute sequence of hand goals (a new goal every 8 s), model only: success, foot skating of the "
              "reference, drift (distance to the default style's reference mixture, pelvis height: first / last minute)")
        figures["goal_sequence"] = {}
        for label, fb in (("backbone", None), ("backbone+feedback", ReferenceFeedback.load(fb_path, "g1_29dof"))):
            t0 = time.perf_counter()
            r = goal_sequence(runtime(backbone, fb), feedback)
            figures["goal_sequence"][label] = r
            print(f"  {label:<22} {r['goals']} goals, success {100 * r['success']:5.1f} %, skating {r['skate_mps']:.3f} m/s, "
                  f"manifold distance {r['manifold_first_min']:.2f} -> {r['manifold_last_min']:.2f}, pelvis "
                  f"{r['pelvis_first_min_m']:.3f} -> {r['pelvis_last_min_m']:.3f} m ({time.perf_counter() - t0:.0f} s)")
        print("\npartial keyframes (root + right hand only), 30-frame gap, hand by FK of the last generated frame: "
              "success within 10 cm, hand / root distance")
        for m in (interp, mm, backbone):
            s, hd, rd = _partial_keyframes(m, windows[30])
            figures["partial"][m.name] = {"success": s, "hand_m": hd, "root_m": rd}
            print(f"  {m.name:<16} success {100 * s:5.1f} %   hand {hd:.3f} m   root {rd:.3f} m")
        eff = effector_goals_through_ik(lambda: runtime(backbone))
        figures["effector_goals_ik"] = eff
        print(f"  runtime + IK, right-hand goals in front of a standing robot: success {100 * eff['success']:.0f} % "
              f"of {eff['goals']}, distance to goal mean {eff['mean_m']:.3f} m, max {eff['max_m']:.3f} m\n")
    if "variants" in sections:
        _variant_table(model_path, runs_dir, figures)
    if "models" in sections:
        _models_table(model_path, lmm_dir, runs_dir, figures)
    if "codebook" in sections:
        stats30 = E.PositionStats.from_windows(E.make_windows(train_f, train_s, 30))
        floor = _codebook_floor(train_f, windows[30], stats30)
        figures["codebook512_l2q_30"] = floor.l2q
        print(f"tokenisation floor: joints snapped to a 512-code k-means codebook leave L2Q {floor.l2q:.3f} at gap 30 "
              f"(L2P {floor.l2p:.3f})\n")
    if "speed" in sections:
        print("speed (this CPU, 1 inference thread): replan = primitives + model + feedback + stabilization")
        fb30 = ReferenceFeedback.load(fb_path, "g1_29dof")
        speed_methods = [("interpolation", interp, None, True), ("backbone", backbone, None, True),
                         ("backbone+feedback", backbone, fb30, True),
                         ("backbone+feedback, no foot lock", backbone, fb30, False)]
        if lmm:
            speed_methods.insert(1, ("learned_motion_matching", lmm, None, True))
        lat_rows = {}
        for label, m, fb, lock in speed_methods:
            lat, cpu = _latency(lambda m=m, fb=fb, lock=lock: _fresh(runtime(m, fb, foot_lock=lock)))
            row = {"wall_p50": float(np.percentile(lat, 50)), "wall_p99": float(np.percentile(lat, 99)),
                   "cpu_p50": float(np.percentile(cpu, 50)), "cpu_p99": float(np.percentile(cpu, 99))}
            lat_rows[label] = row
            figures[f"replan_ms_{label}"] = row
            print(f"  replan {label:<32} wall p50 {row['wall_p50']:6.3f} ms  p99 {row['wall_p99']:6.3f} ms   | CPU time "
                  f"p50 {row['cpu_p50']:6.3f} ms  p99 {row['cpu_p99']:6.3f} ms")
        ip = lat_rows["interpolation"]
        bf = lat_rows["backbone+feedback"]
        nl = lat_rows["backbone+feedback, no foot lock"]
        print(f"  backbone+feedback / interpolation replan (CPU p50): {bf['cpu_p50'] / ip['cpu_p50']:.2f}x; "
              f"the foot lock's share: {bf['cpu_p50'] / nl['cpu_p50']:.2f}x (p50), {bf['cpu_p99'] / nl['cpu_p99']:.2f}x "
              f"(p99); goal p50 <= 1 ms, p99 <= 1.5 ms")
        thr = {}
        for m in [interp] + ([lmm] if lmm else []) + [backbone]:
            thr[m.name] = _throughput(m, windows[30])
        figures["throughput_fps"] = {k: {"wall": v[0], "cpu": v[1]} for k, v in thr.items()}
        for k, (wall_fps, cpu_fps) in thr.items():
            print(f"  batched 256 x 30 frames: {k:<24} {wall_fps:>10,.0f} frames/s wall, {cpu_fps:>10,.0f} frames/CPU-s "
                  f"(ratio to interpolation {wall_fps / thr['interpolation'][0]:.2f} wall, "
                  f"{cpu_fps / thr['interpolation'][1]:.2f} CPU)")
        print("  goal: >= 150,000 frames/s\n")
    if "rollout" in sections:
        print("10-minute autoregressive rollout under random commands and styles (backbone + feedback)")
        t0 = time.perf_counter()
        roll = long_rollout(_fresh(runtime(backbone, ReferenceFeedback.load(fb_path, "g1_29dof"))), 600.0)
        figures["rollout"] = roll
        print(f"  finite {roll['finite']}; pelvis {roll['pelvis_min_m']:.3f}-{roll['pelvis_max_m']:.3f} m; "
              f"max tilt {roll['tilt_max_deg']:.1f} deg; joint-limit violations {roll['joint_limit_violations']}; "
              f"{roll['replans']} replans, {roll['fallbacks']} fallbacks; mean leg joint speed first/last minute "
              f"{roll['leg_speed_first_min_radps']:.2f}/{roll['leg_speed_last_min_radps']:.2f} rad/s; "
              f"{time.perf_counter() - t0:.1f} s wall")
    print(f"\ntotal {time.perf_counter() - t_start:.0f} s")
    if getattr(args, "json", None):
        with open(args.json, "w") as fh:
            json.dump(figures, fh, indent=1, default=float)
    return 0


def _fresh(gen):
    from g1_control.robot import g1
    from g1_control.types import RobotState

    gen.reset(RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M])))
    return gen
