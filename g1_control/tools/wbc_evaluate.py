"""Run the WBC on the scripted references in MuJoCo (lockstep) and report tracking figures.

    python -m g1_control.tools.wbc_evaluate                       # every reference, stand for 60 s
    python -m g1_control.tools.wbc_evaluate walk crouch --json out.json
    python -m g1_control.tools.wbc_evaluate stand --push          # 50 N, 0.2 s push on the pelvis at t = 2 s
    python -m g1_control.tools.wbc_evaluate --compare-wbt         # and holosoma's WBT policy on the same references

Figures per reference: fell or not; joint RMS error (rad, all 29 joints, every tracker tick);
pelvis height error (RMS and max, m); base position drift (horizontal distance between the
simulated pelvis and the reference's, at the end and at most, m). Ground truth is read from the
simulator for the figures only; the controller never sees it.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Literal, cast

import numpy as np

if TYPE_CHECKING:
    from g1_control.trackers.wbc.tracker import WholeBodyTracker

DEFAULT_TRACKER_HZ = 250.0


@dataclass
class TrackingFigures:
    reference: str
    controller: str
    fell: bool
    duration_s: float
    joint_rms_rad: float
    pelvis_height_rms_m: float
    pelvis_height_max_m: float
    base_drift_final_m: float
    base_drift_max_m: float
    wall_s: float
    qp_failures: int = 0
    qp_unsolved: int = 0
    tracker_p50_us: float = 0.0
    tracker_p99_us: float = 0.0
    hand_error_m: float | None = None
    """lean_reach only: simulated right hand to the target point, mean over the hold."""
    fall_detail: str = ""
    """How and when it fell (g1_control/safety/fall.py); empty when it did not."""

    def row(self) -> str:
        return (f"{self.reference:<14} {self.controller:<6} {'FELL' if self.fell else 'ok':<5} {self.duration_s:6.1f} "
                f"{self.joint_rms_rad:9.4f} {self.pelvis_height_rms_m:9.4f} {self.pelvis_height_max_m:9.4f} "
                f"{self.base_drift_final_m:9.4f} {self.base_drift_max_m:9.4f} {self.tracker_p50_us:8.0f} "
                f"{self.tracker_p99_us:8.0f} {self.wall_s:7.1f} {self.qp_failures:4d}/{self.qp_unsolved}")


HEADER = (f"{'reference':<14} {'ctrl':<6} {'fall':<5} {'sim s':>6} {'joint rms':>9} {'z rms':>9} {'z max':>9} "
          f"{'drift end':>9} {'drift max':>9} {'p50 us':>8} {'p99 us':>8} {'wall s':>7} relaxed/unsolved QPs")


Controller = Literal["wbc", "wbt"]


def evaluation_launch(reference: str, params: dict | None = None, *, controller: Controller = "wbc",
                      tracker_hz: float = DEFAULT_TRACKER_HZ, duration_s: float | None = None,
                      variant: str = "g1_29dof"):
    """The evaluation as a launch file: a scripted reference tracked by the WBC (or the WBT policy
    at its 50 Hz), an idle operator, MuJoCo in lockstep, on the G1 `variant` (backend.expected_variant:
    the simulator builds it, the reference is solved and the WBC runs on its model).
    duration_s: default, the reference's."""
    from g1_control.generator.scripted import build_reference
    from g1_control.launch.schema import LaunchFile
    from g1_control.loop.rates import LoopRates
    from g1_control.teleop.scripted import Segment

    if controller not in ("wbc", "wbt"):
        raise ValueError(f"controller must be 'wbc' or 'wbt'; got {controller!r}")
    params = dict(params or {})
    if duration_s is None:
        duration_s = build_reference(reference, variant=variant, **params).duration_s
    launch = LaunchFile(name=f"wbc_evaluate_{reference}_{controller}", duration_s=duration_s)
    launch.backend.expected_variant = variant  # type: ignore[assignment]  # checked by validate() below
    launch.generator.type, launch.generator.reference = "scripted", reference
    launch.generator.reference_params = params
    launch.tracker.type = controller
    hz = 50.0 if controller == "wbt" else tracker_hz
    launch.rates = LoopRates(lowlevel_hz=500.0, tracker_hz=hz, input_hz=50.0, estimator_hz=100.0)
    launch.input.timeline = [Segment(duration_s=duration_s, label="idle")]
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    launch.validate("")
    return launch


def run_wbc(reference: str, params: dict | None = None, *, tracker_hz: float = DEFAULT_TRACKER_HZ,
            push_n: float = 0.0, push_at_s: float = 2.0, push_s: float = 0.2, duration_s: float | None = None,
            controller: Controller = "wbc", variant: str = "g1_29dof"):
    """Run the scripted `reference` (with `params`) with the WholeBodyTracker (or, controller="wbt",
    holosoma's WBT policy at 50 Hz); returns (TrackingFigures, loop)."""
    from g1_control.generator.scripted import TrajectoryGenerator
    from g1_control.launch.builder import build_loop
    from g1_control.sim.mujoco_backend import MujocoBackend

    loop = build_loop(evaluation_launch(reference, params, controller=controller, tracker_hz=tracker_hz,
                                        duration_s=duration_s, variant=variant))
    tracker, generator, sim = loop.tracker, loop.generator, loop.backend
    # What evaluation_launch asks for: a scripted reference on MuJoCo (build_loop's default backend).
    assert isinstance(generator, TrajectoryGenerator) and isinstance(sim, MujocoBackend)
    loop.reset()
    push_tick = round(push_at_s * loop.rates.lowlevel_hz)

    def on_tick(i: int) -> None:
        if push_n and i == push_tick:
            sim.push([push_n, 0.0, 0.0], push_s)

    duration = generator.trajectory.duration_s if duration_s is None else duration_s
    t0 = time.perf_counter()
    loop.scheduler.run(round(duration * loop.rates.lowlevel_hz), stop=lambda: loop.fell, progress=on_tick)
    wall = time.perf_counter() - t0
    figures = figures_of(generator.trajectory, loop, controller, wall)
    if controller == "wbc":
        # What build_loop makes for tracker.type "wbc" (by name at run time: tests and the WBC bench swap it).
        wbc = cast("WholeBodyTracker", tracker)
        figures.qp_failures = wbc.diagnostics.solve_failures
        figures.qp_unsolved = wbc.diagnostics.unsolved_ticks
    return figures, loop


