"""The evdev gamepad driven by kernel-format event bytes through a named pipe and a file."""

import errno
import os

import pytest

from g1_control.errors import InputDeviceError, LaunchFileError
from g1_control.teleop import evdev_protocol as ev
from g1_control.teleop.gamepad import EvdevGamepad, find_gamepads
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapping import MappingConfig
from g1_control.types import CommandLimits


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


@pytest.fixture
def fifo(tmp_path):
    """A named pipe: the gamepad opens the read end by path, the test writes kernel events."""
    path = tmp_path / "event0"
    os.mkfifo(path)
    reader_opened = []

    def open_pad(**kwargs):
        pad = EvdevGamepad(str(path), clock=kwargs.pop("clock", Clock()), **kwargs)
        reader_opened.append(pad)
        return pad

    yield path, open_pad
    for pad in reader_opened:
        pad.close()


def writer(path):
    return os.open(path, os.O_WRONLY | os.O_NONBLOCK)


def frame(*events):
    return b"".join(ev.pack_event(*e) for e in events) + ev.syn_report()


def no_slew():
    """Default gamepad mapping without slew and without the speed trigger (full speed)."""
    return MappingConfig.from_dict({"slew_rate": {"vx": None, "vy": None, "wz": None}, "axes": {"speed_scale": None}},
                                   "m", layout=LAYOUTS["gamepad"])


def test_event_size_is_the_kernels():
    assert ev.EVENT_SIZE == (24 if ev.struct.calcsize("l") == 8 else 16)


def test_sticks_deadzone_and_release_through_a_pipe(fifo):
    path, open_pad = fifo
    pad = open_pad(mapping=no_slew())
    w = writer(path)
    assert pad.poll().vx_mps == 0.0
    # left stick fully up (evdev: negative Y is up) -> full forward
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -32768)))
    cmd = pad.poll()
    assert cmd.vx_mps == pytest.approx(1.0, abs=1e-4) and cmd.vy_mps == 0.0
    # inside the 10 % deadzone: stop
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -3000), (ev.EV_ABS, ev.ABS_X, 3000)))
    cmd = pad.poll()
    assert (cmd.vx_mps, cmd.vy_mps) == (0.0, 0.0)
    # right stick right -> turn clockwise (negative wz)
    os.write(w, frame((ev.EV_ABS, ev.ABS_RX, 32767)))
    assert pad.poll().wz_radps == pytest.approx(-1.0, abs=1e-4)
    os.close(w)


def test_changes_apply_only_at_syn_report_and_partial_events_wait(fifo):
    path, open_pad = fifo
    pad = open_pad(mapping=no_slew())
    w = writer(path)
    event = ev.pack_event(ev.EV_ABS, ev.ABS_Y, -32768)
    os.write(w, event[:10])
    assert pad.poll().vx_mps == 0.0
    os.write(w, event[10:])
    assert pad.poll().vx_mps == 0.0  # whole event, but its frame is not closed yet
    os.write(w, ev.syn_report())
    assert pad.poll().vx_mps == pytest.approx(1.0, abs=1e-4)
    os.close(w)


def test_slew_rate_on_the_gamepad(fifo):
    path, open_pad = fifo
    clock = Clock()
    pad = open_pad(clock=clock)  # default mapping: vx slews at 1 m/s^2, speed trigger released = 0.5
    w = writer(path)
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -32768)))
    speeds = []
    for _ in range(12):
        speeds.append(pad.poll().vx_mps)
        clock.t += 0.1
    assert speeds[0] == 0.0 and speeds[1] == pytest.approx(0.1) and speeds[3] == pytest.approx(0.3)
    assert speeds[-1] == pytest.approx(0.5, abs=1e-4)  # capped by the released speed trigger
    os.close(w)


def test_buttons_chords_dpad_and_estop(fifo):
    path, open_pad = fifo
    clock = Clock()
    pad = open_pad(clock=clock)
    w = writer(path)
    os.write(w, frame((ev.EV_KEY, ev.BTN_SOUTH, 1)))
    assert pad.poll().buttons == {"run"}
    os.write(w, frame((ev.EV_KEY, ev.BTN_SOUTH, 2)))  # auto-repeat: not a new press
    assert pad.poll().buttons == frozenset()
    os.write(w, frame((ev.EV_KEY, ev.BTN_SOUTH, 0)))
    os.write(w, frame((ev.EV_ABS, ev.ABS_HAT0X, 1)))
    assert pad.poll().buttons == {"style_next"}
    os.write(w, frame((ev.EV_ABS, ev.ABS_HAT0X, 0)))
    # a quick tap of B, pressed and released between two polls
    os.write(w, frame((ev.EV_KEY, ev.BTN_EAST, 1)) + frame((ev.EV_KEY, ev.BTN_EAST, 0)))
    assert pad.poll().buttons == {"stop"}
    # drive forward, then the LB+RB e-stop zeroes velocity at once
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -32768)))
    for _ in range(10):
        clock.t += 0.1
        pad.poll()
    assert pad.poll().vx_mps > 0.4
    os.write(w, frame((ev.EV_KEY, ev.BTN_TL, 1), (ev.EV_KEY, ev.BTN_TR, 1)))
    cmd = pad.poll()
    assert cmd.buttons == {"estop"} and cmd.vx_mps == 0.0
    os.close(w)


