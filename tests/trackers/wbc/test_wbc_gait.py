"""The velocity gait's pieces without physics: DCM offsets that repeat step after step, swing
segments that arrive, commands kept within the step limits, named configuration errors."""

import dataclasses
import itertools
import math

import numpy as np
import pytest

from g1_control.errors import WbcConfigError
from g1_control.trackers.wbc.gait import (
    LEFT,
    RIGHT,
    GaitConfig,
    VelocityGait,
    _min_jerk,
    max_width_for,
    nominal_dcm_offset,
    nominal_step,
    step_duration_for,
    step_load,
    support_times_for,
)

OMEGA = math.sqrt(9.81 / 0.66)


@pytest.mark.parametrize("v", [(0.0, 0.0), (0.5, 0.0), (-0.4, 0.1), (0.3, -0.2)])
def test_nominal_offsets_repeat_under_the_pendulum(v):
    """Starting a step at the nominal offset with the CoP on the stance foot, the DCM reaches the
    next foot's nominal offset at its touchdown: b' = b E - d."""
    cfg = GaitConfig()
    E = math.exp(OMEGA * cfg.step_s)
    v = np.array(v)
    for stance in (LEFT, RIGHT):
        b = nominal_dcm_offset(cfg, stance, v, OMEGA)
        d = nominal_step(cfg, 1 - stance, v)
        np.testing.assert_allclose(b * E - d, nominal_dcm_offset(cfg, 1 - stance, v, OMEGA), atol=1e-12)


@pytest.mark.parametrize("v, wz", [((0.6, 0.0), 0.5), ((0.0, 0.0), 1.2), ((0.3, 0.1), -0.8)])
def test_nominal_offsets_repeat_while_turning(v, wz):
    """Turning, each step's frame is turned by wz T from the last: from the nominal offset with the
    CoP on the stance foot the DCM reaches, at touchdown, the next foot's offset in the turned frame,
    the step following the arc (the centre's chord turned by half the turn, the landing foot beside
    the turned centre line). Planned as if straight the DCM ran out of the curve (issue 23)."""
    cfg = GaitConfig()
    T = cfg.step_s
    E = math.exp(OMEGA * T)
    v = np.array(v)

    def rot(a):
        return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])

    for stance in (LEFT, RIGHT):
        f = 1 - stance
        b = nominal_dcm_offset(cfg, stance, v, OMEGA, wz)
        side = 1.0 if f == LEFT else -1.0
        half_w = np.array([0.0, 0.5 * side * cfg.step_width_m])
        d = (nominal_step(cfg, f, v) + (rot(0.5 * wz * T) - np.eye(2)) @ (v * T)
             + (rot(wz * T) - np.eye(2)) @ half_w)
        np.testing.assert_allclose(b * E - d, rot(wz * T) @ nominal_dcm_offset(cfg, f, v, OMEGA, wz), atol=1e-12)
    # no turn: the straight offsets
    np.testing.assert_allclose(nominal_dcm_offset(cfg, LEFT, v, OMEGA, 0.0), nominal_dcm_offset(cfg, LEFT, v, OMEGA))


def test_steps_average_the_commanded_velocity():
    cfg = GaitConfig()
    v = np.array([0.4, 0.15])
    pair = nominal_step(cfg, LEFT, v) + nominal_step(cfg, RIGHT, v)
    np.testing.assert_allclose(pair / (2 * cfg.step_s), v)
    # the foot on the side of the motion steps out, the other closes to the nominal width
    assert nominal_step(cfg, LEFT, v)[1] > cfg.step_width_m
    assert nominal_step(cfg, RIGHT, v)[1] == pytest.approx(-cfg.step_width_m)


def test_minimum_jerk_segment_arrives_at_rest():
    x, v, a = _min_jerk(0.1, 0.5, -2.0, 0.4, 0.3, 0.3)
    assert (x, v, a) == pytest.approx((0.4, 0.0, 0.0), abs=1e-9)
    x0, v0, a0 = _min_jerk(0.1, 0.5, -2.0, 0.4, 0.3, 0.0)
    assert (x0, v0, a0) == pytest.approx((0.1, 0.5, -2.0))


def test_commands_beyond_the_step_limits_are_walked_at_the_limit():
    gait = VelocityGait()
    cfg = gait.config
    T, m = cfg.step_s, cfg.speed_margin
    # walking fast the steps come quicker (the fast double support) and sideways wider: vx and vy
    # reach further than the slow cadence's limits, exactly as far as the fast cadence's
    T_fast = cfg.single_support_s + cfg.fast_double_support_s
    assert T_fast < T and cfg.fast_max_width_m > cfg.max_width_m
    limits = (m * cfg.max_forward_m / T_fast, m * (cfg.fast_max_width_m - cfg.step_width_m) / (2 * T_fast),
              m * cfg.max_relative_yaw_rad / T)
    for axis, limit in enumerate(limits):
        command = np.zeros(3)
        command[axis] = -5.0 if axis == 1 else 5.0
        out = gait.feasible(command)
        assert abs(out[axis]) == pytest.approx(limit) and np.sign(out[axis]) == np.sign(command[axis])
        assert np.count_nonzero(out) == 1
        assert step_load(cfg, out, m) == pytest.approx(1.0)
    assert gait.feasible(np.array([-5.0, 0.0, 0.0]))[0] == pytest.approx(-m * cfg.max_backward_m / T_fast)
    np.testing.assert_allclose(gait.feasible(np.array([0.3, 0.05, 0.2])), [0.3, 0.05, 0.2])
    # combined axes share the reach: their fractions of the limits add up to one, direction kept
    # (slow: the fractions of the slow cadence's limits, as before the cadence rose with speed)
    out = gait.feasible(np.array([0.8, 0.2, -1.0]))
    slow = (m * cfg.max_forward_m / T, m * (cfg.max_width_m - cfg.step_width_m) / (2 * T), limits[2])
    assert sum(abs(out[k]) / slow[k] for k in range(3)) == pytest.approx(1.0)
    np.testing.assert_allclose(out / np.linalg.norm(out), np.array([0.8, 0.2, -1.0]) / np.linalg.norm([0.8, 0.2, -1.0]))
    # the speed correction's limit at a given cadence (fixed step duration) and margin
    out = gait.feasible(np.array([5.0, 0.0, 0.0]), margin=1.0, cadence_of=np.zeros(2))
    assert out[0] == pytest.approx(cfg.max_forward_m / T)


