"""MappingConfig validation and the CommandMapper's shaping, slew, limits, chords and counters."""

import math

import pytest

from g1_control.errors import LaunchFileError
from g1_control.teleop.layouts import LAYOUTS
from g1_control.teleop.mapper import CommandMapper
from g1_control.teleop.mapping import AxisBinding, MappingConfig
from g1_control.teleop.snapshot import InputSnapshot
from g1_control.types import CommandLimits

GAMEPAD = LAYOUTS["gamepad"]
REMOTE = LAYOUTS["unitree_remote"]
KEYBOARD = LAYOUTS["keyboard"]


def mapping(d=None, layout=REMOTE):
    return MappingConfig.from_dict(d, "input.mapping", layout=layout)


def no_slew(layout=REMOTE, **extra):
    return mapping({"slew_rate": {"vx": None, "vy": None, "wz": None}, **extra}, layout)


# -- validation -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "d, message",
    [
        ({"buttons": {"Z": "run"}}, "input.mapping.buttons.Z: 'Z' is not a button of a unitree_remote"),
        ({"buttons": {"A": ["run", "start"]}}, "input.mapping.buttons.A: two actions bound to one button"),
        ({"buttons": {"L1+R1": "estop", "R1+L1": "damp"}},
         "input.mapping.buttons.R1+L1: two actions bound to one button: 'L1+R1' is already 'estop'"),
        ({"buttons": {"A": "jump"}}, "input.mapping.buttons.A is 'jump', not an action"),
        ({"buttons": {"A+A": "run"}}, "chord 'A+A' names a button twice"),
        ({"buttons": ["A"]}, "input.mapping.buttons is list; expected a mapping"),
        ({"axes": {"vx": {"axis": "stick_left"}}}, "input.mapping.axes.vx.axis is 'stick_left', not an axis of a unitree_remote"),
        ({"axes": {"vx": {"axis": "ly", "deadzone": "small"}}}, "input.mapping.axes.vx.deadzone is 'small'; expected a finite number"),
        ({"axes": {"vx": {"axis": "ly", "deadzone": 1.0}}}, "input.mapping.axes.vx.deadzone is 1.0; expected < 1.0"),
        ({"axes": {"vx": {"axis": "ly", "expo": 2}}}, "input.mapping.axes.vx.expo is 2.0; expected <= 1.0"),
        ({"axes": {"vx": {"axis": "ly", "invert": "yes"}}}, "input.mapping.axes.vx.invert is 'yes'; expected true or false"),
        ({"axes": {"vx": {"axis": "ly", "gain": 2}}}, "input.mapping.axes.vx.gain is not an axis setting"),
        ({"axes": {"vz": {"axis": "ly"}}}, "input.mapping.axes.vz: 'vz' is not a command field"),
        ({"axes": {"speed_scale": {"axis": "lx"}}}, "input.mapping.axes.speed_scale.axis: speed_scale needs a trigger but 'lx' is a stick"),
        ({"slew_rate": {"vx": -1}}, "input.mapping.slew_rate.vx is -1.0; expected > 0.0"),
        ({"slew_rate": {"pelvis": 1}}, "input.mapping.slew_rate.pelvis is not a slewed field"),
        ({"yaw_mode": "spin"}, "input.mapping.yaw_mode is 'spin'; expected one of rate, heading"),
        ({"styles": []}, "input.mapping.styles is []; expected a non-empty list"),
        ({"speed_scale_range": [0.9, 0.2]}, "input.mapping.speed_scale_range is [0.9, 0.2]; expected low <= high"),
        ({"key_axes": {"w": ["forward", 0.1]}}, "input.mapping.key_axes: only a keyboard has key_axes"),
        ({"deadzones": {}}, "input.mapping.deadzones is not a mapping section"),
    ],
)
def test_bad_mapping_names_the_key_path(d, message):
    with pytest.raises(LaunchFileError) as err:
        mapping(d)
    assert message in str(err.value)


def test_keyboard_validation():
    with pytest.raises(LaunchFileError, match=r"buttons\.W: 'W' is not a button of a keyboard \(keys are named in lower case: 'w'\)"):
        mapping({"buttons": {"W": "run"}}, KEYBOARD)
    with pytest.raises(LaunchFileError, match=r"key_axes\.w\[1\] is 0; a key that moves nothing"):
        mapping({"key_axes": {"w": ["forward", 0]}}, KEYBOARD)
    with pytest.raises(LaunchFileError, match=r"key_axes\.w: key 'w' is also bound to 'run'"):
        mapping({"buttons": {"w": "run"}}, KEYBOARD)
    # '+' is a key on a keyboard, not a chord separator
    assert frozenset({"+"}) in mapping({"buttons": {"+": "style_next"}}, KEYBOARD).buttons


def test_sections_merge_and_replace():
    m = mapping({"axes": {"wz": None, "vx": {"axis": "ry"}}, "buttons": {"Y": "estop"}})
    assert "wz" not in m.axes and m.axes["vx"] == AxisBinding("ry") and m.axes["vy"].axis == "lx"
    # buttons replace the default section: no default binding lingers
    assert m.buttons == {frozenset({"Y"}): "estop"}