def test_syn_dropped_discards_the_frame_and_resets_to_rest(fifo):
    path, open_pad = fifo
    pad = open_pad(mapping=no_slew())
    w = writer(path)
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -32768), (ev.EV_KEY, ev.BTN_NORTH, 1)))
    cmd = pad.poll()
    assert cmd.vx_mps > 0.9 and cmd.buttons == {"policy_switch"}
    os.write(w, ev.pack_event(ev.EV_SYN, ev.SYN_DROPPED, 0)
             + frame((ev.EV_ABS, ev.ABS_X, 32767)))  # the frame after a drop is discarded
    cmd = pad.poll()
    # a pipe cannot be asked for the true state: the safe guess is everything at rest
    assert (cmd.vx_mps, cmd.vy_mps) == (0.0, 0.0) and pad.dropped_frames == 1
    os.write(w, frame((ev.EV_ABS, ev.ABS_X, -32768)))
    assert pad.poll().vy_mps == pytest.approx(1.0, abs=1e-4)  # back to normal after the drop
    os.close(w)


def test_writer_closing_is_device_loss(fifo, caplog):
    path, open_pad = fifo
    pad = open_pad(mapping=no_slew())
    w = writer(path)
    os.write(w, frame((ev.EV_ABS, ev.ABS_Y, -32768)))
    assert pad.poll().vx_mps > 0.9 and not pad.lost
    os.close(w)
    cmd = pad.poll()
    assert pad.lost and "end of stream" in pad.lost_reason
    assert cmd.buttons == {"damp"} and (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 0.0, 0.0)
    assert "lost" in caplog.text
    assert pad.poll().buttons == {"damp"}  # stays lost, every poll


def test_enodev_read_is_device_loss(fifo):
    path, open_pad = fifo
    pad = open_pad()
    w = writer(path)

    def unplugged(fd, n):  # what read() on an evdev node returns once the pad is pulled out
        raise OSError(errno.ENODEV, os.strerror(errno.ENODEV))

    pad._read_bytes = unplugged
    cmd = pad.poll()
    assert pad.lost and "ENODEV" in pad.lost_reason and cmd.buttons == {"damp"}
    os.close(w)


def test_recorded_event_file_replays_without_loss(tmp_path):
    path = tmp_path / "recorded.events"
    path.write_bytes(frame((ev.EV_ABS, ev.ABS_X, 32767), (ev.EV_KEY, ev.BTN_START, 1)))
    with EvdevGamepad(str(path), no_slew(), CommandLimits(vy_mps=(-0.3, 0.3)), clock=Clock()) as pad:
        cmd = pad.poll()
        assert cmd.vy_mps == pytest.approx(-0.3, abs=1e-4) and cmd.buttons == {"start"}
        assert not pad.lost and pad.poll().vy_mps == pytest.approx(-0.3, abs=1e-4)


def test_custom_codes_and_ranges(tmp_path):
    path = tmp_path / "pad.events"
    path.write_bytes(frame((ev.EV_ABS, ev.ABS_BRAKE, 255), (ev.EV_KEY, ev.BTN_C, 1)))
    pad = EvdevGamepad(str(path), no_slew(), axis_codes={"left_trigger": ev.ABS_BRAKE},
                       axis_ranges={"left_trigger": [0, 255]}, button_codes={"A": ev.BTN_C}, clock=Clock())
    cmd = pad.poll()
    assert cmd.pelvis_height_m == pytest.approx(CommandLimits().pelvis_height_m[0]) and cmd.buttons == {"run"}
    pad.close()
    with pytest.raises(LaunchFileError, match=r"input.button_codes.Q is not a gamepad name"):
        EvdevGamepad(str(path), button_codes={"Q": 1})
    with pytest.raises(LaunchFileError, match=r"input.button_codes: two names share one evdev code"):
        EvdevGamepad(str(path), button_codes={"A": ev.BTN_EAST})
    with pytest.raises(LaunchFileError, match=r"input.axis_ranges.left_x is \[5, 5\]; expected \[minimum, maximum\]"):
        EvdevGamepad(str(path), axis_ranges={"left_x": [5, 5]})


def test_open_errors_are_clear(tmp_path):
    with pytest.raises(InputDeviceError, match=r"input.path: gamepad device '/dev/input/event99' does not exist"):
        EvdevGamepad("/dev/input/event99")
    with pytest.raises(InputDeviceError, match=r"'/dev/null' is not an evdev device"):
        EvdevGamepad("/dev/null")
    with pytest.raises(InputDeviceError, match=r"is not a device, pipe or event file"):
        EvdevGamepad(str(tmp_path))
    locked = tmp_path / "locked"
    locked.write_bytes(b"")
    locked.chmod(0)
    if os.geteuid() != 0:  # root reads anything; the message is checked where the check can bite
        with pytest.raises(InputDeviceError, match="'input' group"):
            EvdevGamepad(str(locked))


