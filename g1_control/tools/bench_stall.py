"""`g1 bench stall`: what a stalled host does to the walking robot, with and without a command life.

On the robot path the control loop writes a motor command each tick and the link's writer thread
streams the latest one at 500 Hz (hardware/link_backend.py). When the host stalls the loop (a shared
machine: 20-200 ms), the motors keep getting the last command. The whole-body controller's command
carries a feedforward torque and a velocity target meant for one tick. Resent as it is, they keep
pushing the joints through the stall. With a command life (safety.command_hold_ticks tracker ticks)
the link sends the command's hold form after that: the same position targets and gains, no
feedforward torque, zero velocity target.

Each trial: the WBC walks launch/sim_wbc_velocity.yaml's timeline at the robot path's 100 Hz, in
lockstep MuJoCo, to a seeded time (drawn in the forward, turning and sideways segments); then the loop
stalls for S ms while physics runs on with the motors fed as a link would feed them; then the loop
resumes for SETTLE_S. Both ways of feeding meet the same robot at the same instant:
  as_is   the last command for the whole stall (a link without a command life);
  hold    the last command for its life, then its hold form (the robot link's default).
Figures from the simulator's ground truth: fell (the loop's fall monitor or a safety trip: an
over-speed trip damps the robot), the peak |joint speed| from the stall's start to the end of the
trial. The stall lengths: STALLS_S.

    g1 bench stall                                   # both variants, 8 seeded instants each (~15 min)
    g1 bench stall --only g1_23dof --trials 4 --seed 7 --json stall.json
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, cast

import numpy as np

if TYPE_CHECKING:
    from g1_control.sim.mujoco_backend import MujocoBackend

STALLS_S = (0.04, 0.08, 0.12, 0.2)
VARIANTS = ("g1_29dof", "g1_23dof")
TRACKER_HZ = 100.0
"""The WBC's rate on the robot path (launch/sim2sim_wbc.yaml, sim2sim_23dof.yaml)."""
DRAW_FROM_S = (4.0, 24.0)
"""The stall instants are drawn in this span of sim_wbc_velocity's timeline (walking forward, turning
left, walking sideways; the first second of walking is left out)."""
SETTLE_S = 1.5
"""How long the loop runs on after the stall (a fall or trip later than this is not counted)."""
MODES = ("as_is", "hold")


@dataclass
class StallTrial:
    variant: str
    stall_s: float
    at_s: float
    mode: str
    fell: bool
    trip: str
    peak_dq_radps: float
    min_pelvis_m: float
    wall_s: float


def _launch(variant: str):
    from g1_control.launch.schema import load_launch
    from g1_control.resources import launch_dir

    return load_launch(launch_dir() / "sim_wbc_velocity.yaml",
                       [f"rates.tracker_hz={TRACKER_HZ:g}", f"rates.lowlevel_hz={TRACKER_HZ:g}",
                        f"backend.expected_variant={variant}"])


def hold_form(command):
    """The link's hold form of `command` (MotorCommand.hold_form, as hardware/link_backend.py sends it)."""
    return command.hold_form()


def run_trial(variant: str, stall_s: float, at_s: float, mode: str) -> StallTrial:
    from g1_control.deploy.backends import command_ttl_s
    from g1_control.launch.builder import build_loop

    launch = _launch(variant)
    life_s = command_ttl_s(launch) if mode == "hold" else None
    t0 = time.perf_counter()
    loop = build_loop(launch)
    loop.reset()
    sim = cast("MujocoBackend", loop.backend)
    loop.run(at_s)
    dt = float(sim.model.opt.timestep)
    command = loop.motor_command.copy()
    held = hold_form(command)
    peak, low = 0.0, float(sim.data.qpos[2])
    stepped = 0
    for i in range(round(stall_s / dt)):
        late = life_s is not None and i * dt >= life_s - 1e-9
        sim.step_ticks(held if late else command, dt, 1)
        stepped += 1
        peak = max(peak, float(np.abs(sim.read_state().dq_radps).max()))
        low = min(low, float(sim.data.qpos[2]))
    for _ in range(round(SETTLE_S * TRACKER_HZ)):
        if loop.fell or loop.faulted:
            break
        loop.run(1.0 / TRACKER_HZ)
        peak = max(peak, float(np.abs(sim.read_state().dq_radps).max()))
        low = min(low, float(sim.data.qpos[2]))
    trip = next((str(e) for e in loop.events if e.trips and e.kind != "fall"), "")
    fell = bool(loop.fell or trip)
    sim.close()
    return StallTrial(variant, stall_s, round(at_s, 3), mode, fell, trip, round(peak, 2), round(low, 3),
                      time.perf_counter() - t0)