def test_steps_come_quicker_walking_fast_and_not_walking_slowly():
    """The cadence rises with the step reach: slow walking keeps the configured timing; fast
    walking shortens the double support (down to the fast one), never the swing."""
    cfg = GaitConfig()
    for slow in ((0.0, 0.0), (0.5, 0.0), (-0.4, 0.0), (0.2, 0.1)):
        assert support_times_for(cfg, np.array(slow)) == (cfg.single_support_s, cfg.double_support_s)
    durations = [step_duration_for(cfg, np.array([vx, 0.0])) for vx in (0.85, 0.9, 0.95, 1.0)]
    assert all(a > b for a, b in itertools.pairwise(durations))
    assert support_times_for(cfg, np.array([0.0, 0.4])) == pytest.approx((cfg.single_support_s,
                                                                           cfg.fast_double_support_s))
    assert step_duration_for(cfg, np.array([1.5, 0.0])) == pytest.approx(cfg.single_support_s + cfg.fast_double_support_s)
    # the stance may widen for fast sideways steps only
    assert max_width_for(cfg, np.array([0.0, 0.2])) == cfg.max_width_m
    assert max_width_for(cfg, np.array([1.5, 0.0])) == cfg.max_width_m
    assert max_width_for(cfg, np.array([0.0, 0.4])) == pytest.approx(cfg.fast_max_width_m)


def test_the_gait_walks_the_fast_cadence_once_the_command_is_fast():
    """Through the state machine (no physics): the steps' duration follows the walked command."""
    gait = VelocityGait()
    soles, yaws = _feet()
    command = np.array([1.0, 0.0, 0.0])
    durations = []
    for k in range(1500):
        gait.schedule(0.004 * k, command, soles, yaws, np.zeros(2))
        if gait.mode == "walk":
            durations.append(gait.step_T)
    assert durations[0] == pytest.approx(gait.config.step_s)  # from standing: the slow cadence
    assert durations[-1] == pytest.approx(step_duration_for(gait.config, command[:2]))
    assert durations[-1] < gait.config.step_s - 0.02


def _feet():
    return np.array([[0.0, 0.11, 0.0], [0.0, -0.11, 0.0]]), np.zeros(2)


def test_standing_gait_keeps_both_feet_down_and_starts_on_a_command():
    gait = VelocityGait()
    soles, yaws = _feet()
    for k in range(50):
        contacts = gait.schedule(0.004 * k, np.zeros(3), soles, yaws, np.zeros(2))
        assert contacts.all() and gait.mode == "stand"
    t = 0.2
    while gait.mode != "walk":
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        assert t < 0.2 + gait.config.start_s + 0.01
    # single support of the swing foot (forward and straight: the right foot leads)
    contacts = gait.schedule(t + 0.004, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    assert contacts.tolist() == [True, False]


def test_landing_moves_with_the_measured_dcm():
    """Step adjustment: a DCM pushed forward sends the swing foot further forward."""
    landings = []
    for push in (0.0, 0.12):
        gait = VelocityGait()
        soles, yaws = _feet()
        t = 0.0
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        while gait.mode != "walk" or gait.targets.contacts.all():  # into the single support
            t += 0.004
            gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        dcm = soles[LEFT, :2] + np.array([push, -0.03])
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        landings.append(out.landing_m[0])
    # the CoP takes what the sole allows (5 cm) of the error; the step takes the rest, grown by
    # the pendulum until touchdown
    assert landings[1] > landings[0] + 0.2


def _into_single_support(gait, soles, yaws):
    t = 0.0
    gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    while gait.mode != "walk" or gait.targets.contacts.all():
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    return t


def test_a_dcm_far_off_its_plan_makes_the_step_a_recovery_step_until_it_lands():
    """A push (the DCM GaitConfig.recovery_dcm_error_m off its plan) makes the step under way a
    recovery step (the tracker then holds its swing foot harder), for the rest of that step only."""
    soles, yaws = _feet()
    gait = VelocityGait()
    t = _into_single_support(gait, soles, yaws)
    cfg = gait.config
    # late in the swing, where the landing point is frozen: the DCM's error alone marks the step
    while t - gait._t0 < cfg.double_support_s + (cfg.freeze_landing_after + 0.05) * cfg.single_support_s:
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    near = soles[LEFT, :2] + np.array([0.05, -0.03])
    on_plan = gait.update(t, 0.004, soles, yaws, near, OMEGA)
    assert on_plan.dcm_error_m < cfg.recovery_dcm_error_m and not on_plan.recovery
    # pushed sideways: the error grows by more than the threshold (whatever the plan is exactly)
    pushed = near + np.array([0.0, -(cfg.recovery_dcm_error_m + on_plan.dcm_error_m + 0.02)])
    out = gait.update(t + 0.004, 0.004, soles, yaws, pushed, OMEGA)
    assert out.dcm_error_m > cfg.recovery_dcm_error_m and out.recovery
    # back near the plan, the step stays a recovery step (latched) ...
    assert gait.update(t + 0.008, 0.004, soles, yaws, near, OMEGA).recovery
    # ... until the next step
    first = gait.steps
    while gait.steps == first or gait.targets.contacts.all():
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    stance = soles[gait.stance, :2]
    later = gait.update(t, 0.004, soles, yaws, stance + np.array([0.0, 0.03 * (1 if gait.stance == RIGHT else -1)]), OMEGA)
    assert later.swing_foot >= 0 and not later.recovery


@pytest.mark.parametrize("widest", [0.6, 0.45])
def test_a_recovery_step_lands_as_wide_as_recovery_max_width(widest):
    """Pushed hard sideways towards the swing foot's side, the recovery step lands at
    GaitConfig.recovery_max_width_m from the stance foot (a plain step's limit is max_width_m, 0.45)."""
    soles, yaws = _feet()
    gait = VelocityGait(GaitConfig(recovery_max_width_m=widest))
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT
    out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.05, -1.0]), OMEGA)
    assert out.recovery and out.swing_foot == RIGHT
    assert soles[LEFT, 1] - out.landing_m[1] == pytest.approx(widest, abs=1e-9)


def _to_touchdown(gait, t, soles, yaws):
    """Schedule ticks until the swing foot under way lands; the time of the touchdown tick."""
    first = gait.steps
    while gait.steps == first:
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    return t