def test_find_gamepads_ignores_what_is_not_evdev(tmp_path):
    (tmp_path / "event0").write_bytes(b"")
    os.mkfifo(tmp_path / "event1")
    assert find_gamepads(str(tmp_path)) == []


# -- the evdev-node path: ioctls answered by a stand-in for the kernel's evdev driver ----------
def test_ioctl_numbers_match_the_kernel_headers():
    # values of the macros in linux/input.h on x86_64 / aarch64
    assert ev.EVIOCGVERSION == 0x80044501
    assert ev.EVIOCGABS(ev.ABS_X) == 0x80184540
    assert ev.EVIOCGKEY(96) == 0x80604518
    assert ev.EVIOCGBIT(ev.EV_ABS, 8) == 0x80084523


class FakeEvdevDriver:
    """Answers the evdev ioctls for one fd the way the kernel does for an xpad pad."""

    def __init__(self, real_ioctl):
        self.real_ioctl = real_ioctl
        self.fd = None
        self.abs = {ev.ABS_X: [0, -32768, 32767], ev.ABS_Y: [0, -32768, 32767],
                    ev.ABS_RX: [0, -32768, 32767], ev.ABS_RY: [0, -32768, 32767],
                    ev.ABS_Z: [0, 0, 255], ev.ABS_RZ: [0, 0, 255], ev.ABS_HAT0X: [0, -1, 1], ev.ABS_HAT0Y: [0, -1, 1]}
        self.keys_down = set()

    def __call__(self, fd, request, buf, mutate=True):
        if fd != self.fd:
            return self.real_ioctl(fd, request, buf, mutate)
        nr, size = request & 0xFF, (request >> 16) & 0x3FFF
        if nr == 0x01:
            buf[:4] = ev.struct.pack("i", 0x010001)
        elif 0x40 <= nr < 0x80 and (nr - 0x40) in self.abs:
            value, lo, hi = self.abs[nr - 0x40]
            buf[:size] = ev.struct.pack(ev.ABSINFO_FORMAT, value, lo, hi, 16, 128, 0)
        elif nr == 0x18:
            bits = bytearray(size)
            for code in self.keys_down:
                bits[code // 8] |= 1 << (code % 8)
            buf[:size] = bits
        else:
            raise OSError(errno.EINVAL, "unsupported")
        return 0


@pytest.fixture
def evdev_node(monkeypatch):
    """A gamepad on a character device whose ioctls the fake driver answers and whose events come
    from a pipe (the one piece of the kernel a test cannot create without /dev/uinput)."""
    driver = FakeEvdevDriver(ev.fcntl.ioctl)
    monkeypatch.setattr(ev.fcntl, "ioctl", driver)
    real_open = os.open

    def open_records_fd(path, flags, *args):
        fd = real_open(path, flags, *args)
        if path == "/dev/null":
            driver.fd = fd
        return fd

    monkeypatch.setattr("g1_control.teleop.gamepad.os.open", open_records_fd)
    read_end, write_end = os.pipe()
    os.set_blocking(read_end, False)
    yield driver, lambda pad: setattr(pad, "_read_bytes", lambda fd, n: os.read(read_end, n)), write_end
    os.close(read_end)
    os.close(write_end)


def test_evdev_node_ranges_initial_state_and_resync(evdev_node):
    driver, route, write_end = evdev_node
    driver.abs[ev.ABS_Y][0] = -32768  # the stick is already pushed forward when teleop starts
    driver.keys_down = {ev.BTN_NORTH}
    pad = EvdevGamepad("/dev/null", no_slew(), clock=Clock())
    route(pad)
    assert pad._ranges["left_trigger"] == (0, 255)  # asked from the device, not the xpad default
    cmd = pad.poll()
    assert cmd.vx_mps == pytest.approx(1.0, abs=1e-4) and cmd.buttons == {"policy_switch"}
    os.write(write_end, frame((ev.EV_ABS, ev.ABS_Z, 255)))
    assert pad.poll().pelvis_height_m == pytest.approx(CommandLimits().pelvis_height_m[0])
    # events are lost in the kernel buffer; the driver's state now has LB+RB held, stick centred
    driver.abs[ev.ABS_Y][0] = 0
    driver.abs[ev.ABS_Z][0] = 0
    driver.keys_down = {ev.BTN_TL, ev.BTN_TR}
    os.write(write_end, ev.pack_event(ev.EV_SYN, ev.SYN_DROPPED, 0) + frame((ev.EV_ABS, ev.ABS_X, 32767)))
    cmd = pad.poll()
    assert cmd.buttons == {"estop"} and (cmd.vx_mps, cmd.vy_mps) == (0.0, 0.0)
    assert cmd.pelvis_height_m == pytest.approx(CommandLimits().pelvis_height_m[1])
    pad.close()

