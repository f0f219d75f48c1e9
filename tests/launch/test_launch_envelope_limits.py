"""The loop builder's command limits come from the tracker's measured envelope, not the policy's
trained range: stick scaling and the generator ask only for what the layer delivers."""

from g1_control.launch.builder import build_loop, command_limits, make_tracker
from g1_control.launch.schema import LaunchFile, Segment


def _launch(envelope: bool) -> LaunchFile:
    launch = LaunchFile(name="limits")
    launch.input.timeline = [Segment(0.1, vx_mps=0.9)]
    launch.tracker.envelope_limits = envelope
    launch.output.video, launch.output.plot, launch.viewer = False, False, False
    return launch


def test_limits_are_the_envelope_within_the_launch_limits():
    launch = _launch(True)
    tracker = make_tracker(launch)
    env = tracker.spec.envelope
    limits = command_limits(launch, tracker.command_limits)
    assert limits.vx_mps == env.vx_mps and limits.vy_mps == env.vy_mps
    assert limits.vx_mps[1] < 0.9  # the trained range (1.0) would have passed 0.9 on
    trained = command_limits(_launch(False), make_tracker(_launch(False)).command_limits)
    assert trained.vx_mps == (-1.0, 1.0) and trained.vy_mps == (-0.6, 0.6)  # launch limits cap vy at 0.6


def test_the_velocity_generator_clamps_to_the_envelope():
    loop = build_loop(_launch(True))
    loop.reset()
    loop.run(0.1)
    assert loop.log.arrays()["command"][-1][0] == 0.9  # the operator asked 0.9 ...
    assert loop.generator.limits.vx_mps[1] == loop.tracker.spec.envelope.vx_mps[1]  # ... the plan gets the envelope
