"""A scripted gamepad sequence through a FIFO into the real evdev reader and mapping."""

import pytest

from g1_control.errors import LaunchFileError
from g1_control.teleop.gamepad import EvdevGamepad
from g1_control.teleop.gamepad_script import GamepadScriptFeeder, parse_gamepad_script
from g1_control.types import CommandLimits

SCRIPT = [
    {"t_s": 0.5, "press": ["start"]},
    {"t_s": 0.6, "release": ["start"]},
    {"t_s": 1.0, "press": "A"},
    {"t_s": 1.1, "release": "A"},
    {"t_s": 1.5, "axes": {"left_y": -1.0, "right_trigger": 1.0}},
    {"t_s": 4.0, "axes": {"left_y": 0.0}, "press": ["dpad_right"]},
    {"t_s": 4.1, "release": ["dpad_right"]},
    {"t_s": 6.0, "press": ["LB", "RB"]},
]


class SimClock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_script_drives_the_gamepad_in_sim_time():
    clock = SimClock()
    steps = parse_gamepad_script(SCRIPT, "session.gamepad_script")
    with GamepadScriptFeeder(steps) as feeder:
        pad = EvdevGamepad(feeder.path, limits=CommandLimits(vx_mps=(-0.6, 0.8)), clock=clock)
        log = {}
        for tick in range(700):  # 7 s at 100 Hz
            clock.t = tick / 100
            feeder.advance(clock.t)
            cmd = pad.poll()
            for button in cmd.buttons:
                log.setdefault(button, clock.t)
            log[round(clock.t, 2)] = cmd.vx_mps
        assert feeder.done
        assert log["start"] == pytest.approx(0.5) and log["run"] == pytest.approx(1.0)
        assert log["style_next"] == pytest.approx(4.0) and log["estop"] == pytest.approx(6.0)
        # default slew 1 m/s^2: the first step is taken in the tick the stick moves
        assert log[1.49] == 0.0 and log[1.5] == pytest.approx(0.01) and log[2.0] == pytest.approx(0.51)
        assert log[3.9] == pytest.approx(0.8, abs=1e-3)  # full stick, full trigger: the limit
        assert log[4.5] == pytest.approx(0.29, abs=1e-3) and log[5.0] == 0.0  # released: ramps to 0
        feeder.unplug()
        assert pad.poll().buttons == {"damp"} and pad.lost
        pad.close()


@pytest.mark.parametrize(
    "steps, message",
    [
        ([], "session.script is list; expected a non-empty list of steps"),
        ([{"t_s": 1.0}, {"t_s": 0.5}], "session.script[1].t_s is 0.5, before the previous step's 1.0"),
        ([{"t_s": 0, "axes": {"left_y": 2}}], "session.script[0].axes.left_y is 2; expected a number in [-1, 1]"),
        ([{"t_s": 0, "axes": {"left_trigger": -0.5}}], "axes.left_trigger is -0.5; expected a number in [0, 1]"),
        ([{"t_s": 0, "press": ["Z"]}], "session.script[0].press: 'Z' is not a gamepad button"),
        ([{"t_s": 0, "press": ["A"], "release": ["A"]}], "['A'] both pressed and released in one step"),
        ([{"t_s": 0, "hold": ["A"]}], "session.script[0].hold is not a step field"),
        ([{"at": 0}], "session.script[0].at is not a step field"),
        ([{"t_s": -1}], "session.script[0].t_s is -1; expected a time in seconds >= 0"),
    ],
)
def test_bad_script(steps, message):
    with pytest.raises(LaunchFileError) as err:
        parse_gamepad_script(steps, "session.script")
    assert message in str(err.value)
