"""`g1 retarget`: human motion capture (or robot clips) -> G1 motion-library clips.

    g1 retarget walk.bvh -o walk.npz
    g1 retarget mocap/*.npy -o clips/ --jobs 2 --plot
    g1 retarget --demo -o runs/demo_clips --plot      # the seven holosoma demo sequences

Inputs: world joint positions .npy (T, J, 3) / OMOMO .pt (holosoma demo data), BVH (LAFAN1
skeleton), Unitree G1 CSV, motion npz (BeyondMimic / mjlab, with or without names). Human inputs
are retargeted by whole-body IK; robot inputs are converted (and checked). Every clip gets a
metrics line; a batch goes on past bad files and lists the failures at the end (exit status 1).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict
from pathlib import Path

SUPPORTED = (".npy", ".pt", ".bvh", ".csv", ".npz")


def register(subparsers) -> None:
    parser = subparsers.add_parser(
        "retarget",
        help="retarget human mocap to the G1 (or convert G1 clips), with a metrics report",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("inputs", nargs="*", metavar="INPUT",
                        help="motion files or folders (searched for " + ", ".join(SUPPORTED) + ")")
    parser.add_argument("-o", "--output", required=True, metavar="OUT",
                        help="output file (.npz motion library clip or .csv G1 CSV) for one input, "
                        "else a folder that receives one file per input")
    parser.add_argument("--demo", action="store_true",
                        help="add the seven holosoma demo sequences (registry package, fetched into the cache)")
    parser.add_argument("--format", choices=("npz", "csv"), default="npz", help="file type written into a folder")
    parser.add_argument("--fps", type=float, default=30.0, help="output frame rate in Hz (default 30)")
    parser.add_argument("--input-fps", type=float, default=None,
                        help="frame rate of .npy / .csv inputs that do not store one (default: 120 for .npy, 30 for .csv)")
    parser.add_argument("--height", type=float, default=None, metavar="M",
                        help="performer height in m (default: from the data, else the skeleton's default)")
    parser.add_argument("--limb-scale", action="append", default=[], metavar="LIMB=F",
                        help="extra scale for one limb (left_arm, right_arm, left_leg, right_leg); repeatable")
    parser.add_argument("--joint-map", metavar="FILE", help="JSON joint map for a skeleton the tool does not know")
    parser.add_argument("--jobs", type=int, default=None, help="worker processes (default: one per core, at most one per input)")
    parser.add_argument("--plot", action="store_true", help="write a metrics PNG next to each output")
    parser.add_argument("--report", metavar="FILE", help="also write the metrics of the batch as JSON")
    parser.set_defaults(func=run)


def _collect(args) -> list[Path]:
    files: list[Path] = []
    for item in args.inputs:
        path = Path(item)
        if path.is_dir():
            files += sorted(p for p in path.rglob("*") if p.suffix.lower() in SUPPORTED)
        else:
            files.append(path)
    if args.demo:
        from g1_control.assets import fetch

        root = fetch("holosoma-demo-mocap") / "holosoma_retargeting" / "demo_data"
        files += sorted(root.glob("climb/*/*.npy")) + sorted(root.glob("OMOMO_new/*.pt"))
    return files


def _limb_scale(items: list[str]) -> dict[str, float]:
    from g1_control.ik.exceptions import IKError

    out = {}
    for item in items:
        name, _, value = item.partition("=")
        try:
            out[name] = float(value)
        except ValueError:
            raise IKError(f"--limb-scale expects LIMB=FACTOR (e.g. left_arm=1.1). Got '{item}'") from None
    return out


def process_one(path: str, out_path: str, options: dict, show_frames: bool = False) -> dict:
    """Retarget or convert one file; return its metrics as a dict, or {'error': message}."""
    from g1_control.errors import G1ControlError

    try:
        from g1_control.motion.clip import MotionClip
        from g1_control.motion.formats.dispatch import load_motion, save_clip
        from g1_control.motion.resample import resample
        from g1_control.retarget.metrics import compute_metrics, plot_metrics
        from g1_control.retarget.mocap import MocapRetargetConfig, MocapRetargeter, load_joint_map

        skeleton = load_joint_map(options["joint_map"]) if options.get("joint_map") else None
        motion = load_motion(path, joint_names=skeleton.joints if skeleton else None,
                             fps=options.get("input_fps"), height_m=options.get("height"))
        if isinstance(motion, MotionClip):
            clip = motion if motion.fps == options["fps"] else resample(motion, options["fps"])
        else:
            config = MocapRetargetConfig(fps=options["fps"], human_height_m=options.get("height"),
                                         limb_scale=options.get("limb_scale", {}))
            bar = None
            if show_frames:
                from tqdm import tqdm

                frames = int((motion.num_frames - 1) / motion.fps * options["fps"]) + 1
                bar = tqdm(total=frames, desc=Path(path).name, unit="frame", file=sys.stderr, leave=False)
            try:
                clip = MocapRetargeter(config).retarget(motion, skeleton, progress=bar.update if bar else None)
            finally:
                if bar is not None:
                    bar.close()
        Path(out_path).parent.mkdir(parents=True, exist_ok=True)
        save_clip(clip, out_path)
        metrics = compute_metrics(clip)
        if options.get("plot"):
            plot_metrics(clip, Path(out_path).with_suffix(".png"), metrics)
        return {"input": path, "output": out_path, **asdict(metrics),
                "object_contact_preserved_fraction": metrics.object_contact_preserved_fraction}
    except G1ControlError as exc:
        return {"input": path, "error": str(exc)}
    except Exception as exc:
        return {"input": path, "error": f"unexpected {type(exc).__name__}: {exc}"}


def run(args) -> int:
    from tqdm import tqdm

    from g1_control.ik.exceptions import IKError
    from g1_control.retarget.metrics import ClipMetrics, format_table

    files = _collect(args)
    if not files:
        raise IKError("no input files (give INPUT paths or --demo)")
    out = Path(args.output)
    single = len(files) == 1 and out.suffix.lower() in (".npz", ".csv")
    targets = [str(out)] if single else [str(out / f"{f.stem}.{args.format}") for f in files]
    if not single and out.suffix:
        raise IKError(f"{len(files)} inputs need a folder for -o, not the file name '{out}'")
    options = {"fps": args.fps, "input_fps": args.input_fps, "height": args.height,
               "limb_scale": _limb_scale(args.limb_scale), "joint_map": args.joint_map, "plot": args.plot}
    jobs = max(1, min(args.jobs or os.cpu_count() or 1, len(files)))
    started = time.perf_counter()
    results: list[dict] = []
    if jobs == 1:
        for f, t in tqdm(list(zip(files, targets)), desc="retarget", unit="file", file=sys.stderr,
                         disable=len(files) == 1):
            results.append(process_one(str(f), t, options, show_frames=True))
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(process_one, str(f), t, options) for f, t in zip(files, targets)]
            for fut in tqdm(as_completed(futures), total=len(futures), desc="retarget", unit="file", file=sys.stderr):
                results.append(fut.result())
    elapsed = time.perf_counter() - started
    order = {str(f): i for i, f in enumerate(files)}
    results.sort(key=lambda r: order[r["input"]])
    good = [r for r in results if "error" not in r]
    bad = [r for r in results if "error" in r]
    if good:
        fields = ClipMetrics.__dataclass_fields__
        print(format_table([ClipMetrics(**{k: r[k] for k in fields}) for r in good]))
        frames = sum(r["num_frames"] for r in good)
        print(f"\n{len(good)} clip(s), {frames} frames in {elapsed:.1f} s with {jobs} process(es): "
              f"{frames / elapsed:.0f} frames/s overall")
        failing = [r["source"] for r in good
                   if not ClipMetrics(**{k: r[k] for k in ClipMetrics.__dataclass_fields__}).passes()]
        if failing:
            print("clips outside the acceptance thresholds: " + ", ".join(failing))
    if args.report:
        import json

        Path(args.report).write_text(json.dumps(results, indent=2))
    if bad:
        print(f"\n{len(bad)} file(s) failed:", file=sys.stderr)
        for r in bad:
            message = r["error"] if r["input"] in r["error"] else f"{r['input']}: {r['error']}"
            print(f"  {message}", file=sys.stderr)
        return 1
    return 0
