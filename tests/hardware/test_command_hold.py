"""A motor command lives for command_ttl_s on a robot link: when the control loop stops renewing it
(a stalled host), the writer resends its hold form (same position targets and gains, no feedforward
torque, zero velocity target) instead of pushing the joints with a stale torque. Read here as the robot
reads it: LowCmd_ frames off a pyserial pty pair, decoded on the robot's side."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest

from g1_control.hardware.link_backend import LinkBackend
from g1_control.hardware.links.serial_port import SerialLink, open_pty_pair
from g1_control.hardware.unitree.conversions import lowcmd_to_motor_command
from g1_control.hardware.unitree.messages import LowState
from g1_control.robot import g1
from g1_control.types import MotorCommand

pytestmark = pytest.mark.timing

RATE_HZ = 200.0
TTL_S = 0.06


def _wbc_like() -> MotorCommand:
    """What the whole-body controller sends: targets one tick ahead, a velocity target, feedforward torque."""
    q = g1.DEFAULT_Q_RAD.copy()
    q[3] += 0.2
    dq = np.full(g1.NUM_JOINTS, 0.4)
    tau = np.linspace(-5.0, 5.0, g1.NUM_JOINTS)
    return MotorCommand(q_rad=q, dq_radps=dq, kp=np.full(g1.NUM_JOINTS, 40.0), kd=np.full(g1.NUM_JOINTS, 2.0),
                        tau_nm=tau)


class _Robot:
    """The robot's end of a pty pair: announces itself with one LowState_, then records every LowCmd_
    with its arrival time."""

    def __init__(self, ttl_s: float | None):
        tty_end, master_end = open_pty_pair()
        self.link = SerialLink("robot", master_end)
        self.backend = LinkBackend(SerialLink("host", tty_end), command_rate_hz=RATE_HZ, connect_timeout_s=3.0,
                                   close_damping_s=0.0, command_ttl_s=ttl_s)
        self.link.send(self.link.encode(LowState(mode_machine=5, tick=1)))
        self.backend.reset()
        self.frames: list[tuple[float, MotorCommand]] = []

    def listen(self, seconds: float) -> list[tuple[float, MotorCommand]]:
        got = []
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            for payload in self.link.receive(0.01):
                got.append((time.monotonic(), lowcmd_to_motor_command(self.link.decode_command(payload))))
        self.frames += got
        return got

    def close(self) -> None:
        self.backend.close()
        self.link.close()


@pytest.fixture
def robot(request):
    r = _Robot(getattr(request, "param", TTL_S))
    yield r
    r.close()


def _is_full(cmd: MotorCommand, sent: MotorCommand) -> bool:
    return bool(np.allclose(cmd.tau_nm, sent.tau_nm, atol=0.01) and np.allclose(cmd.dq_radps, sent.dq_radps, atol=0.01))


def _is_hold_of(cmd: MotorCommand, sent: MotorCommand) -> bool:
    return bool(np.all(cmd.tau_nm == 0.0) and np.all(cmd.dq_radps == 0.0)
                and np.allclose(cmd.q_rad, sent.q_rad, atol=1e-4) and np.allclose(cmd.kp, sent.kp, atol=0.01)
                and np.allclose(cmd.kd, sent.kd, atol=0.01))


def test_a_command_not_renewed_within_its_life_is_resent_without_torque_or_velocity_targets(robot):
    sent = _wbc_like()
    t_write = time.monotonic()
    robot.backend.write_command(sent)
    frames = robot.listen(0.4)
    kinds = ["full" if _is_full(c, sent) else "hold" if _is_hold_of(c, sent) else "other" for _, c in frames]
    assert "other" not in kinds, "every frame is the command or its hold form"
    assert kinds[0] == "full" and "hold" in kinds, kinds
    first_hold = kinds.index("hold")
    assert set(kinds[first_hold:]) == {"hold"}, "once held, the stream stays held until a new command"
    assert frames[first_hold][0] - t_write >= TTL_S, "the hold form came before the command's life was up"
    stats = robot.backend.stats()
    assert stats.holds == 1 and stats.commands_held >= len(kinds) - first_hold
    assert stats.command_ttl_s == TTL_S

    # A new command restores the stream at once, and lives its own life.
    robot.backend.write_command(sent)
    frames = robot.listen(0.4)
    runs = "".join("f" if _is_full(c, sent) else "h" for _, c in frames)
    assert re.fullmatch(r"h*f{3,}h+", runs), f"held (frames in flight), then the command, then held again: {runs}"
    assert robot.backend.stats().holds == 2


def test_a_command_renewed_in_time_is_never_held(robot):
    sent = _wbc_like()
    end = time.monotonic() + 0.4
    while time.monotonic() < end:
        robot.backend.write_command(sent)
        robot.listen(TTL_S / 4)
    assert all(_is_full(c, sent) for _, c in robot.frames)
    assert robot.backend.stats().holds == 0


def test_a_command_without_torque_or_velocity_targets_is_its_own_hold_form(robot):
    q = g1.DEFAULT_Q_RAD.copy()
    sent = MotorCommand(q_rad=q, kp=g1.KP_DEFAULT.copy(), kd=g1.KD_DEFAULT.copy())  # a policy's command
    robot.backend.write_command(sent)
    frames = robot.listen(0.3)
    assert frames and all(_is_hold_of(c, sent) for _, c in frames)
    assert robot.backend.stats().holds == 0, "nothing to hold: no hold is counted"


def test_a_velocity_target_without_torque_is_held_too(robot):
    """A command whose only one-tick part is its velocity target (no feedforward torque) is not its own
    hold form: once its life is up it is resent with the velocity target zeroed."""
    sent = _wbc_like()
    sent.tau_nm[:] = 0.0
    robot.backend.write_command(sent)
    frames = robot.listen(0.3)
    assert _is_full(frames[0][1], sent), "the command goes out as it is first"
    assert _is_hold_of(frames[-1][1], sent), "past its life the velocity target is no longer sent"
    assert robot.backend.stats().holds == 1


def test_damping_is_never_replaced_by_a_hold_form(robot):
    robot.backend.write_command(_wbc_like())
    robot.listen(0.15)  # the command is held by now
    robot.backend.damp()
    frames = robot.listen(0.3)
    damping = [bool(np.all(c.kp == 0.0) and np.all(c.kd > 0.0)) for _, c in frames]
    assert True in damping
    after = damping[damping.index(True):]
    assert len(after) >= 20 and all(after), "damping (kp 0) streams on after a hold, whatever the command's age"


@pytest.mark.parametrize("robot", [None], indirect=True)
def test_without_a_life_the_latest_command_streams_as_it_is(robot):
    sent = _wbc_like()
    robot.backend.write_command(sent)
    frames = robot.listen(0.3)
    assert frames and all(_is_full(c, sent) for _, c in frames)
    assert robot.backend.stats().holds == 0 and robot.backend.stats().command_ttl_s is None


def test_a_life_that_is_not_positive_is_refused():
    tty_end, master_end = open_pty_pair()
    host = SerialLink("host", tty_end)
    with pytest.raises(ValueError, match="command_ttl_s"):
        LinkBackend(host, command_ttl_s=0.0)
    host.close()
    master_end.close()


def test_a_command_written_while_the_writer_encodes_a_hold_form_wins(robot):
    """The race the writer thread can lose: it picked the old command's hold form, then a new command
    arrived while it encoded it. What goes out is the new command, not the stale hold form."""
    old, new = _wbc_like(), _wbc_like()
    new.tau_nm[:] = 3.0
    robot.backend.write_command(old)
    picked = robot.backend._hold
    robot.backend.write_command(new)
    payload = robot.backend._hold_payload(picked)
    assert _is_full(lowcmd_to_motor_command(robot.link.decode_command(payload)), new)
    assert robot.backend.stats().holds == 0
