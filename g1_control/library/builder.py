"""Build the motion library (see __init__.py): sources -> clips cut into pieces -> mirrored ->
split by clip -> written with an index. Cached: a build whose configuration matches the
index on disk is skipped unless forced."""

from __future__ import annotations

import hashlib
import itertools
import json
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from g1_control.fanout import fan_out
from g1_control.motion.clip import MotionClip
from g1_control.motion.library import INDEX_NAME, LibraryError, MotionLibrary

BUILD_VERSION = 3
"""Bumped when the builder's output changes for the same configuration (invalidates caches).
2: demo mocap retargeted with the collision-aware IK and the URDF's ankle/waist limits (issue 12).
3: every piece gated on `g1 check`'s acceptance figures; a failing piece is repaired through the
   IK, or left out (issue 23)."""

LICENSES = {
    "rollout": "generated here (g1-control) with holosoma-inference 0.1.3's loco policy (Apache-2.0 upstream)",
    "wbt": "reference clip read out of holosoma-inference 0.1.3's WBT ONNX (Apache-2.0 upstream)",
    "demo": "retargeted here from holosoma-retargeting 0.1.0 demo mocap (Apache-2.0 upstream)",
}


@dataclass
class LibraryConfig:
    fps: float = 30.0
    rollout_seconds: float = 45.0
    rollouts_per_style: int = 2
    rollout_styles: tuple[str, ...] | None = None
    """None: every style in styles.ROLLOUT_STYLES."""
    dance: bool = True
    demo: bool = True
    mirror: bool = True
    clip_seconds: float = 8.0
    test_every: int = 5
    """Every test_every-th piece of each source (offset 2) is held out."""
    gate: bool = True
    """Admit only pieces that meet `g1 check`'s acceptance figures (no limit violation, no link in
    the floor or the scene, no self-collision, sliding on <= 1 % of stance frames); a piece that
    misses them is repaired (`repair`) or left out with its mirror, and the index says which and
    why (`gate`)."""
    repair: bool = True
    """A piece that fails the gate goes through the IK (library/repair.py) and is admitted, tagged
    ik_repaired, when the repaired piece passes `g1 check`; else it is left out."""

    def key(self) -> str:
        blob = json.dumps({"v": BUILD_VERSION, **asdict(self)}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]


def rollout_job(args: tuple[str, int, float, float]) -> tuple[MotionClip | None, dict]:
    """One seeded rollout (style, seed, seconds, fps) -> (its clip, or None; what happened), from
    its arguments alone (what `--jobs` processes and Ray workers run; g1_control/fanout.py)."""
    from g1_control.generator.styles import ROLLOUT_STYLES
    from g1_control.library.rollouts import RolloutConfig, record_rollout

    style, seed, seconds, fps = args
    return record_rollout(ROLLOUT_STYLES[style], RolloutConfig(duration_s=seconds, seed=seed, fps=fps))


def _demo_clips(fps: float) -> list[MotionClip]:
    from g1_control.assets import fetch
    from g1_control.motion.formats.dispatch import load_human_motion
    from g1_control.retarget.mocap import MocapRetargetConfig, MocapRetargeter

    root = fetch("holosoma-demo-mocap") / "holosoma_retargeting" / "demo_data"
    out = []
    for path in sorted(root.glob("climb/*/*.npy")) + sorted(root.glob("OMOMO_new/*.pt")):
        clip = MocapRetargeter(MocapRetargetConfig(fps=fps)).retarget(load_human_motion(str(path)))
        clip.style = "climb" if "climb" in str(path) else "lift"
        clip.source = path.stem
        clip.tags = ("demo", "retargeted")
        out.append(clip)
    return out