@pytest.mark.parametrize("steps", [1, 0])
def test_the_step_after_a_pushed_step_is_held_like_it(steps):
    """GaitConfig.after_push_steps: the step after a pushed step (double support included) is an
    after-push step (the tracker keeps the CoM lowered); the step after that is a plain step again.
    (push_detect_m 0: on the DCM's error alone, whether or not a push was told.)"""
    soles, yaws = _feet()
    gait = VelocityGait(GaitConfig(after_push_steps=steps, push_detect_m=0.0))
    t = _into_single_support(gait, soles, yaws)
    out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.05, -1.0]), OMEGA)
    assert out.pushed and not out.after_push
    t = _to_touchdown(gait, t, soles, yaws)
    assert gait.stance == RIGHT and gait.targets.contacts.all()  # the next step's double support
    out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.05, 0.03]), OMEGA)
    assert out.after_push == bool(steps) and not out.pushed
    t = _to_touchdown(gait, t, soles, yaws)
    out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2], OMEGA)
    assert not out.after_push and not out.pushed


@pytest.mark.parametrize("threshold", [0.2, math.inf])
def test_a_dcm_far_off_its_plan_in_the_double_support_lifts_the_swing_foot_at_once(threshold):
    """GaitConfig.early_lift_dcm_error_m: pushed in a step's double support, the swing foot lifts once
    fast_double_support_s of it has passed (the load moves onto the other foot first); the single
    support keeps its length, so the step lands that much sooner."""
    soles, yaws = _feet()
    gait = VelocityGait(GaitConfig(early_lift_dcm_error_m=threshold, push_detect_m=0.0))
    cfg = gait.config
    t = _to_touchdown(gait, _into_single_support(gait, soles, yaws), soles, yaws)
    step_before = gait.step_T
    # on its plan, the double support goes on
    out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.05, 0.03]), OMEGA)
    assert out.dcm_error_m < 0.2
    assert gait.schedule(t + 0.004, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2)).all()
    lifted_at = None
    while t - gait._t0 < cfg.double_support_s - 0.008:
        t += 0.004
        out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.4, 0.0]), OMEGA)
        assert out.dcm_error_m > 0.2
        if not gait.schedule(t + 0.004, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2)).all():
            lifted_at = t + 0.004 - gait._t0
            break
    if math.isfinite(threshold):
        assert lifted_at is not None and gait.targets.contacts.tolist() == [False, True]
        assert cfg.fast_double_support_s <= lifted_at < cfg.fast_double_support_s + 0.005
        assert gait.step_T == pytest.approx(step_before - (cfg.double_support_s - lifted_at))
    else:
        assert lifted_at is None and gait.step_T == step_before


def _pendulum_walk(gait, seconds, push=None, command=(0.3, 0.0, 0.0)):
    """Ticks of a walk where the DCM moves as the pendulum does under the CoP the gait asks (the feet
    land where the gait sends them); push: (from s, to s, DCM velocity m/s) added on top, as a force
    on the body does. Per tick: (t, targets' push_drift_m, push_seen, pushed, after_push)."""
    soles, yaws = _feet()
    t, dt, xi = 0.0, 0.004, np.zeros(2)
    rows = []
    while t < seconds:
        c = np.array(command(t) if callable(command) else command)
        gait.schedule(t, c, soles, yaws, xi)
        out = gait.update(t, dt, soles, yaws, xi, OMEGA)
        if out.swing_foot >= 0:
            soles[out.swing_foot, :2] = out.swing_pos_m[:2]
        p = out.cop_xy_m.copy()
        xi = p + (xi - p) * math.exp(OMEGA * dt)
        for start, end, vel in ([] if push is None else [push] if np.isscalar(push[0]) else push):
            if start <= t < end:
                xi = xi + np.asarray(vel) * dt
        rows.append((t, out.push_drift_m, out.push_seen, out.pushed, out.after_push))
        t += dt
    return np.array(rows, dtype=float)


def _reversal(t):
    """Walking forward 0.5 m/s, then backwards and turning hard from 2 s: the plan moves, not the DCM."""
    return (0.5, 0.0, 0.0) if t < 2.0 else (-0.3, 0.0, 0.8)


@pytest.mark.parametrize("command", [(0.3, 0.0, 0.0), _reversal])
def test_a_push_is_told_from_what_the_pendulum_explains(command):
    """GaitConfig.push_detect_m: the DCM moving as the pendulum does under the CoP the gait asks (a
    command changing included) is never a push; 1.1 m/s more for 0.2 s (150 N on the robot's 35 kg at
    w ~ 3.9/s) is one, told by its end, remembered push_memory_s."""
    cfg = GaitConfig()
    quiet = _pendulum_walk(VelocityGait(), 4.0, command=command)
    assert quiet[:, 1].max() < 1e-6 and not quiet[:, 2].any()
    rows = _pendulum_walk(VelocityGait(), 4.0, push=(2.0, 2.2, (0.0, -1.1)), command=command)
    t, drift, seen = rows[:, 0], rows[:, 1], rows[:, 2] > 0
    assert not seen[t < 2.0].any() and drift[t < 2.0].max() < 1e-6
    first = t[seen][0]
    assert 2.0 + cfg.push_detect_hold_s < first < 2.22
    assert drift.max() > cfg.push_detect_m
    assert seen[(t >= first) & (t <= first + cfg.push_memory_s - 0.01)].all()
    assert not seen[t > first + cfg.push_memory_s + 0.3].any()  # the drift decays with the memory


@pytest.mark.parametrize("max_rate", [2.0, 1e9])
def test_a_dcm_estimate_that_jumps_out_and_back_is_no_push(max_rate):
    """GaitConfig.push_detect_max_rate_mps: the DCM estimate jumping 0.24 m at 4 m/s and back within
    0.16 s (as walking 0.6-0.7 m/s in random timelines, without a push) is not told a push; uncapped it is."""
    glitch = [(2.0, 2.06, (4.0, 0.0)), (2.1, 2.16, (-4.0, 0.0))]
    rows = _pendulum_walk(VelocityGait(GaitConfig(push_detect_max_rate_mps=max_rate)), 3.0, push=glitch)
    assert rows[:, 2].any() == (max_rate > 100)


