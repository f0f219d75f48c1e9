"""`g1 bench robust`: the walking controllers on randomised robots (what the real G1 will differ in
from the model: link masses +-10 %, CoM offsets up to 2 cm, motor strength 85-100 %, 5-15 ms
command latency, foot friction 0.5-1.2; g1_control/sim/randomize.py), in one run, one table.

For each of --draws seeded draws (seeds --seed, --seed+1, ...), every controller meets the same
robot:
  wbc/forward_0.6   the model-based whole-body controller (tracker.type wbc, 250 Hz): 1 s standing,
                    then 0.6 m/s forward for --seconds;
  wbc23/forward_0.6 the same on the 23-DoF G1, the base model (backend.expected_variant g1_23dof: the
                    simulator builds it and the controller models it; `--only wbc` runs both rows);
  ppo/forward_0.6   holosoma's ppo walking policy (tracker.type policy, 50 Hz), the same timeline;
  layer/step        launch/sim_step.yaml (the walking policy walks to a 0.15 m platform, the WBC steps
                    up, stands, steps down; tracker.type layer): done when both feet are on the
                    platform at the end of step_up and on the floor at the end of step_down.
Figures from the simulator's ground truth: achieved (vx, vy, wz) in the heading frame over whole gait
cycles after 3 s of walking (bench_locomotion.steady_velocity), fell (the loop's fall monitor),
lowest pelvis height. The nominal robot's rows run first in the same run, as the baseline. The
summary names each draw a row fell on, with its foot friction and command latency.
Exits 1 when any row fell (or a step was not completed).

    g1 bench robust                               # 10 draws, forward rows + step (~30 min)
    g1 bench robust --only wbc,ppo --seconds 10   # forward rows only
    g1 bench robust --draws 3 --json robust.json
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from g1_control.sim.randomize import RandomizeConfig, draw

if TYPE_CHECKING:
    from g1_control.robot.g1 import VariantName

FORWARD_MPS = 0.6
CONTROLLERS = ("wbc", "wbc23", "ppo")
ROW_KINDS: dict[str, tuple[str, VariantName | None]] = {"wbc": ("wbc", None), "wbc23": ("wbc", "g1_23dof"),
                                                        "ppo": ("ppo", None)}
"""row name -> (bench_locomotion controller, robot variant; None: the 29-DoF G1)."""
STEP_LAUNCH = "sim_step.yaml"


@dataclass
class RobustRow:
    controller: str
    case: str
    seed: int | None
    """The draw's seed; None: the nominal robot."""
    draw: str = ""
    command_vx_mps: float = math.nan
    achieved: list[float] = field(default_factory=lambda: [math.nan] * 3)
    fell: bool = False
    fall: str = ""
    min_pelvis_m: float = math.nan
    step_done: bool | None = None
    """layer/step only: both feet on the platform after step_up and on the floor after step_down."""
    goals: list[str] = field(default_factory=list)
    sim_s: float = 0.0
    wall_s: float = 0.0

    @property
    def failed(self) -> bool:
        return self.fell or self.step_done is False


def _randomize(seed: int | None) -> RandomizeConfig | None:
    return None if seed is None else RandomizeConfig(seed=seed)


def draw_friction_latency(seed: int) -> tuple[float, float]:
    """(foot friction, command latency s) of draw `seed` (drawn before anything that depends on the
    robot's bodies, so every variant's draw has them)."""
    d = draw(RandomizeConfig(seed=seed), (), 0)
    return d.foot_friction, d.latency_s


def forward_row(name: str, seed: int | None, walk_s: float) -> RobustRow:
    from g1_control.tools.bench_locomotion import Case, run_case

    controller, variant = ROW_KINDS[name]
    case = Case(f"forward_{FORWARD_MPS}", (FORWARD_MPS, 0.0, 0.0))
    locomotion = run_case(controller, case, walk_s, randomize=_randomize(seed), variant=variant)
    row = RobustRow(name, case.name, seed, draw=locomotion.backend, command_vx_mps=FORWARD_MPS)
    row.achieved, row.fell, row.fall = locomotion.achieved, locomotion.fell, locomotion.fall
    row.min_pelvis_m, row.sim_s, row.wall_s = locomotion.min_pelvis_m, locomotion.sim_s, locomotion.wall_s
    return row


def step_row(seed: int | None) -> RobustRow:
    from g1_control.launch.builder import build_loop
    from g1_control.launch.schema import load_launch
    from g1_control.report.outcomes import GoalWatcher
    from g1_control.resources import launch_dir

    launch = load_launch(launch_dir() / STEP_LAUNCH)
    launch.backend.randomize = _randomize(seed)
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    loop = build_loop(launch)
    loop.reset()
    row = RobustRow("layer", "step", seed, draw=loop.chain["backend"])
    watcher = GoalWatcher(loop)
    t0 = time.perf_counter()
    try:
        n = round(launch.total_duration_s * loop.rates.lowlevel_hz)
        loop.scheduler.run(n, stop=lambda: loop.fell, progress=watcher.tick)
    finally:
        row.wall_s = time.perf_counter() - t0
        loop.backend.close()
    row.sim_s = float(loop.time_s)
    row.fell, row.fall = loop.fell, str(loop.fall) if loop.fall else ""
    row.min_pelvis_m = float(loop.log.arrays()["base_pos_m"][:, 2].min())
    outcomes = watcher.outcomes()
    up = [o for o in outcomes if o["kind"] == "step_up"]
    down = [o for o in outcomes if o["kind"] == "step_down"]
    row.step_done = bool(up and down and up[0].get("on_top_at_end") and down[0].get("on_floor_at_end")
                         and not row.fell)
    row.goals = [f"{o['kind']} {o['status']}" for o in outcomes]
    return row