def figures_of(trajectory, loop, controller: str, wall_s: float) -> TrackingFigures:
    log = loop.log.arrays()
    t = log["t_s"]
    ref = [trajectory.sample(tk) for tk in t]
    q_ref = np.array([r.q_rad for r in ref])
    root_ref = np.array([r.root_pos_w_m for r in ref])
    joint_err = log["q_rad"] - q_ref
    z_err = log["base_pos_m"][:, 2] - root_ref[:, 2]
    xy_err = np.linalg.norm(log["base_pos_m"][:, :2] - root_ref[:, :2], axis=1)
    timing = loop.scheduler.report()["tracker"]
    hand_error = _hand_error(trajectory, log) if "hand_target_w_m" in trajectory.extras else None
    return TrackingFigures(
        reference=trajectory.name, controller=controller, fell=bool(loop.fell), duration_s=float(loop.time_s),
        joint_rms_rad=float(np.sqrt(np.mean(joint_err**2))),
        pelvis_height_rms_m=float(np.sqrt(np.mean(z_err**2))), pelvis_height_max_m=float(np.abs(z_err).max()),
        base_drift_final_m=float(xy_err[-1]), base_drift_max_m=float(xy_err.max()), wall_s=wall_s,
        tracker_p50_us=timing["p50_us"], tracker_p99_us=timing["p99_us"], hand_error_m=hand_error,
        fall_detail=str(loop.fall) if loop.fall else "")


def _hand_error(trajectory, log) -> float:
    import pinocchio as pin

    from g1_control.robot.dynamics import build_model

    model = build_model()
    data = model.createData()
    fid = model.getFrameId("right_hand")
    t0, t1 = trajectory.extras["hold_window_s"]
    rows = np.flatnonzero((log["t_s"] >= t0) & (log["t_s"] <= t1))
    if rows.size == 0:
        return float("nan")
    hands = []
    for k in rows:
        w, x, y, z = log["base_quat_wxyz"][k]
        pin.framesForwardKinematics(model, data, np.concatenate([log["base_pos_m"][k], [x, y, z, w], log["q_rad"][k]]))
        hands.append(data.oMf[fid].translation.copy())
    return float(np.linalg.norm(np.mean(hands, axis=0) - trajectory.extras["hand_target_w_m"]))


def main(argv: list[str] | None = None) -> int:
    from g1_control.generator.scripted import REFERENCES
    from g1_control.launch.schema import VARIANT_NAMES

    parser = argparse.ArgumentParser(prog="python -m g1_control.tools.wbc_evaluate", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("references", nargs="*", default=list(REFERENCES), help=f"any of {', '.join(REFERENCES)}")
    parser.add_argument("--stand-seconds", type=float, default=60.0, help="length of the stand reference (default 60)")
    parser.add_argument("--push", action="store_true", help="push the pelvis with 50 N for 0.2 s at t = 2 s")
    parser.add_argument("--tracker-hz", type=float, default=DEFAULT_TRACKER_HZ)
    parser.add_argument("--compare-wbt", action="store_true",
                        help="also run holosoma's WBT dance policy (ppo) on each reference, for comparison")
    parser.add_argument("--variant", default="g1_29dof", choices=VARIANT_NAMES,
                        help="the G1 simulated and modelled (default g1_29dof; g1_23dof: no waist roll/pitch, no "
                        "wrist pitch/yaw)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = parser.parse_args(argv)
    unknown = [r for r in args.references if r not in REFERENCES]
    if unknown:
        parser.error(f"unknown reference(s) {unknown}; known: {', '.join(REFERENCES)}")
    rows = []
    print(HEADER)
    for name in args.references:
        params = {"duration_s": args.stand_seconds} if name == "stand" else {}
        controllers: tuple[Controller, ...] = ("wbc", "wbt") if args.compare_wbt else ("wbc",)
        for controller in controllers:
            figures, _ = run_wbc(name, params, tracker_hz=args.tracker_hz, push_n=50.0 if args.push else 0.0,
                                 controller=controller, variant=args.variant)
            if args.push:
                figures.reference += "+push"
            if args.variant != "g1_29dof":
                figures.reference += f"@{args.variant.removeprefix('g1_')}"
            rows.append(figures)
            hand = "" if figures.hand_error_m is None else f"  hand to target {figures.hand_error_m:.3f} m"
            print(figures.row() + hand, flush=True)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump([asdict(r) for r in rows], fh, indent=2)
    return 1 if any(r.fell for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