@pytest.mark.parametrize("pushed", [True, False])
def test_after_push_steps_follow_a_told_push_only(pushed):
    """After a told push, after_push_steps holds the next step low; a DCM as far off its plan without a
    push told (the error put there at once: nothing the pendulum's drift shows) does not."""
    gait = VelocityGait(GaitConfig(after_push_steps=1))
    if pushed:
        rows = _pendulum_walk(gait, 4.0, push=(2.0, 2.2, (0.0, -1.1)))
        assert rows[:, 3].any() and rows[:, 4].any()
        assert rows[rows[:, 4] > 0, 0].min() > 2.0
    else:
        soles, yaws = _feet()
        t = _into_single_support(gait, soles, yaws)
        out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.05, -1.0]), OMEGA)
        assert out.pushed and not out.push_seen
        t = _to_touchdown(gait, t, soles, yaws)
        out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.05, 0.03]), OMEGA)
        assert not out.after_push


def test_the_early_lift_waits_for_a_told_push():
    """early_lift_dcm_error_m with the push check (the default): a DCM off its plan in the double
    support without a push told keeps the double support."""
    soles, yaws = _feet()
    gait = VelocityGait(GaitConfig(early_lift_dcm_error_m=0.2))
    cfg = gait.config
    t = _to_touchdown(gait, _into_single_support(gait, soles, yaws), soles, yaws)
    while t - gait._t0 < cfg.double_support_s - 0.008:
        t += 0.004
        out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.4, 0.0]), OMEGA)
        assert out.dcm_error_m > 0.2 and not out.push_seen
        assert gait.schedule(t + 0.004, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2)).all()


@pytest.mark.parametrize("kwargs, text", [
    ({"single_support_s": 0.0}, "single_support_s must be a finite number > 0"),
    ({"min_width_m": 0.3}, "min_width_m <= step_width_m <= max_width_m"),
    ({"freeze_landing_after": 1.5}, "freeze_landing_after must be in"),
    ({"fast_double_support_s": 0.1}, "fast_double_support_s <= double_support_s"),
    ({"cadence_reach_from": 1.2}, "cadence_reach_from < cadence_reach_full"),
    ({"fast_max_width_m": 0.4}, "max_width_m <= fast_max_width_m"),
    ({"recovery_max_width_m": 0.0}, "recovery_max_width_m must be a finite number > 0"),
    ({"after_push_steps": -1}, "after_push_steps must be an integer >= 0; got -1"),
    ({"after_push_steps": 1.5}, "after_push_steps must be an integer >= 0; got 1.5"),
    ({"early_lift_dcm_error_m": 0.0}, r"early_lift_dcm_error_m must be > 0 \(inf: never\); got 0.0"),
    ({"early_lift_dcm_error_m": math.nan}, "early_lift_dcm_error_m must be > 0"),
    ({"touchdown_height_m": 0.0}, r"touchdown_height_m must be > 0 \(inf: on the clock\); got 0.0"),
    ({"touchdown_height_m": math.nan}, "touchdown_height_m must be > 0"),
    ({"touchdown_max_wait_s": -0.1}, "touchdown_max_wait_s must be a finite number >= 0; got -0.1"),
    ({"touchdown_max_wait_s": math.inf}, "touchdown_max_wait_s must be a finite number >= 0"),
    ({"terrain_side_follow_reach_m": -0.05}, "terrain_side_follow_reach_m must be a finite number >= 0; got -0.05"),
    ({"touchdown_descent_mps": math.nan}, "touchdown_descent_mps must be a finite number >= 0"),

    ({"push_detect_m": -0.1}, r"push_detect_m must be >= 0 \(0: no check, inf: never\); got -0.1"),
    ({"push_detect_m": math.nan}, "push_detect_m must be >= 0"),
    ({"push_detect_tau_s": 0.0}, "push_detect_tau_s must be a finite number > 0; got 0.0"),
    ({"push_detect_hold_s": -1.0}, "push_detect_hold_s must be a finite number >= 0; got -1.0"),
    ({"push_memory_s": math.inf}, "push_memory_s must be a finite number >= 0; got inf"),
    ({"push_detect_max_rate_mps": 0.0}, "push_detect_max_rate_mps must be a finite number > 0; got 0.0"),
])
def test_bad_gait_config_is_refused(kwargs, text):
    with pytest.raises(WbcConfigError, match=text):
        GaitConfig(**kwargs)


def test_axis_limits_at_a_cadence_are_the_bisection_of_step_load_bit_for_bit():
    """The written-out bisection (_axis_limits_at_cadence) gives exactly what bisecting step_load
    itself gives, for commands slow and fast, forward, backward and sideways, at several margins."""
    from g1_control.trackers.wbc.gait import _AXES, _axis_limit_bisected, _axis_limits

    cfg = GaitConfig()
    rng = np.random.default_rng(3)
    cadences = [np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([-0.4, 0.3, 0.5])]
    cadences += [rng.uniform([-1.0, -0.6, -1.5], [1.2, 0.6, 1.5]) for _ in range(20)]
    for cadence in cadences:
        for margin in (0.8, 0.9, 1.0):
            fast = _axis_limits(cfg, margin, cadence)
            generic = tuple(_axis_limit_bisected(cfg, margin, cadence, axis, sign) for axis, sign in _AXES)
            assert fast == generic, (cadence, margin)


def _step_ahead(x_edge: float = 1.0):
    from g1_control.scene import Platform, SceneConfig
    from g1_control.trackers.wbc.terrain import Terrain

    return Terrain.of_scene(SceneConfig(platforms=[Platform("step", (x_edge + 0.6, 0.0), (1.2, 1.4), 0.15)]))


def _double_support_after_first_touchdown(terrain, dcm_ahead_of_right_m):
    """How long (s) the left foot stays down after the first step's touchdown (the right foot's), the
    DCM held dcm_ahead_of_right_m ahead of the right sole."""
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[:, 0] += 0.6
    cmd = np.array([0.3, 0.0, 0.0])
    t = _into_single_support(gait, soles, yaws)
    dcm = soles[RIGHT, :2] + np.array([dcm_ahead_of_right_m, 0.05])
    while gait.stance == LEFT:
        t += 0.004
        gait.schedule(t, cmd, soles, yaws, dcm)
    touchdown = t
    while gait.targets.contacts[LEFT] and t < touchdown + 2.0:
        t += 0.004
        gait.schedule(t, cmd, soles, yaws, dcm)
    return t - touchdown


