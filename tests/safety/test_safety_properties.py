"""Property: whatever the references, policy outputs and states, no command that leaves the safety
filter, and no LowCmd_ the DDS encoder makes of it, breaks a joint limit, carries NaN, or has a
bad CRC; and once tripped the filter only ever emits damping."""

from __future__ import annotations

import numpy as np
from hypothesis import event, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from g1_control.hardware.unitree.conversions import motor_command_to_lowcmd
from g1_control.hardware.unitree.messages import LowCmd, verify_crc
from g1_control.robot import g1
from g1_control.safety import SafetyConfig, SafetyEventKind, SafetyFilter
from g1_control.types import MotorCommand, RobotState

N = g1.NUM_JOINTS
any_float = st.floats(allow_nan=True, allow_infinity=True, width=64)
mostly_sane = st.one_of(st.floats(-50, 50), any_float)
vec = arrays(np.float64, N, elements=mostly_sane)


@st.composite
def commands(draw):
    """A policy output of one of three kinds, drawn evenly so that each path of the filter is taken often:
    finite within the limits or beyond them (the clamp path), finite with NaN/inf planted in some
    fields (the non-finite trip), or anything at all."""
    kind = draw(st.sampled_from(["clamp", "clamp", "clamp", "nonfinite", "any"]))
    if kind == "any":
        fields = {name: draw(vec) for name in ("q_rad", "dq_radps", "kp", "kd", "tau_nm")}
    else:
        wide = arrays(np.float64, N, elements=st.one_of(st.floats(-5, 5), st.floats(-1e3, 1e3)))
        fields = {name: draw(wide) for name in ("q_rad", "dq_radps", "kp", "kd", "tau_nm")}
        if kind == "nonfinite":
            for name in draw(st.lists(st.sampled_from(sorted(fields)), min_size=1, max_size=3, unique=True)):
                j = draw(st.integers(0, N - 1))
                fields[name][j] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    return kind, MotorCommand(**fields, enable=draw(arrays(np.bool_, N)))


@st.composite
def states(draw):
    """A healthy robot (near the default pose, upright, cool, the same mode_machine) three times in four,
    so that commands reach an untripped filter; otherwise anything the sensors might report."""
    if draw(st.sampled_from([True, True, True, False])):
        tilt = draw(arrays(np.float64, 2, elements=st.floats(-0.2, 0.2)))
        quat = np.array([1.0, tilt[0], tilt[1], 0.0])
        return "healthy", RobotState(
            t_s=draw(st.floats(-0.04, 0.0)),
            q_rad=g1.DEFAULT_Q_RAD + draw(arrays(np.float64, N, elements=st.floats(-0.2, 0.2))),
            dq_radps=draw(arrays(np.float64, N, elements=st.floats(-5, 5))),
            imu_quat_wxyz=quat / np.linalg.norm(quat),
            motor_temperature_c=draw(arrays(np.float64, N, elements=st.floats(20, 80))),
            mode_machine=5,
        )
    quat = draw(arrays(np.float64, 4, elements=st.floats(-1, 1)))
    if np.linalg.norm(quat) < 1e-3:
        quat = np.array([1.0, 0.0, 0.0, 0.0])
    return "any", RobotState(
        t_s=draw(st.floats(-0.1, 0.0)),  # now_s is 0: states up to 100 ms old
        q_rad=draw(arrays(np.float64, N, elements=st.floats(-3, 3))),
        dq_radps=draw(arrays(np.float64, N, elements=st.one_of(st.floats(-40, 40), any_float))),
        imu_quat_wxyz=quat / np.linalg.norm(quat),
        motor_temperature_c=draw(arrays(np.float64, N, elements=st.floats(20, 100))),
        mode_machine=draw(st.sampled_from([4, 5, 6])),
    )


def assert_safe(cmd: MotorCommand, mode_machine: int) -> None:
    assert cmd.is_finite()
    assert np.all(cmd.q_rad >= g1.Q_MIN_RAD) and np.all(cmd.q_rad <= g1.Q_MAX_RAD)
    assert np.all(np.abs(cmd.tau_nm) <= g1.EFFORT_LIMIT_NM)
    assert np.all(np.abs(cmd.dq_radps) <= g1.VELOCITY_LIMIT_RADPS)
    assert np.all(cmd.kp >= 0) and np.all(cmd.kd >= 0)
    wire = LowCmd.from_dds(motor_command_to_lowcmd(cmd, mode_machine).to_dds())
    verify_crc(wire)
    q = wire.motor_q_rad[:N].astype(np.float64)
    tau = wire.motor_tau_nm[:N].astype(np.float64)
    on = wire.motor_mode[:N] == 1
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(tau))
    assert np.all(q[on] >= g1.Q_MIN_RAD[on]) and np.all(q[on] <= g1.Q_MAX_RAD[on])
    assert np.all(np.abs(tau) <= g1.EFFORT_LIMIT_NM)


