"""The Unitree remote: byte layout (built here independently with struct), mapping, loss."""

import math
import struct

import pytest

from g1_control.errors import RemoteDecodeError
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig
from g1_control.teleop.unitree_remote import UnitreeRemote, decode_wireless_remote, encode_wireless_remote
from g1_control.types import RobotState


def remote_bytes(bits=0, lx=0.0, rx=0.0, ry=0.0, l2=0.0, ly=0.0, head=b"\xa5\x5a"):
    """40 bytes laid out as docs/robot_facts.md states, field by field (independent of the module's encoder)."""
    data = bytearray(40)
    data[0:2] = head
    data[2:4] = struct.pack("<H", bits)
    for offset, value in ((4, lx), (8, rx), (12, ry), (16, l2), (20, ly)):
        data[offset:offset + 4] = struct.pack("<f", value)
    return bytes(data)


# bit positions per docs/robot_facts.md: 0 R1, 1 L1, 2 start, 3 select, 4 R2, 5 L2, 6 F1, 7 F2,
# 8 A, 9 B, 10 X, 11 Y, 12 up, 13 right, 14 down, 15 left
R1, L1, START, SELECT, A, B, X, RIGHT, LEFT = 1, 2, 4, 8, 1 << 8, 1 << 9, 1 << 10, 1 << 13, 1 << 15


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def no_slew():
    return MappingConfig.from_dict({"slew_rate": {"vx": None, "vy": None, "wz": None}}, "m",
                                   layout=LAYOUTS["unitree_remote"])


def test_decode_matches_the_documented_layout():
    reading = decode_wireless_remote(remote_bytes(A | L1 | (1 << 14), lx=0.25, rx=-0.5, ry=0.75, l2=1.0, ly=-1.0))
    assert reading.buttons == {"A", "L1", "down"}
    assert (reading.lx, reading.rx, reading.ry, reading.l2, reading.ly) == (0.25, -0.5, 0.75, 1.0, -1.0)
    for bit, name in enumerate(("R1", "L1", "start", "select", "R2", "L2", "F1", "F2",
                                "A", "B", "X", "Y", "up", "right", "down", "left")):
        assert decode_wireless_remote(remote_bytes(1 << bit)).buttons == {name}
    assert encode_wireless_remote({"A", "L1", "down"}, 0.25, -0.5, 0.75, 1.0, -1.0)[2:] == \
        remote_bytes(A | L1 | (1 << 14), 0.25, -0.5, 0.75, 1.0, -1.0)[2:]


def test_decode_rejects_wrong_length():
    with pytest.raises(RemoteDecodeError, match="wireless_remote has 39 bytes; expected 40"):
        decode_wireless_remote(bytes(39))
    with pytest.raises(RemoteDecodeError, match=r"unknown remote buttons \['Z'\]"):
        encode_wireless_remote({"Z"})


def test_sticks_follow_unitree_convention():
    clock = Clock()
    remote = UnitreeRemote(no_slew(), clock=clock)
    remote.feed(remote_bytes(ly=1.0, lx=-1.0, rx=1.0))
    cmd = remote.poll()
    # left stick forward -> +vx; left stick left (lx < 0) -> +vy; right stick right -> clockwise
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == pytest.approx((1.0, 1.0, -1.0))
    remote.feed(remote_bytes(ly=0.08, lx=-0.05))  # inside the 0.1 deadzone: stopped
    cmd = remote.poll()
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 0.0, 0.0)


def test_nan_and_out_of_range_floats_are_clamped_and_counted():
    remote = UnitreeRemote(no_slew(), clock=Clock())
    remote.feed(remote_bytes(ly=math.nan, lx=-3.0, rx=math.inf))
    cmd = remote.poll().validate()
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 1.0, 0.0)
    assert remote.stats.nan_axis_values == 2 and remote.stats.clamped_axis_values == 1


def test_default_buttons_and_estop_chord():
    clock = Clock()
    remote = UnitreeRemote(clock=clock)
    presses = [(START, {"start"}), (A, {"run"}), (B, {"stop"}), (SELECT, {"damp"}), (X, {"policy_switch"}),
               (RIGHT, {"style_next"}), (LEFT, {"style_prev"}), (L1 | R1, {"estop"})]
    for bits, expected in presses:
        remote.feed(remote_bytes(bits))
        assert remote.poll().buttons == expected, expected
        remote.feed(remote_bytes(bits))  # still held on the next sample: no repeat
        assert remote.poll().buttons == frozenset()
        remote.feed(remote_bytes(0))
        remote.poll()
    # walking at speed, then L1 then R1 within one poll: e-stop, velocity zero at once
    for _ in range(20):
        clock.t += 0.05
        remote.feed(remote_bytes(ly=1.0))
        remote.poll()
    assert remote.poll().vx_mps == pytest.approx(1.0)
    remote.feed(remote_bytes(L1, ly=1.0))
    remote.feed(remote_bytes(L1 | R1, ly=1.0))
    cmd = remote.poll()
    assert cmd.buttons == {"estop"} and cmd.vx_mps == 0.0


def test_pulls_robot_state_and_goes_lost_when_the_stream_stalls(caplog):
    clock = Clock()
    state = RobotState(tick=1, wireless_remote=remote_bytes(ly=1.0))
    remote = UnitreeRemote(no_slew(), state_source=lambda: state, stale_after_s=0.2, clock=clock)
    assert remote.poll().vx_mps == pytest.approx(1.0)
    for _ in range(3):  # the same tick again is not fresh data
        clock.t += 0.1
        cmd = remote.poll()
    assert remote.lost and "no remote data for 0.300 s" in remote.lost_reason
    assert cmd.buttons == {"damp"} and cmd.vx_mps == 0.0 and "lost" in caplog.text
    state.tick = 2  # the stream coming back does not un-lose the device
    assert remote.poll().buttons == {"damp"}


def test_fresh_ticks_keep_it_alive_and_malformed_bytes_do_not():
    clock = Clock()
    state = RobotState(tick=0, wireless_remote=remote_bytes())
    remote = UnitreeRemote(no_slew(), state_source=lambda: state, stale_after_s=0.2, clock=clock)
    for tick in range(1, 20):
        clock.t += 0.1
        state.tick = tick
        remote.poll()
    assert not remote.lost
    state.wireless_remote = b""  # a backend that reports no remote
    for tick in range(20, 24):
        clock.t += 0.1
        state.tick = tick
        remote.poll()
    assert remote.lost and remote.decode_errors >= 2 and "malformed" in remote.lost_reason


def test_source_failure_is_loss():
    def broken():
        raise ConnectionError("DDS participant closed")

    remote = UnitreeRemote(state_source=broken, clock=Clock())
    assert remote.poll().buttons == {"damp"}
    assert remote.lost_reason == "state source failed: ConnectionError: DDS participant closed"


def test_never_any_data_is_loss_after_the_stale_time():
    clock = Clock()
    remote = UnitreeRemote(state_source=lambda: None, stale_after_s=0.25, clock=clock)
    assert not remote.lost and remote.poll().vx_mps == 0.0
    clock.t = 0.3
    remote.poll()
    assert remote.lost


def test_wrong_mapping_or_stale_time_is_refused():
    from g1_control.errors import LaunchFileError

    with pytest.raises(LaunchFileError, match="UnitreeRemote needs a unitree_remote mapping, got one for a keyboard"):
        UnitreeRemote(MappingConfig.default("keyboard"))
    with pytest.raises(LaunchFileError, match="stale_after_s is -1; expected a positive number of seconds"):
        UnitreeRemote(stale_after_s=-1)