def test_near_a_step_the_other_foot_lifts_only_once_the_dcm_is_over_the_stance_sole():
    cfg = GaitConfig()
    near = _step_ahead()
    # the DCM behind the stance sole: the double support waits for it, at most terrain_max_wait_s
    waited = _double_support_after_first_touchdown(near, -0.05)
    assert waited == pytest.approx(cfg.double_support_s + cfg.terrain_max_wait_s, abs=0.01)
    # over it, or on flat ground, the double support is the configured one
    assert _double_support_after_first_touchdown(near, 0.02) == pytest.approx(cfg.double_support_s, abs=0.005)
    assert _double_support_after_first_touchdown(None, -0.05) == pytest.approx(cfg.double_support_s, abs=0.005)


def test_at_a_riser_the_step_goes_onto_the_tread_and_keeps_that_level():
    """The stance foot just short of a riser: the landing the DCM asks lies across the edge; moved
    back it would gain nothing, so it goes onto the tread (further than TerrainConfig.max_shift_m
    reaches), whole sole on it; the DCM then falling back does not bring the landing back down."""
    terrain = _step_ahead(1.0)
    tc = terrain.config
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[:, 0] = 1.0 - tc.sole_half_length_m - tc.riser_gap_m - 0.01
    t = _into_single_support(gait, soles, yaws)
    dcm = soles[LEFT, :2] + np.array([0.05, -0.03])  # asks a short step, across the edge
    out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    landing = out.landing_m.copy()
    assert landing[2] == pytest.approx(0.15)
    assert landing[0] - tc.sole_half_length_m - tc.edge_margin_m >= 1.0 - 1e-9
    assert landing[0] - soles[LEFT, 0] > tc.max_shift_m + 0.05
    assert terrain.is_level(landing[:2], 0.0)
    for _ in range(5):
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        out = gait.update(t, 0.004, soles, yaws, dcm - np.array([0.04, 0.0]), OMEGA)
        assert out.landing_m[2] == pytest.approx(0.15) and terrain.is_level(out.landing_m[:2], 0.0)


@pytest.mark.parametrize("drift_m", [0.0, 0.05, -0.05])
def test_on_flat_ground_a_height_drift_of_the_feet_is_not_a_step(drift_m):
    """Without platforms in the scene, soles measured at different heights (leg odometry drifting
    with a slipping or tipping foot) do not make the swing a step up or down: the foot moves across
    after the flat gait's short hold, not the terrain's long one (on `g1 bench robust`'s draw 0 the
    held foot then had to cross at up to 12 m/s, measured)."""
    soles, yaws = _feet()
    soles[RIGHT, 2] += drift_m
    gait = VelocityGait()
    assert gait.terrain.flat
    t = _into_single_support(gait, soles, yaws)
    cfg = gait.config
    moved = []
    while t - gait._t0 < cfg.double_support_s + 0.3 * cfg.single_support_s:
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        dcm = soles[gait.stance, :2] + np.array([0.05, 0.03 * (1 if gait.stance == RIGHT else -1)])
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        moved.append(float(np.hypot(*out.swing_vel_mps[:2])))
    assert out.swing_foot >= 0
    # by 0.3 of the single support (the terrain's hold is 0.4) the foot is well under way across
    assert max(moved) > 0.3


def _two_treads():
    """Stairs from x = 1.0: a 0.15 m tread 0.45 m deep, then a 0.30 m one."""
    from g1_control.scene import Platform, SceneConfig
    from g1_control.trackers.wbc.terrain import Terrain

    return Terrain.of_scene(SceneConfig(platforms=[Platform("tread1", (1.225, 0.0), (0.45, 1.4), 0.15),
                                                   Platform("tread2", (1.675, 0.0), (0.45, 1.4), 0.30)]))


def test_a_trailing_foot_comes_onto_the_stance_foot_level_not_past_it():
    """The stance foot on the first tread, the swing foot on the floor behind, the DCM asking a long
    step (its landing would lie on the second tread): the trailing foot comes onto the first tread,
    whole sole on it, never two treads up in one swing."""
    terrain = _two_treads()
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[LEFT] = (1.2, 0.11, 0.15)
    soles[RIGHT] = (0.8, -0.11, 0.0)
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT
    out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.35, -0.05]), OMEGA)
    assert out.landing_m[2] == pytest.approx(0.15)
    assert terrain.is_level(out.landing_m[:2], 0.0) and terrain.height(out.landing_m[:2]) == pytest.approx(0.15)


@pytest.mark.parametrize("plan", [True, False])
def test_a_step_onto_a_tread_is_planned_as_the_long_step_from_its_double_support(plan):
    """GaitConfig.terrain_plan_long_steps: the stance foot just landed short of a riser, its double
    support under way: the next step goes onto the tread, so it already has its long single support,
    and the DCM's plan is that step's (the DCM over the stance sole's centre, where a 0.8 s step wants
    it at lift-off); without, the plan is a 0.42 s step's, 4-5 cm inside the stance sole."""
    terrain = _two_treads()
    gait = VelocityGait(GaitConfig(terrain_plan_long_steps=plan), terrain)
    soles, yaws = _feet()
    soles[:, 0] = 0.6
    t = _into_single_support(gait, soles, yaws)
    soles[RIGHT, 0] = 0.775  # lands with its toe a riser gap short of the first tread
    t = _to_touchdown(gait, t, soles, yaws)
    assert gait.stance == RIGHT
    dcm = soles[RIGHT, :2].copy()
    for _ in range(3):
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, dcm)
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    assert not gait._swinging and out.landing_m[2] == pytest.approx(0.15)
    cfg = gait.config
    if plan:
        assert gait.active.single_support_s > cfg.terrain_single_support_s + 0.2
        assert out.dcm_error_m < 0.02
    else:
        assert gait.active.single_support_s == cfg.terrain_single_support_s
        assert out.dcm_error_m > 0.035


