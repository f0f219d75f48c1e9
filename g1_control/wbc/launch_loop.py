"""The control loop a launch file with `tracker.type: wbc` describes.

The WBC needs whole-body references with root poses and a contact schedule; the velocity-command
generator the other launch files use supplies neither, so a WBC launch names one of the scripted
references (g1_control.wbc.references) in `tracker.wbc_reference`. The input timeline still runs
(and is logged) but does not steer the reference. The tracker must run at >= 200 Hz.

    tracker: {type: wbc, wbc_reference: walk}
    rates: {lowlevel_hz: 500, tracker_hz: 250}
"""

from __future__ import annotations

from g1_control.errors import LaunchFileError

MIN_TRACKER_HZ = 200.0


def build_wbc_loop(launch, segments):
    from g1_control.launch.runner import safety_config
    from g1_control.loop.control_loop import ControlLoop
    from g1_control.safety import SafetyFilter
    from g1_control.sim.mujoco_backend import MujocoBackend, MujocoConfig
    from g1_control.teleop.scripted import ScriptedInput
    from g1_control.wbc.references import (
        REFERENCES,
        TrajectoryGenerator,
        TrajectoryRetargeter,
        build_reference,
    )
    from g1_control.wbc.tracker import WbcConfig, WholeBodyTracker

    r = launch.rates
    if r.tracker_hz < MIN_TRACKER_HZ:
        raise LaunchFileError(f"rates.tracker_hz: {r.tracker_hz} Hz is too slow for tracker.type wbc "
                              f"(the whole-body controller needs >= {MIN_TRACKER_HZ:.0f} Hz, e.g. 250)")
    name = launch.tracker.wbc_reference
    if name not in REFERENCES:
        raise LaunchFileError(f"tracker.wbc_reference: unknown reference '{name}'; known: {', '.join(REFERENCES)}")
    trajectory = build_reference(name)
    backend = MujocoBackend(MujocoConfig(physics_dt_s=launch.backend.physics_dt_s, lockstep=True))
    loop_box: list[ControlLoop] = []
    device = ScriptedInput(segments, clock=lambda: loop_box[0].time_s)
    loop = ControlLoop(
        backend, device, TrajectoryGenerator(trajectory), TrajectoryRetargeter(trajectory),
        WholeBodyTracker(WbcConfig(rate_hz=r.tracker_hz)),
        r,
        wallclock=launch.backend.mode == "wallclock", safety=SafetyFilter(safety_config(launch)),
        log_capacity=int(launch.total_duration_s * r.tracker_hz) + 2,
    )
    loop_box.append(loop)
    return loop