def cut(clip: MotionClip, seconds: float) -> list[MotionClip]:
    """Consecutive pieces of about `seconds`; a short tail joins the last piece."""
    from g1_control.motion.edit import slice_clip

    n = max(1, round(seconds * clip.fps))
    count = max(1, clip.num_frames // n)
    bounds = [i * n for i in range(count)] + [clip.num_frames]
    return [slice_clip(clip, a, b) for a, b in itertools.pairwise(bounds)]


def gate_reasons(clip: MotionClip) -> list[str]:
    """Why `clip` fails `g1 check` (measured on its own scene, as `g1 check` does), [] when it passes."""
    from g1_control.retarget.metrics import compute_metrics, failures

    return failures(compute_metrics(clip))


def gate_piece(piece: MotionClip, repair: bool = True) -> tuple[MotionClip | None, dict]:
    """The library gate on one piece: (the piece to admit, or None; what happened). A piece that
    fails `g1 check` is repaired through the IK when `repair`, and admitted only if the repaired
    piece passes; the record says why it failed, and what the repair changed or why it still fails."""
    reasons = gate_reasons(piece)
    if not reasons:
        return piece, {}
    record: dict = {"reasons": reasons}
    if not repair:
        return None, record
    from g1_control.library.repair import repair_piece

    fixed, deviation = repair_piece(piece)
    record.update(deviation)
    after = gate_reasons(fixed)
    if after:
        record["after_repair"] = after
        return None, record
    return fixed, record


def build_library(out_dir: str | Path, config: LibraryConfig | None = None, *, force: bool = False,
                  jobs: int = 1, ray: str | None = None, progress: bool = True) -> MotionLibrary:
    """Build (or reuse) the library in `out_dir`; the rollouts fan out over `jobs` processes or the
    Ray cluster at `ray` (g1_control/fanout.py), the same clips either way."""
    from tqdm import tqdm

    from g1_control.generator.styles import ROLLOUT_STYLES
    from g1_control.motion.formats.clip_npz import write_clip_npz
    from g1_control.motion.mirror import mirror

    config = config or LibraryConfig()
    out = Path(out_dir)
    index_path = out / INDEX_NAME
    if index_path.is_file() and not force:
        try:
            if json.loads(index_path.read_text()).get("key") == config.key():
                return MotionLibrary(out)
        except json.JSONDecodeError:
            pass
    styles = config.rollout_styles or tuple(ROLLOUT_STYLES)
    unknown = [s for s in styles if s not in ROLLOUT_STYLES]
    if unknown:
        raise LibraryError(f"unknown rollout styles {unknown}; known: {', '.join(ROLLOUT_STYLES)}")
    started = time.perf_counter()
    sources: list[MotionClip] = []
    infos: list[dict] = []
    tasks = [(s, 100 + k, config.rollout_seconds, config.fps) for s in styles for k in range(config.rollouts_per_style)]
    rollouts = fan_out(rollout_job, tasks, jobs=jobs, ray=ray)  # a bad --jobs/--ray stops here, before the bar
    bar = tqdm(total=len(tasks) + int(config.dance) + int(config.demo), desc="library sources", unit="src",
               file=sys.stderr, disable=not progress)
    for clip, info in rollouts:
        sources += [clip] if clip is not None else []
        infos.append(info)
        bar.update()
    if config.dance:
        from g1_control.library.dance import extract_dance

        sources.append(extract_dance(fps=config.fps))
        bar.update()
    if config.demo:
        sources += _demo_clips(config.fps)
        bar.update()
    bar.close()
    (out / "clips").mkdir(parents=True, exist_ok=True)
    for old in (out / "clips").glob("*.npz"):
        old.unlink()
    cut_sources = [(source, cut(source, config.clip_seconds)) for source in sources]
    # Sources too short to give 3 pieces are held out whole: the second of each style (when a
    # style has at least 3 such sources), so every split holds whole, unseen performances.
    short: dict[str, list[str]] = {}
    for source, pieces in cut_sources:
        if len(pieces) < 3:
            short.setdefault(source.style, []).append(source.source)
    held_out_sources = {names[1] for names in short.values() if len(names) >= 3}
    entries: list[dict] = []
    left_out: list[dict] = []
    repaired: list[dict] = []
    for source, pieces in tqdm(cut_sources, desc="check, mirror, write", unit="src", file=sys.stderr,
                               disable=not progress):
        for k, piece in enumerate(pieces):
            long_held = len(pieces) >= 3 and k % config.test_every == 2
            split = "test" if long_held or source.source in held_out_sources else "train"
            if config.gate:
                admitted, record = gate_piece(piece, config.repair)
                if record:
                    record = {"name": f"{source.source}_{k:02d}", "source": source.source, "style": source.style,
                              "split": split, "num_frames": piece.num_frames, **record}
                    (repaired if admitted is not None else left_out).append(record)
                if admitted is None:
                    continue
                piece = admitted
            variants = [(piece, False)] + ([(mirror(piece), True)] if config.mirror else [])
            for clip, mirrored in variants:
                name = f"{source.source}_{k:02d}{'_mirror' if mirrored else ''}"
                clip.source = name
                write_clip_npz(clip, out / "clips" / f"{name}.npz")
                entries.append({"name": name, "file": f"clips/{name}.npz", "style": clip.style, "split": split,
                                "source": source.source, "mirrored": mirrored, "num_frames": clip.num_frames})
    gate = {"checked": config.gate, "repair": config.repair, "repaired": repaired, "left_out": left_out}
    index = {"key": config.key(), "version": BUILD_VERSION, "fps": config.fps, "config": asdict(config),
             "licenses": LICENSES, "rollouts": infos, "build_s": round(time.perf_counter() - started, 1),
             "gate": gate, "clips": entries}
    index_path.write_text(json.dumps(index, indent=1))
    if (left_out or repaired) and progress:
        print(gate_summary(gate), file=sys.stderr)
    return MotionLibrary(out)


def gate_summary(gate: dict) -> str:
    """What the gate repaired and left out, one line per piece (name, split, why, what the repair did)."""
    repaired, left_out = gate.get("repaired", []), gate.get("left_out", [])
    lines = []
    if repaired:
        lines.append(f"library gate: {len(repaired)} piece(s) failed `g1 check` and were repaired through the IK "
                     "(admitted, tagged ik_repaired):")
        lines += [f"  {e['name']} ({e['style']}, {e['split']}): {'; '.join(e['reasons'])}; repaired: joints moved "
                  f"{e['joint_deviation_mean_rad']:.3f} rad on average, up to {e['joint_deviation_max_rad']:.2f} "
                  f"({e['joint_deviation_max_at']})" for e in repaired]
    if left_out:
        lines.append(f"library gate: {len(left_out)} piece(s) left out (and their mirrors): they fail `g1 check`"
                     + (" even after the IK repair" if gate.get("repair") else ""))
        lines += [f"  {e['name']} ({e['style']}, {e['split']}): {'; '.join(e['reasons'])}"
                  + (f"; after the repair: {'; '.join(e['after_repair'])}" if e.get("after_repair") else "")
                  for e in left_out]
    return "\n".join(lines)