@pytest.mark.parametrize("speed", [2.0, 0.0])
def test_on_steps_a_swing_s_landing_moves_no_faster_than_its_limit(speed):
    """GaitConfig.terrain_landing_speed_mps: a DCM jumping 0.1 m back and forth every tick (as it read in
    the long steps up, predicted e^{w t_r} further out) moves the landing at most speed * dt a tick on a
    terrain; unlimited (0), the landing jumps with it."""
    gait = VelocityGait(GaitConfig(terrain_landing_speed_mps=speed), _step_ahead(2.0))
    soles, yaws = _feet()
    t = _into_single_support(gait, soles, yaws)
    assert gait._swinging
    last = None
    moves = []
    for k in range(20):
        t += 0.004
        dcm = soles[gait.stance, :2] + np.array([0.05 + 0.1 * (k % 2), 0.0])
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, dcm)
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        assert out.swing_foot >= 0
        if last is not None:
            moves.append(float(np.hypot(*(out.landing_m[:2] - last))))
        last = out.landing_m[:2].copy()
    if speed > 0:
        assert max(moves) <= speed * 0.004 + 1e-9
    else:
        assert max(moves) > 0.05


def test_a_swing_keeps_the_level_its_foothold_had():
    """Both feet on the first tread, a short step under way: the DCM then running ahead moves the
    landing forward, but not onto the next tread (its swing was planned for this level)."""
    terrain = _two_treads()
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[:, 0] = 1.16
    soles[:, 2] = 0.15
    t = _into_single_support(gait, soles, yaws)
    out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.0, -0.05]), OMEGA)
    assert out.landing_m[2] == pytest.approx(0.15)
    for ahead in (0.4, 0.3, 0.5):  # the landing asked lies on (or beyond the riser of) the second tread
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([ahead, -0.05]), OMEGA)
        assert out.landing_m[2] == pytest.approx(0.15), ahead
        assert terrain.is_level(out.landing_m[:2], 0.0) and terrain.height(out.landing_m[:2]) == pytest.approx(0.15)


@pytest.mark.parametrize("dcm_out_m, stance_y_m", [(0.015, None), (0.3, None), (0.3, 0.62)])
def test_a_trailing_foot_asked_off_the_stairs_side_does_not_aim_at_the_stance_sole(dcm_out_m, stance_y_m):
    """The right foot steps up onto the first tread near its side (y 0.7); the left foot, on the floor
    beside the stairs' side, trails. The DCM asks it to land where no sole lies whole on the stance
    foot's level along the heading (as a DCM running out sideways does, `g1 bench stairs` seed 100):
    straddling the second tread's riser at the tread's side (0.015 m out), or off the stairs' side over
    the second tread (0.3 m out). The foot then comes onto the tread beside the stance foot, at the step
    width; with the stance foot at the tread's side (no room beside it), onto the floor off the side,
    where it was asked. Never where the stance foot stands (the last step's foothold, where it aimed
    before)."""
    terrain = _two_treads()
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[LEFT] = (0.8, 0.55, 0.0)
    soles[RIGHT] = (0.8, 0.33, 0.0)
    cmd = np.array([0.3, 0.0, 0.0])
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT
    # the right foot's step onto the first tread (its foothold there), then its touchdown
    for _ in range(5):
        t += 0.004
        gait.schedule(t, cmd, soles, yaws, soles[LEFT, :2])
        out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.3, -0.04]), OMEGA)
    assert out.landing_m[2] == pytest.approx(0.15)
    soles[RIGHT] = out.landing_m
    while gait.stance == LEFT:
        t += 0.004
        gait.schedule(t, cmd, soles, yaws, soles[RIGHT, :2])
    assert gait.stance == RIGHT and terrain.height(soles[RIGHT, :2]) == pytest.approx(0.15)
    if stance_y_m is not None:
        soles[RIGHT, 1] = stance_y_m
        assert terrain.fits(soles[RIGHT, :2], 0.0, 0.15)
    # the left foot's landing, the DCM out to the left
    t += 0.004
    gait.schedule(t, cmd, soles, yaws, soles[RIGHT, :2])
    out = gait.update(t, 0.004, soles, yaws, soles[RIGHT, :2] + np.array([0.0, dcm_out_m]), OMEGA)
    landing = out.landing_m
    assert landing[1] - soles[RIGHT, 1] >= gait.config.min_width_m
    if stance_y_m is None:
        assert landing[2] == pytest.approx(0.15) and terrain.fits(landing[:2], 0.0, 0.15)
        assert landing[:2] == pytest.approx(soles[RIGHT, :2] + np.array([0.0, gait.config.step_width_m]))
    else:
        assert landing[2] == pytest.approx(0.0) and terrain.fits(landing[:2], 0.0, 0.0)
        assert landing[1] > 0.7  # off the stairs' side, where it was asked


def test_on_steps_the_cop_sent_is_the_two_tick_mean_of_the_cop_law_s():
    """GaitConfig.terrain_cop_two_tick_mean: the feet before a riser, the landing the DCM asks snapped
    onto the tread, the DCM held still: the gait's own loop (the landing predicted from this tick's
    CoP moves the DCM's plan, and the plan the next tick's CoP) makes the CoP law alternate tick to
    tick, more than 3 cm at a time (stop 48's chatter). With the mean, what the gait sends is the mean
    of that same law's last two values within the contact phase (two gaits, one input): it no longer
    jumps tick to tick."""
    def run(mean):
        gait = VelocityGait(GaitConfig(terrain_cop_two_tick_mean=mean), _step_ahead(1.0))
        soles, yaws = _feet()
        soles[:, 0] = 0.75
        t = _into_single_support(gait, soles, yaws)
        cops, phases, levels = [], [], []
        for _ in range(150):
            t += 0.004
            dcm = soles[gait.stance, :2] + np.array([0.06, 0.0])
            gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, dcm)
            out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
            cops.append(out.cop_xy_m.copy())
            phases.append((gait._t0, gait._swinging))
            levels.append(out.landing_m[2])
        return np.array(cops), phases, levels

    law, phases, levels = run(False)
    sent, phases_on, _ = run(True)
    assert phases_on == phases and min(levels) == pytest.approx(0.15)  # the landing on the tread throughout
    same = [k for k in range(1, len(law)) if phases[k] == phases[k - 1]]
    jumps = [float(np.hypot(*(law[k] - law[k - 1]))) for k in same]
    assert sum(j > 0.03 for j in jumps) >= 20
    for k in same:
        np.testing.assert_allclose(sent[k], 0.5 * (law[k] + law[k - 1]), atol=1e-12)
    # what is sent jumps only where the law itself moves on (the double support's first ticks)
    assert sum(float(np.hypot(*(sent[k] - sent[k - 1]))) > 0.03 for k in same) <= 2