def stall_instants(seed: int, n: int) -> list[float]:
    rng = np.random.default_rng(seed)
    return sorted(float(t) for t in rng.uniform(*DRAW_FROM_S, size=n))


def summarise(trials: list[StallTrial]) -> list[dict]:
    out = []
    for variant in dict.fromkeys(t.variant for t in trials):
        for stall in dict.fromkeys(t.stall_s for t in trials):
            row: dict = {"variant": variant, "stall_ms": round(stall * 1000)}
            for mode in MODES:
                sub = [t for t in trials if (t.variant, t.stall_s, t.mode) == (variant, stall, mode)]
                if sub:
                    peaks = [t.peak_dq_radps for t in sub]
                    row[mode] = {"trials": len(sub), "fell": sum(t.fell for t in sub),
                                 "peak_dq_median": float(np.median(peaks)), "peak_dq_max": float(max(peaks))}
            out.append(row)
    return out


def main(args) -> int:
    variants = [v for v in VARIANTS if not args.only or any(v.startswith(p) for p in args.only.split(","))]
    if not variants:
        raise SystemExit(f"--only {args.only}: no variant starts with it (variants: {', '.join(VARIANTS)})")
    n = args.trials if args.trials is not None else 8
    instants = stall_instants(args.seed, n)
    from g1_control.deploy.backends import command_ttl_s

    life_ms = (command_ttl_s(_launch(variants[0])) or 0.0) * 1000
    print(f"g1 bench stall: the WBC at {TRACKER_HZ:g} Hz walking sim_wbc_velocity's timeline; the loop stalls at "
          f"{n} instants (seed {args.seed}: {', '.join(f'{t:.2f}' for t in instants)} s); as_is: the last command "
          f"through the stall; hold: its hold form after its {life_ms:.0f} ms life; fell = a fall or a safety trip "
          f"within {SETTLE_S:g} s (ground truth)", flush=True)
    trials: list[StallTrial] = []
    total = len(variants) * len(STALLS_S) * n * len(MODES)
    for variant in variants:
        for stall in STALLS_S:
            for at in instants:
                for mode in MODES:
                    trials.append(run_trial(variant, stall, at, mode))
                    t = trials[-1]
                    print(f"  [{len(trials):3d}/{total}] {variant} stall {stall * 1000:3.0f} ms at {at:6.2f} s {mode:5s}: "
                          f"{'FELL' if t.fell else 'up  '} peak |dq| {t.peak_dq_radps:5.1f} rad/s"
                          + (f"  ({t.trip})" if t.trip else ""), flush=True)
    rows = summarise(trials)
    print(f"\n{'variant':<10} {'stall':>6}   {'as_is: fell':>12} {'peak |dq| med/max':>18}   "
          f"{'hold: fell':>11} {'peak |dq| med/max':>18}")
    for row in rows:
        cells = [f"{row[m]['fell']:>5d}/{row[m]['trials']:<4d}  {row[m]['peak_dq_median']:7.1f} /{row[m]['peak_dq_max']:5.1f}"
                 for m in MODES]
        print(f"{row['variant']:<10} {row['stall_ms']:>4d}ms   {cells[0]:>33}   {cells[1]:>31}")
    fell = {m: sum(t.fell for t in trials if t.mode == m) for m in MODES}
    runs = len(trials) // len(MODES)
    print(f"all stalls: as_is fell {fell['as_is']}/{runs}, hold fell {fell['hold']}/{runs}")
    if args.json:
        Path(args.json).write_text(json.dumps({"seed": args.seed, "instants_s": instants, "tracker_hz": TRACKER_HZ,
                                               "life_ms": life_ms, "rows": rows,
                                               "trials": [asdict(t) for t in trials]}, indent=2))
    return 0
