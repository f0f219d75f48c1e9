"""The tracking layer: hand-over by the reference's phase, the policy decimated to its rate, and a
blend whose driver torque is exactly the weighted sum of the two controllers' torques."""

import numpy as np
import pytest

from g1_control.robot import g1
from g1_control.trackers.layer import POLICY, WBC, TrackingLayer, blend_commands
from g1_control.types import PHASE_LOCOMOTION, PHASE_WHOLE_BODY, JointReference, MotorCommand, RobotState


def _random_command(rng):
    n = g1.NUM_JOINTS
    return MotorCommand(q_rad=rng.normal(size=n), dq_radps=rng.normal(size=n), kp=rng.uniform(5, 50, n),
                        kd=rng.uniform(0.5, 5, n), tau_nm=rng.normal(size=n))


def _torque(cmd, q, dq):
    return cmd.tau_nm + cmd.kp * (cmd.q_rad - q) + cmd.kd * (cmd.dq_radps - dq)


def test_the_blend_is_torque_exact():
    rng = np.random.default_rng(0)
    a, b = _random_command(rng), _random_command(rng)
    q, dq = rng.normal(size=g1.NUM_JOINTS), rng.normal(size=g1.NUM_JOINTS)
    for w in (0.0, 0.3, 0.7, 1.0):
        out = blend_commands(a, b, w, MotorCommand())
        np.testing.assert_allclose(_torque(out, q, dq), (1 - w) * _torque(a, q, dq) + w * _torque(b, q, dq), atol=1e-9)


class _Fake:
    """A controller that returns a constant command and counts its calls."""

    def __init__(self, tau, rate_hz=50.0):
        self.calls, self.resets = 0, 0
        self.cmd = MotorCommand(kp=np.ones(g1.NUM_JOINTS), kd=np.ones(g1.NUM_JOINTS),
                                tau_nm=np.full(g1.NUM_JOINTS, tau))
        self.spec = type("Spec", (), {"rate_hz": rate_hz})()

    def act(self, reference, state):
        self.calls += 1
        return self.cmd

    def reset(self, state=None):
        self.resets += 1

    def observe(self, estimate):
        pass


def test_hand_over_by_phase_with_a_blend_and_the_policy_at_its_own_rate():
    policy, wbc = _Fake(1.0), _Fake(3.0)
    layer = TrackingLayer(policy, wbc, rate_hz=100.0, blend_s=0.3)
    ref, state = JointReference(), RobotState()
    taus = []
    for k in range(200):
        state.t_s = k * 0.01
        ref.phase = PHASE_WHOLE_BODY if 50 <= k < 150 else PHASE_LOCOMOTION
        taus.append(layer.act(ref, state).tau_nm[0])
    taus = np.array(taus)
    assert taus[:50] == pytest.approx(1.0) and taus[90:150] == pytest.approx(3.0) and taus[-10:] == pytest.approx(1.0)
    blend = taus[50:80]
    assert np.all(np.diff(blend) >= -1e-12) and 1.0 < blend[10] < 3.0  # a smooth ramp, not a step
    assert np.abs(np.diff(taus)).max() < 0.25  # largest change per tick: 2 / 30 ticks * quintic peak 1.875
    assert [s for _, s in layer.switches] == [WBC, POLICY]
    # the WBC runs only while it is wanted (its 100 ticks and the 30-tick blend out); the policy at 50 Hz
    assert wbc.calls == 100 + 30
    assert policy.calls < 0.5 * (50 + 30 + 50) + 5


@pytest.mark.parametrize("gait", [True, False])
def test_walking_with_a_held_load_goes_to_the_wbc_where_it_has_a_gait(gait):
    """A locomotion reference carrying a held object's forces on the hands is walked by the WBC's own
    gait (the load in its dynamics); without forces, or with a WBC that has no gait, by the policy."""
    policy, wbc = _Fake(1.0), _Fake(3.0)
    wbc.gait = object() if gait else None
    layer = TrackingLayer(policy, wbc, rate_hz=100.0, blend_s=0.0)
    assert layer.walks_holding() is gait
    ref, state = JointReference(), RobotState()
    ref.phase = PHASE_LOCOMOTION
    taus = []
    for k in range(60):
        state.t_s = k * 0.01
        ref.hand_forces_w_n[:] = 0.0
        if 20 <= k < 40:
            ref.hand_forces_w_n[:, 2] = -9.81  # a 2 kg box, half in each hand
        taus.append(layer.act(ref, state).tau_nm[0])
    held = 3.0 if gait else 1.0
    assert taus[:20] == pytest.approx([1.0] * 20) and taus[20:40] == pytest.approx([held] * 20)
    assert taus[40:] == pytest.approx([1.0] * 20)
    assert [s for _, s in layer.switches] == ([WBC, POLICY] if gait else [])


@pytest.mark.parametrize("hz", [100, 250])
def test_the_launch_builder_gives_the_layers_wbc_a_gait_for_carries_at_250_hz_only(hz):
    """At rates.tracker_hz >= 250 the layer walks a held box in its WBC's gait (its goals carry so:
    GoalConfig.walk_while_holding); slower, the WBC has no gait and carries are whole-body steps."""
    from g1_control.launch.builder import make_generator, make_tracker
    from g1_control.launch.schema import load_launch
    from tests.paths import LAUNCH_DIR

    launch = load_launch(LAUNCH_DIR / "sim_box.yaml", [f"rates.tracker_hz={hz}"])
    tracker = make_tracker(launch)
    assert isinstance(tracker, TrackingLayer)
    assert tracker.walks_holding() is (hz >= 250)
    assert (tracker.wbc.gait is not None) is (hz >= 250)
    assert make_generator(launch, None, tracker).config.walk_while_holding is (hz >= 250)