def test_a_swing_asked_off_the_stairs_side_keeps_its_foothold():
    """Both feet on the first tread near its right side, the right foot's step under way with its
    foothold on that tread: the DCM then asking a landing off the stairs' side (no place on the tread
    along the heading from there), the swing keeps the foothold it had (its level and its place), rather
    than moving to a new place beside the stance foot mid-swing."""
    terrain = _two_treads()
    gait = VelocityGait(GaitConfig(), terrain)
    soles, yaws = _feet()
    soles[:, 0] = 1.16
    soles[:, 2] = 0.15
    soles[LEFT, 1], soles[RIGHT, 1] = -0.35, -0.57
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT and gait._swinging
    landings = []
    for out_m in (0.0, 0.0, -0.3, -0.3, -0.3, -0.3):
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
        out = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.05, out_m]), OMEGA)
        landings.append(out.landing_m.copy())
    kept = landings[1]
    assert kept[2] == pytest.approx(0.15) and terrain.fits(kept[:2], 0.0, 0.15)
    for landing in landings[2:]:
        np.testing.assert_allclose(landing, kept, atol=1e-12)


WAIT_FOR_CONTACT = GaitConfig(touchdown_height_m=0.02)
"""The touchdown wait switched on (off by default)."""


def _step_up_until_touchdown(cfg, above_m, terrain=None):
    """The right foot on the floor steps up onto a 0.15 m step (the left foot on it already), held
    `above_m` above the landing once the clock's touchdown has come. Returns (the time past the clock's
    touchdown when the right foot became the stance foot (inf: not within 0.5 s), the lowest swing
    reference height asked after the clock's touchdown (inf: none), the gait)."""
    terrain = _step_ahead(1.0) if terrain is None else terrain
    gait = VelocityGait(cfg, terrain)
    soles, yaws = _feet()
    soles[LEFT] = (1.25, 0.11, 0.15)
    soles[RIGHT] = (0.85, -0.11, 0.0)
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT and not gait.targets.contacts[RIGHT]
    cmd = np.array([0.3, 0.0, 0.0])
    dcm = soles[LEFT, :2] + np.array([0.02, -0.03])
    out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    clock = gait._t0 + gait.step_T
    lowest = math.inf
    while t < clock + 0.5:
        t += 0.004
        if t >= clock:
            soles[RIGHT] = (*out.landing_m[:2], out.landing_m[2] + above_m)
        gait.schedule(t, cmd, soles, yaws, dcm)
        if gait.stance == RIGHT:
            return t - clock, lowest, gait
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        assert out.swing_foot == RIGHT and out.landing_m[2] == pytest.approx(0.15)
        if t >= clock:
            lowest = min(lowest, float(out.swing_pos_m[2]))
    return math.inf, lowest, gait


def test_on_terrain_a_swing_foot_still_in_the_air_is_not_declared_in_stance():
    """Stepping up, the swing foot 9 cm above the tread at the clock's touchdown (it lagged its
    reference): the step goes on, its reference lowering below the tread, until the foot is within
    touchdown_height_m of the tread, at most touchdown_max_wait_s; the next step starts from then."""
    cfg = WAIT_FOR_CONTACT
    late, lowest, gait = _step_up_until_touchdown(cfg, 0.09)
    assert late == pytest.approx(cfg.touchdown_max_wait_s, abs=0.005)
    assert lowest < 0.15 - 0.5 * cfg.touchdown_descent_mps * cfg.touchdown_max_wait_s
    # the double support after it starts at the late touchdown, not at the clock's
    assert gait._t0 == pytest.approx(gait.touchdowns[-1][0])
    # on the tread (within touchdown_height_m), or with the check off: on the clock
    assert _step_up_until_touchdown(cfg, 0.01)[0] < 0.005
    # off (inf, the default): on the clock
    assert GaitConfig().touchdown_height_m == math.inf
    late, lowest, _ = _step_up_until_touchdown(GaitConfig(), 0.09)
    assert late < 0.005 and lowest == math.inf


def test_a_foot_coming_down_onto_the_tread_becomes_the_stance_foot_then():
    """The swing foot 9 cm up at the clock's touchdown, then coming down at 0.6 m/s: the stance
    changes once it is within touchdown_height_m of the tread (0.07 m down: ~0.12 s late)."""
    cfg = dataclasses.replace(WAIT_FOR_CONTACT, touchdown_max_wait_s=0.5)
    terrain = _step_ahead(1.0)
    gait = VelocityGait(cfg, terrain)
    soles, yaws = _feet()
    soles[LEFT] = (1.25, 0.11, 0.15)
    soles[RIGHT] = (0.85, -0.11, 0.0)
    t = _into_single_support(gait, soles, yaws)
    cmd = np.array([0.3, 0.0, 0.0])
    dcm = soles[LEFT, :2] + np.array([0.02, -0.03])
    out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    clock = gait._t0 + gait.step_T
    while gait.stance == LEFT:
        t += 0.004
        if t >= clock:
            soles[RIGHT] = (*out.landing_m[:2], 0.15 + max(0.09 - 0.6 * (t - clock), 0.0))
        gait.schedule(t, cmd, soles, yaws, dcm)
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        assert t < clock + 0.5
    assert soles[RIGHT, 2] - 0.15 <= cfg.touchdown_height_m + 1e-9
    assert t - clock == pytest.approx((0.09 - cfg.touchdown_height_m) / 0.6, abs=0.01)


def test_on_flat_ground_touchdown_stays_on_the_clock():
    """Without platforms in the scene nothing changes: a foot held up lands on the clock."""
    gait = VelocityGait(WAIT_FOR_CONTACT)
    soles, yaws = _feet()
    t = _into_single_support(gait, soles, yaws)
    swing = 1 - gait.stance
    clock = gait._t0 + gait.step_T
    soles[swing, 2] = 0.09
    while gait.stance != swing:
        t += 0.004
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    assert t - clock < 0.005


