"""`g1 check`: the clip quality metrics on any G1 clip file, measured from its joint trajectory
against the robot's description (URDF limits and collision meshes), whoever made the clip.

    g1 check runs/demo/*.npz                           # our clips (their own scene)
    g1 check walk.csv dance.pkl --json report.json     # Unitree CSV, GMR pickle
    g1 check climb_original.npz --scene demo_data/climb/mocap_climb_seq_0/box_models
    g1 check clip.npz --plot plots/ --mujoco           # plots; cross-check with MuJoCo's collision

Reads: motion-library / BeyondMimic / mjlab npz, Unitree G1 CSV (30 fps unless --fps), holosoma
result npz (qpos), GMR pickles. Per clip: joint position and velocity limit violations (URDF),
frames with any link > 1 cm inside the floor or a scene shape, sliding > 1 cm per frame on
near-ground frames (a foot's lowest sphere within 2 cm of what it stands on, moving vertically
< 0.1 m/s), frames with a self-collision deeper than 1 cm (every pair of non-adjacent links).
Definitions: g1_control/retarget/README.md. Exit status 1 when a clip misses the acceptance
figures (0 penetration, 0 self-collision, 0 limit violations, sliding <= 1 %) or cannot be read.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import asdict
from pathlib import Path

SUPPORTED = (".npz", ".csv", ".pkl")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "check", help="clip quality metrics (penetration, sliding, self-collision, limits) of any G1 clip file",
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("clips", nargs="+", metavar="CLIP", help="clip files or folders (" + ", ".join(SUPPORTED) + ")")
    parser.add_argument("--scene", action="append", default=[], metavar="PATH",
                        help="static scene shapes: an OBJ file (one convex shape) or a folder of them; repeatable; "
                        "replaces the clip's own scene")
    parser.add_argument("--no-scene", action="store_true", help="ignore the clip's own scene (floor only)")
    parser.add_argument("--fps", type=float, default=None, help="frame rate of files that store none (CSV: 30)")
    parser.add_argument("--json", metavar="FILE", help="write the metrics of every clip as JSON")
    parser.add_argument("--plot", metavar="DIR", help="write a PNG per clip into DIR")
    parser.add_argument("--mujoco", action="store_true",
                        help="also measure penetration and self-collision with MuJoCo's collision detection and "
                        "report the agreement")
    parser.set_defaults(func=run)


def _collect(items: list[str]) -> list[Path]:
    files: list[Path] = []
    for item in items:
        path = Path(item)
        files += sorted(p for p in path.rglob("*") if p.suffix.lower() in SUPPORTED) if path.is_dir() else [path]
    return files


def _scene(args):
    from g1_control.motion.objects import ObjectShape, load_scene, read_obj_vertices

    if args.no_scene:
        return ()
    if not args.scene:
        return None
    shapes: list = []
    for item in args.scene:
        path = Path(item)
        shapes += load_scene(path) if path.is_dir() else [ObjectShape.from_points(path.stem, read_obj_vertices(path))]
    return tuple(shapes)


def check_one(path: Path, scene, args) -> dict:
    from g1_control.motion.clip import MotionClip
    from g1_control.motion.formats.dispatch import load_motion
    from g1_control.retarget.clip_geometry import measure, mujoco_cross_check
    from g1_control.retarget.metrics import compute_metrics, plot_metrics

    clip = load_motion(path, fps=args.fps)
    if not isinstance(clip, MotionClip):
        return {"input": str(path), "error": f"{path}: human motion, not a G1 clip; retarget it first (g1 retarget)"}
    clip.source = clip.source or path.name
    geometry = measure(clip, scene)
    metrics = compute_metrics(clip, scene, geometry=geometry)
    out = {"input": str(path), **asdict(metrics), "passes": metrics.passes(),
           "object_contact_preserved_fraction": metrics.object_contact_preserved_fraction}
    if args.mujoco:
        cross = mujoco_cross_check(clip, scene)
        both_self = (geometry.self_penetration_m > 0.01) == (cross.self_penetration_m > 0.01)
        both_pen = (geometry.penetration_m > 0.01) == (cross.penetration_m > 0.01)
        out["mujoco"] = {
            "self_collision_frames": int((cross.self_penetration_m > 0.01).sum()),
            "penetration_frames": int((cross.penetration_m > 0.01).sum()),
            "frames_agreeing_self_collision": int(both_self.sum()),
            "frames_agreeing_penetration": int(both_pen.sum()),
            "max_self_depth_difference_m": float(abs(geometry.self_penetration_m - cross.self_penetration_m).max()),
            "max_penetration_difference_m": float(abs(geometry.penetration_m - cross.penetration_m).max()),
        }
    if args.plot:
        Path(args.plot).mkdir(parents=True, exist_ok=True)
        plot_metrics(clip, Path(args.plot) / f"{path.stem}.png", metrics, geometry=geometry, scene=scene)
    return out


def run(args) -> int:
    from g1_control.errors import G1ControlError
    from g1_control.motion.exceptions import MotionFormatError
    from g1_control.retarget.metrics import ClipMetrics, format_table

    files = _collect(args.clips)
    if not files:
        raise MotionFormatError("no clip files given (" + ", ".join(SUPPORTED) + ")")
    scene = _scene(args)
    results = []
    for path in files:
        try:
            results.append(check_one(path, scene, args))
        except G1ControlError as exc:
            results.append({"input": str(path), "error": str(exc)})
    good = [r for r in results if "error" not in r]
    bad = [r for r in results if "error" in r]
    if good:
        fields = ClipMetrics.__dataclass_fields__
        print(format_table([ClipMetrics(**{k: r[k] for k in fields}) for r in good]))
        for r in good:
            if r["self_collision_frames"] or r["penetration_frames"]:
                print(f"{r['source']}: deepest self-collision {r['max_self_penetration_m'] * 100:.1f} cm "
                      f"({r['self_collision_pair'] or '-'}), deepest penetration {r['max_penetration_m'] * 100:.1f} cm "
                      f"({r['penetration_link'] or '-'})")
            if "mujoco" in r:
                m = r["mujoco"]
                print(f"{r['source']}: MuJoCo finds {m['self_collision_frames']} self-collision and "
                      f"{m['penetration_frames']} penetration frames; agreement {m['frames_agreeing_self_collision']}"
                      f"/{r['num_frames']} and {m['frames_agreeing_penetration']}/{r['num_frames']} frames, depths "
                      f"within {max(m['max_self_depth_difference_m'], m['max_penetration_difference_m']) * 1000:.2f} mm")
        failing = [r["source"] for r in good if not r["passes"]]
        print(f"\n{len(good) - len(failing)} of {len(good)} clip(s) meet the acceptance figures"
              + (": outside them: " + ", ".join(failing) if failing else ""))
    if args.json:
        import json

        Path(args.json).write_text(json.dumps(results, indent=2))
    for r in bad:
        print(f"g1 check: {r['error']}", file=sys.stderr)
    return 1 if bad or any(not r["passes"] for r in good) else 0