HEADER = (f"{'controller/case':<20} {'draw':>7} {'command vx':>10} {'achieved (vx vy wz)':>25} {'vx %':>6} "
          f"{'fell':>5} {'min z m':>7} {'step':>5} {'wall s':>6}")


def format_row(row: RobustRow) -> str:
    got = "({:+.3f} {:+.3f} {:+.3f})".format(*row.achieved) if np.isfinite(row.achieved).all() else "-"
    pct = f"{100 * row.achieved[0] / row.command_vx_mps:6.1f}" if np.isfinite(row.achieved[0]) else f"{'-':>6}"
    cmd = f"{row.command_vx_mps:10.2f}" if np.isfinite(row.command_vx_mps) else f"{'-':>10}"
    step = "-" if row.step_done is None else ("done" if row.step_done else "NOT")
    seed = "nominal" if row.seed is None else f"s{row.seed}"
    return (f"{row.controller + '/' + row.case:<20} {seed:>7} {cmd} {got:>25} {pct} "
            f"{'FELL' if row.fell else 'no':>5} {row.min_pelvis_m:7.3f} {step:>5} {row.wall_s:6.0f}")


def run_rows(seeds: list[int | None], walk_s: float, only: list[str] | None = None, echo=print) -> list[RobustRow]:
    """Per seed (None: the nominal robot), each controller's forward row, then the step row."""
    wanted = [c for c in (*CONTROLLERS, "step") if not only or any(c.startswith(p) for p in only)]
    rows: list[RobustRow] = []
    for seed in seeds:
        for name in wanted:
            row = step_row(seed) if name == "step" else forward_row(name, seed, walk_s)
            rows.append(row)
            echo(format_row(row))
    return rows


def summary(rows: list[RobustRow]) -> list[str]:
    out = []
    for name in (*CONTROLLERS, "layer"):
        randomized = [r for r in rows if r.controller == name and r.seed is not None]
        if not randomized:
            continue
        falls = sum(r.fell for r in randomized)
        line = f"  {name}: {falls} falls in {len(randomized)} randomised draws"
        vx = np.array([r.achieved[0] for r in randomized if np.isfinite(r.achieved[0])])
        if len(vx):
            line += (f"; achieved vx {vx.mean():.3f} m/s mean ({vx.min():.3f}..{vx.max():.3f}) for "
                     f"{FORWARD_MPS} commanded = {100 * vx.mean() / FORWARD_MPS:.0f} %")
        nominal = [r for r in rows if r.controller == name and r.seed is None and np.isfinite(r.achieved[0])]
        if nominal:
            line += f"; nominal robot {nominal[0].achieved[0]:.3f} m/s"
        steps = [r for r in randomized if r.step_done is not None]
        if steps:
            line += f"; step up and down done {sum(bool(r.step_done) for r in steps)}/{len(steps)}"
        failed = [r.seed for r in randomized if r.failed and r.seed is not None]
        if failed:
            line += "; failed on " + ", ".join(
                f"s{seed} (friction {f:.2f}, latency {1000 * lat:.1f} ms)"
                for seed in failed for f, lat in [draw_friction_latency(seed)])
        out.append(line)
    return out


def main(args) -> int:
    only = [p for p in (args.only or "").split(",") if p] or None
    walk_s = float(args.seconds)
    draws = int(args.draws)
    seeds: list[int | None] = [None, *range(args.seed, args.seed + draws)]
    defaults = RandomizeConfig()
    print(f"g1 bench robust: {draws} seeded draws (seeds {args.seed}..{args.seed + draws - 1}) of link mass "
          f"x{defaults.mass_scale[0]:g}..{defaults.mass_scale[1]:g}, CoM offset <= {100 * defaults.com_offset_m:g} cm, "
          f"motor strength {defaults.motor_strength[0]:g}..{defaults.motor_strength[1]:g}, latency "
          f"{1000 * defaults.latency_s[0]:g}..{1000 * defaults.latency_s[1]:g} ms, foot friction "
          f"{defaults.foot_friction[0]:g}..{defaults.foot_friction[1]:g}; nominal robot first. Forward {FORWARD_MPS} m/s for "
          f"{walk_s:.0f} s after 1 s standing; achieved = ground-truth mean over whole gait cycles after 3 s")
    from g1_control.tools.environment import describe, environment

    env = environment()
    print(describe(env))
    print(HEADER, flush=True)
    rows = run_rows(seeds, walk_s, only, echo=lambda line: print(line, flush=True))
    for seed in seeds[1:]:
        draw = next((r.draw for r in rows if r.seed == seed), "")
        print(f"  draw s{seed}: {draw.split('(', 1)[-1].rstrip(')')}")
    for line in summary(rows):
        print(line)
    failed = [f"{r.controller}/{r.case}@{'nominal' if r.seed is None else f's{r.seed}'}" for r in rows if r.failed]
    if failed:
        print(f"FELL or step not done: {', '.join(failed)}")
    if args.json:
        Path(args.json).write_text(json.dumps({"walk_s": walk_s, "forward_mps": FORWARD_MPS, "draws": draws, "environment": env,
                                               "randomize": asdict(defaults),
                                               "rows": [asdict(r) for r in rows]}, indent=2))
    return 1 if failed else 0