def test_a_step_on_one_level_of_a_terrain_scene_lands_on_the_clock():
    """A platform in the scene but the step on the floor: a foot held 9 cm up at the clock's
    touchdown becomes the stance foot then (only a step onto another level waits for contact)."""
    gait = VelocityGait(WAIT_FOR_CONTACT, _step_ahead(3.0))
    assert not gait.terrain.flat
    soles, yaws = _feet()
    t = _into_single_support(gait, soles, yaws)
    swing = 1 - gait.stance
    dcm = soles[gait.stance, :2] + np.array([0.05, 0.03 * (1 if gait.stance == RIGHT else -1)])
    out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    clock = gait._t0 + gait.step_T
    while gait.stance != swing:
        t += 0.004
        if t >= clock:
            soles[swing, 2] = 0.09
        gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, dcm)
        out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
        assert out.landing_m[2] == pytest.approx(0.0) or gait.stance == swing
    assert t - clock < 0.005


def test_a_trailing_foot_stepping_down_waits_for_contact_once_over_the_lower_level():
    """The trailing foot steps down off a 0.15 m step onto the floor beside the stance foot: over the
    floor by the clock's touchdown but 9 cm above it, it is still a step onto another level (where it
    lifted from counts, not where it is) and waits for contact."""
    cfg = WAIT_FOR_CONTACT
    gait = VelocityGait(cfg, _step_ahead(1.0))  # the step spans x 1.0 .. 2.2
    soles, yaws = _feet()
    soles[LEFT] = (2.45, 0.11, 0.0)
    soles[RIGHT] = (2.05, -0.11, 0.15)
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT
    cmd = np.array([0.3, 0.0, 0.0])
    dcm = soles[LEFT, :2] + np.array([0.02, -0.03])
    out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
    clock = gait._t0 + gait.step_T
    while gait.stance == LEFT and t < clock + 0.5:
        t += 0.004
        if t >= clock - 0.1:
            soles[RIGHT] = (*out.landing_m[:2], 0.09)
        gait.schedule(t, cmd, soles, yaws, dcm)
        if gait.stance == LEFT:
            out = gait.update(t, 0.004, soles, yaws, dcm, OMEGA)
            assert out.landing_m[2] == pytest.approx(0.0)
    assert t - clock == pytest.approx(cfg.touchdown_max_wait_s, abs=0.005)


def _oblique_stairs_landings(cfg):
    """`g1 bench stairs` seed 100's stairs (turned 16.7 deg, offset 0.06 m), the left foot on the floor
    before them: the first landing the DCM asks snaps onto the first tread; a tick later the DCM has run
    10 cm further right (and ahead). Returns the two landings relative to the left sole, and the terrain."""
    from g1_control.tools.bench_stairs import course_scene
    from g1_control.trackers.wbc.terrain import Terrain

    terrain = Terrain.of_scene(course_scene("stairs", math.radians(16.7), 0.06)[0])
    gait = VelocityGait(cfg, terrain)
    soles, yaws = _feet()
    soles[:, 0] = 0.96
    t = _into_single_support(gait, soles, yaws)
    assert gait.stance == LEFT
    first = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.03, -0.04]), OMEGA).landing_m.copy()
    t += 0.004
    gait.schedule(t, np.array([0.3, 0.0, 0.0]), soles, yaws, np.zeros(2))
    later = gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.15, -0.10]), OMEGA).landing_m.copy()
    return first - soles[LEFT], later - soles[LEFT], later[:2], terrain


def test_a_landing_kept_on_its_tread_follows_the_dcm_sideways_with_terrain_side_follow_reach():
    """A step whose landing snapped onto a tread keeps that tread; with terrain_side_follow_reach_m (off
    by default) not its first sideways place: the DCM running further sideways moves the foothold
    sideways too, still whole on the tread (kept where it was, the first step up of seed 100's stairs
    landed with the DCM 8.6 cm outside the foot, and the robot fell sideways off it in its next single
    support). The landing's speed limit (terrain_landing_speed_mps) is off here: this is where the
    foothold goes, not how fast."""
    first, later, xy, terrain = _oblique_stairs_landings(GaitConfig(terrain_side_follow_reach_m=0.1,
                                                                     terrain_landing_speed_mps=0.0))
    assert first[2] == pytest.approx(0.15) and later[2] == pytest.approx(0.15)
    assert later[1] < first[1] - 0.15  # followed the DCM sideways (to the step width limit)
    assert terrain.is_level(xy, 0.0) and terrain.height(xy) == pytest.approx(0.15)
    # by default the foothold stays where it first snapped, sideways too
    kept_first, kept, _, _ = _oblique_stairs_landings(GaitConfig(terrain_landing_speed_mps=0.0))
    assert kept_first[:2] == pytest.approx(first[:2], abs=1e-9)
    assert kept[:2] == pytest.approx(kept_first[:2], abs=1e-9)


@pytest.mark.parametrize("walked", [0.0, 0.3])
def test_the_speed_correction_applies_while_walking_and_not_once_the_command_walked_is_zero(walked):
    """Stopping (the command walked down to zero) the gait plans the stop as it is, without the speed
    correction: random timeline s8 of `g1 bench locomotion` stopped from a combined walk with the correction
    at (-0.28, -0.14) m/s, kept stepping and was thrown. Walking, the correction moves the landing."""
    soles, yaws = _feet()
    landings = []
    for correction in ((0.0, 0.0), (-0.28, -0.14)):
        gait = VelocityGait()
        t = _into_single_support(gait, soles, yaws)
        gait.command_h[:] = (walked, 0.0, 0.0)
        gait.speed_correction_h[:] = correction
        landings.append(gait.update(t, 0.004, soles, yaws, soles[LEFT, :2] + np.array([0.02, -0.03]),
                                    OMEGA).landing_m.copy())
    moved = float(np.linalg.norm(landings[1][:2] - landings[0][:2]))
    if walked:
        assert moved > 0.05, "walking, the correction moves the landing"
    else:
        assert moved == 0.0, "stopping, the landing is the stop's own"


def test_a_touchdown_while_stopping_clears_the_speed_correction():
    gait = VelocityGait()
    soles, yaws = _feet()
    t = _into_single_support(gait, soles, yaws)
    gait.speed_correction_h[:] = (-0.28, -0.14)
    gait.command_h[:] = 0.0
    n = gait.steps
    while gait.steps < n + 1:  # a touchdown with the command walked at zero
        t += 0.004
        gait.schedule(t, np.zeros(3), soles, yaws, soles.mean(axis=0)[:2])
        assert t < 5.0
    assert not gait.speed_correction_h.any(), "nothing wound up from the stopping steps"