def test_default_mappings_are_valid_and_have_the_safety_buttons():
    for kind in LAYOUTS:
        actions = set(MappingConfig.default(kind).buttons.values())
        assert {"estop", "damp", "start", "stop", "run"} <= actions, kind


# -- shaping ---------------------------------------------------------------------------------
def test_deadzone_and_expo_are_continuous():
    b = AxisBinding("ly", deadzone=0.1, expo=0.5)
    assert b.shape(0.1) == 0.0 and b.shape(-0.05) == 0.0
    assert b.shape(1.0) == pytest.approx(1.0) and b.shape(-1.0) == pytest.approx(-1.0)
    assert 0 < b.shape(0.1001) < 1e-3
    x = (0.55 - 0.1) / 0.9
    assert b.shape(0.55) == pytest.approx(0.5 * x + 0.5 * x**3)
    assert AxisBinding("lx", invert=True).shape(0.3) == pytest.approx(-0.3)


def test_sticks_scale_to_each_limit_and_release_stops():
    limits = CommandLimits(vx_mps=(-0.5, 1.0), vy_mps=(-0.4, 0.4), wz_radps=(-1.2, 1.2))
    mapper = CommandMapper(no_slew(), limits)
    cmd = mapper.update(InputSnapshot(axes={"ly": 1.0, "lx": 1.0, "rx": -1.0}), 0.0)
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == pytest.approx((1.0, -0.4, 1.2))
    assert mapper.update(InputSnapshot(axes={"ly": -1.0}), 0.01).vx_mps == pytest.approx(-0.5)
    released = mapper.update(InputSnapshot(axes={"ly": 0.05, "lx": -0.08, "rx": 0.0}), 0.02)
    assert (released.vx_mps, released.vy_mps, released.wz_radps) == (0.0, 0.0, 0.0)


def test_slew_rate_limits_change_and_release_ramps_to_exact_zero():
    mapper = CommandMapper(mapping({"slew_rate": {"vx": 2.0}}), CommandLimits())
    assert mapper.update(InputSnapshot(axes={"ly": 1.0}), 0.0).vx_mps == 0.0  # first poll: dt = 0
    assert mapper.update(InputSnapshot(axes={"ly": 1.0}), 0.1).vx_mps == pytest.approx(0.2)
    assert mapper.update(InputSnapshot(axes={"ly": 1.0}), 0.3).vx_mps == pytest.approx(0.6)
    assert mapper.update(InputSnapshot(axes={"ly": 1.0}), 1.0).vx_mps == pytest.approx(1.0)
    assert mapper.update(InputSnapshot(axes={}), 1.25).vx_mps == pytest.approx(0.5)
    assert mapper.update(InputSnapshot(axes={}), 2.0).vx_mps == 0.0


def test_estop_bypasses_slew_and_zeroes_at_once():
    mapper = CommandMapper(mapping({"slew_rate": {"vx": 0.5}}), CommandLimits())
    t = 0.0
    for _ in range(30):
        cmd = mapper.update(InputSnapshot(axes={"ly": 1.0}), t)
        t += 0.1
    assert cmd.vx_mps > 0.9
    cmd = mapper.update(InputSnapshot(axes={"ly": 1.0}, held=frozenset({"L1", "R1"})), t)
    assert cmd.buttons == {"estop"} and cmd.vx_mps == 0.0
    # still held: the edge is not repeated, and slew starts again from zero
    cmd = mapper.update(InputSnapshot(axes={"ly": 1.0}, held=frozenset({"L1", "R1"})), t + 0.1)
    assert cmd.buttons == frozenset() and cmd.vx_mps == pytest.approx(0.05)


def test_nan_and_out_of_range_axes_are_clamped_and_counted():
    mapper = CommandMapper(no_slew(), CommandLimits())
    cmd = mapper.update(InputSnapshot(axes={"ly": math.nan, "lx": 7.0, "rx": -math.inf}), 0.0)
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, -1.0, 0.0)
    assert mapper.stats.nan_axis_values == 2 and mapper.stats.clamped_axis_values == 1
    cmd.validate()


def test_chords_fire_once_and_the_larger_chord_wins():
    m = mapping({"buttons": {"L1": "style_next", "L1+R1": "estop", "A": "run", "L1+A": "policy_switch"}})
    mapper = CommandMapper(m)
    press = lambda held, t, pressed=(): mapper.update(InputSnapshot(held=frozenset(held), pressed=pressed), t)
    assert press({"L1", "R1"}, 0.0).buttons == {"estop"}  # together: only the chord
    assert press(set(), 0.1).buttons == frozenset()
    assert press({"L1"}, 0.2).buttons == {"style_next"}
    assert press({"L1", "A"}, 0.3).buttons == {"policy_switch"}  # not 'run'
    assert press({"A"}, 0.4).buttons == frozenset()  # releasing L1 is no new press
    assert press(set(), 0.5).buttons == frozenset()
    assert press(set(), 0.6, pressed=("A",)).buttons == {"run"}  # a tap between polls still counts