def _damping(cmd: MotorCommand) -> bool:
    return bool(np.all(cmd.kp == 0) and np.all(cmd.kd > 0) and np.all(cmd.tau_nm == 0))


@settings(max_examples=80, deadline=None)
@given(steps=st.lists(st.tuples(commands(), states()), min_size=1, max_size=6))
def test_no_unsafe_command_ever_leaves_the_filter(steps):
    f = SafetyFilter()
    for i, ((_cmd_kind, cmd), (state_kind, state)) in enumerate(steps):
        now = float(i) * 0.02
        state.t_s += now
        state.tick = i
        tripped_before = f.tripped
        accepted = f.expected_mode_machine  # the first state's, once one got that far
        out = f.filter(cmd, state, now)
        assert_safe(out, state.mode_machine)
        if tripped_before:
            event("tripped before")
            assert _damping(out)
        elif state_kind == "healthy" and accepted is not None and accepted != state.mode_machine:
            event("a healthy state after one of another mode_machine")  # the variant changed: that trips first
            assert f.trip_event is not None and f.trip_event.kind == SafetyEventKind.MODE_MACHINE_CHANGED
            assert _damping(out)
        elif state_kind == "healthy" and cmd.is_finite():
            event("clamp path (untripped filter, finite command)")
            assert not f.tripped, f.trip_event
            assert all(np.array_equal(getattr(out, n), np.minimum(np.maximum(getattr(cmd, n), f._lo[k]), f._hi[k]))
                       for k, n in enumerate(("q_rad", "dq_radps", "tau_nm", "kp", "kd")))
        elif state_kind == "healthy":
            event("NaN/inf command into an untripped filter")
            assert f.trip_event is not None and f.trip_event.kind == SafetyEventKind.NONFINITE_COMMAND
            assert _damping(out)


finite_vec = arrays(np.float64, N, elements=st.one_of(st.floats(-50, 50), st.floats(-1e6, 1e6)))


@settings(max_examples=120, deadline=None)
@given(q=finite_vec, dq=finite_vec, kp=finite_vec, kd=finite_vec, tau=finite_vec, enable=arrays(np.bool_, N))
def test_each_field_is_clamped_to_its_own_limits_and_counted(q, dq, kp, kd, tau, enable):
    config = SafetyConfig(max_kp=400.0, max_kd=20.0)
    f = SafetyFilter(config)
    cmd = MotorCommand(q_rad=q, dq_radps=dq, kp=kp, kd=kd, tau_nm=tau, enable=enable)
    upright = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), motor_temperature_c=np.full(N, 40.0))
    out = f.filter(cmd, upright, 0.0)
    assert not f.tripped
    limits = {"q_rad": (g1.Q_MIN_RAD, g1.Q_MAX_RAD), "dq_radps": (-g1.VELOCITY_LIMIT_RADPS, g1.VELOCITY_LIMIT_RADPS),
              "tau_nm": (-g1.EFFORT_LIMIT_NM, g1.EFFORT_LIMIT_NM), "kp": (0.0, 400.0), "kd": (0.0, 20.0)}
    for name, (lo, hi) in limits.items():
        given_, sent = getattr(cmd, name), getattr(out, name)
        inside = (given_ >= lo) & (given_ <= hi)
        # In-limit values pass unchanged (bar the float32-safe margin at the very edge of a limit).
        np.testing.assert_allclose(sent[inside], given_[inside], rtol=0, atol=1e-5, err_msg=name)
        assert np.all(sent >= lo) and np.all(sent <= hi), name
        # Out-of-limit values land on the nearer limit.
        np.testing.assert_allclose(sent[~inside], np.clip(given_, lo, hi)[~inside], rtol=0, atol=1e-5, err_msg=name)
        assert np.array_equal(f.clamps.per_joint[name], (sent != given_).astype(int)), name
    assert f.clamps.commands == int(any(np.any(getattr(out, n) != getattr(cmd, n)) for n in limits))
    np.testing.assert_array_equal(out.enable, enable)
    assert out.enable is not cmd.enable and out.q_rad is not cmd.q_rad  # the caller's arrays stay the caller's