def test_style_cycles_and_heading_integrates():
    m = no_slew(styles=["walk", "march", "sneak"], yaw_mode="heading",
                buttons={"right": "style_next", "left": "style_prev"})
    mapper = CommandMapper(m, CommandLimits(wz_radps=(-1.0, 1.0)))
    assert mapper.update(InputSnapshot(), 0.0).style == "walk"
    assert mapper.update(InputSnapshot(pressed=("left",)), 0.0).style == "sneak"
    assert mapper.update(InputSnapshot(pressed=("right",)), 0.0).style == "walk"
    t, cmd = 0.0, None
    for _ in range(100):
        t += 0.01
        cmd = mapper.update(InputSnapshot(axes={"rx": -1.0}), t)
    assert cmd.heading_rad == pytest.approx(1.0) and cmd.wz_radps == pytest.approx(1.0)
    for _ in range(300):
        t += 0.01
        cmd = mapper.update(InputSnapshot(axes={"rx": -1.0}), t)
    assert cmd.heading_rad == pytest.approx(4.0 - 2 * math.pi)  # wrapped to [-pi, pi]


def test_speed_trigger_and_pelvis_height():
    limits = CommandLimits(pelvis_height_m=(0.6, 0.8))
    mapper = CommandMapper(no_slew(GAMEPAD), limits)
    released = mapper.update(InputSnapshot(axes={"left_y": -1.0}), 0.0)
    assert released.vx_mps == pytest.approx(0.5) and released.pelvis_height_m == pytest.approx(0.8)
    pulled = mapper.update(InputSnapshot(axes={"left_y": -1.0, "right_trigger": 1.0, "left_trigger": 1.0}), 0.01)
    assert pulled.vx_mps == pytest.approx(1.0) and pulled.pelvis_height_m == pytest.approx(0.6)


def test_a_trigger_past_its_range_crouches_no_lower_than_the_limit():
    """The pelvis height is not clipped after shaping, so the clamp on the raw axis is what keeps a
    trigger reading 1.5 (a miscalibrated pad) from crouching below limits.pelvis_height_m."""
    mapper = CommandMapper(no_slew(GAMEPAD), CommandLimits(pelvis_height_m=(0.6, 0.8)))
    cmd = mapper.update(InputSnapshot(axes={"left_trigger": 1.5}), 0.0)
    assert cmd.pelvis_height_m == pytest.approx(0.6) and mapper.stats.clamped_axis_values == 1


def test_keyboard_keys_step_virtual_axes_and_space_stops():
    mapper = CommandMapper(no_slew(KEYBOARD), CommandLimits())
    cmd = mapper.update(InputSnapshot(pressed=("w", "w", "w", "a", "e")), 0.0)
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == pytest.approx((0.3, 0.1, -0.1))
    assert mapper.update(InputSnapshot(), 0.5).vx_mps == pytest.approx(0.3)  # no releases: it holds
    cmd = mapper.update(InputSnapshot(pressed=("space",)), 0.6)
    assert (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 0.0, 0.0) and cmd.buttons == frozenset()
    for _ in range(30):
        cmd = mapper.update(InputSnapshot(pressed=("s",)), 0.7)
    assert cmd.vx_mps == pytest.approx(-1.0)  # saturates at full travel


def test_lost_command_is_damp_and_zero():
    mapper = CommandMapper(no_slew(), CommandLimits())
    mapper.update(InputSnapshot(axes={"ly": 1.0}), 0.0)
    cmd = mapper.lost_command()
    assert cmd.buttons == {"damp"} and (cmd.vx_mps, cmd.vy_mps, cmd.wz_radps) == (0.0, 0.0, 0.0)


# -- limits ----------------------------------------------------------------------------------
HOLOSOMA_META = {"command_ranges": '{"lin_vel_x": [-1.0, 1.0], "lin_vel_y": [-1.0, 1.0], '
                                   '"ang_vel_yaw": [-1.0, 1.0], "heading": [-3.14, 3.14]}'}


def test_limits_from_tracker_metadata():
    limits = CommandLimits.from_tracker_metadata(HOLOSOMA_META)
    assert limits.vx_mps == (-1.0, 1.0) and limits.wz_radps == (-1.0, 1.0)
    narrow = CommandLimits.from_tracker_metadata({"command_ranges": {"lin_vel_x": [-0.3, 0.6]}})
    assert narrow.vx_mps == (-0.3, 0.6) and narrow.vy_mps == (-1.0, 1.0)
    with pytest.raises(LaunchFileError, match="has no 'command_ranges'"):
        CommandLimits.from_tracker_metadata({})
    with pytest.raises(LaunchFileError, match=r"command_ranges.lin_vel_x is \[1, -1\]; expected finite low <= high"):
        CommandLimits.from_tracker_metadata({"command_ranges": {"lin_vel_x": [1, -1]}})
    with pytest.raises(LaunchFileError, match=r"CommandLimits.vx_mps is \(0.2, 1.0\); the range must contain 0"):
        CommandLimits(vx_mps=(0.2, 1.0))
    with pytest.raises(LaunchFileError, match=r"limits.vz is not a command limit"):
        CommandLimits.from_dict({"vz": [0, 1]}, "limits")
