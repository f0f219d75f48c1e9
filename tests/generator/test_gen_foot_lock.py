"""Foot locking (generator/foot_lock.py) on hand-built gaps with known answers, and in the runtime."""

import numpy as np
import pytest

from g1_control.generator import evaluation as E
from g1_control.generator import features as F
from g1_control.generator.foot_lock import FootLockConfig, FootLockedInbetweener, end_given, feet_of, lock_feet
from g1_control.generator.runtime import InbetweeningGenerator, RuntimeConfig
from g1_control.generator.style_stats import StyleStats
from g1_control.robot import g1
from g1_control.types import Command, RobotState


def _standing_frame() -> np.ndarray:
    """The default pose with its soles on the floor (ankles at stance height), canonical frame."""
    frame = np.zeros(F.DIM)
    frame[3:9] = (1, 0, 0, 0, 1, 0)
    frame[F.JOINTS] = g1.DEFAULT_Q_RAD
    frame[2] = 0.8
    feet, _ = feet_of(frame[None])
    frame[2] += E.STANCE_ANKLE_Z_M - feet[0, :, 2].mean()
    return F.fix_effectors(frame[None])[0]


def _sliding_gap(gap: int = 30, amplitude_m: float = 0.05) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(context_last, gap frames, target): standing, and a gap whose root (and so both planted feet)
    slides forward and back by amplitude_m with the legs unchanged."""
    stand = _standing_frame()
    frames = np.repeat(stand[None], gap, axis=0)
    frames[:, 0] += amplitude_m * np.sin(np.pi * np.arange(1, gap + 1) / (gap + 1))
    return stand, F.fix_effectors(frames), stand


def test_planted_feet_of_a_sliding_gap_stay_where_they_stood():
    ctx, frames, target = _sliding_gap()
    before, _ = feet_of(frames[None])
    start = feet_of(ctx[None])[0][0]  # (2, 3)
    assert np.abs(before[0, :, :, 0] - start[None, :, 0]).max() > 0.045  # the generated feet slide 5 cm
    out = lock_feet(frames[None], ctx[None], target[None])[0]
    after = feet_of(out[None])[0][0]
    assert np.abs(after[:, :, :2] - start[None, :, :2]).max() < 2e-3  # held on their spot
    assert np.allclose(out[:, F.ROOT], frames[:, F.ROOT])  # the root is the plan's
    assert np.abs(out[:, 9:21] - frames[:, 9:21]).max() > 0.05  # the legs took the slide
    assert np.allclose(out[:, 21:38], frames[:, 21:38])  # waist and arms untouched
    for k, name in enumerate(g1.FOOT_BODIES):  # the foot effectors moved with the feet (to first order)
        assert np.abs(out[:, F.effector_slice(name)] - after[:, k]).max() < 5e-3
    speed = E.foot_quality(out[None], 30.0)[0]
    assert speed < 0.1 * E.foot_quality(frames[None], 30.0)[0]


def test_a_gap_with_no_foot_on_the_ground_is_returned_unchanged():
    ctx, frames, target = _sliding_gap()
    lifted = frames.copy()
    lifted[:, 2] += 0.2  # every ankle 20 cm above stance height
    ctx, target = ctx.copy(), target.copy()
    ctx[2] += 0.2
    target[2] += 0.2
    out = lock_feet(lifted[None], ctx[None], target[None])[0]
    assert np.allclose(out, lifted)


def test_a_stance_foot_through_the_floor_is_lifted_onto_it():
    ctx, frames, target = _sliding_gap(amplitude_m=0.0)
    sunk = frames.copy()
    sunk[10:20, 2] -= 0.02  # the root 2 cm lower: both ankles 2 cm under stance height
    out = lock_feet(sunk[None], ctx[None], target[None])[0]
    feet, _ = feet_of(out[None])
    assert feet[0, :, :, 2].min() > E.STANCE_ANKLE_Z_M - FootLockConfig().floor_tolerance_m - 1e-3
    assert E.foot_quality(out[None], 30.0)[1] == 0.0 < E.foot_quality(sunk[None], 30.0)[1]


def test_a_correction_beyond_the_reach_limit_is_scaled_down_to_it():
    ctx, frames, target = _sliding_gap(amplitude_m=0.3)
    out = lock_feet(frames[None], ctx[None], target[None], config=FootLockConfig(max_shift_m=0.05))[0]
    before, _ = feet_of(frames[None])
    after, _ = feet_of(out[None])
    moved = np.linalg.norm(after[0, :, :, :2] - before[0, :, :, :2], axis=-1)
    assert moved.max() == pytest.approx(0.05, abs=5e-3)


def test_the_end_frame_counts_only_when_the_target_gives_the_root_and_legs():
    mask = np.ones((3, F.DIM), dtype=bool)
    mask[1, 12] = False  # a leg joint not given
    mask[2, 0] = False  # the root's x not given
    assert end_given(mask).tolist() == [True, False, False]


def test_config_errors_name_the_field():
    with pytest.raises(ValueError, match="max_shift_m"):
        FootLockConfig(max_shift_m=float("nan"))
    with pytest.raises(ValueError, match="iterations"):
        FootLockConfig(iterations=0)


def test_the_wrapper_locks_what_its_inner_inbetweener_made():
    ctx, frames, target = _sliding_gap()

    class Sliding:
        name = "sliding"

        def infill(self, context, target, target_mask, gap, style):
            return frames[None].repeat(len(context), axis=0)

    ctx10 = np.repeat(ctx[None, None], 10, axis=1)
    locked = FootLockedInbetweener(Sliding()).infill(ctx10, target[None], np.ones((1, F.DIM), bool), 30,
                                                     np.zeros(1, int))
    assert E.foot_quality(locked, 30.0)[0] < 0.1 * E.foot_quality(frames[None], 30.0)[0]


class _SlidingInbetweener:
    """Stands still in every gap with the root (and so both planted feet) sliding 5 cm forward and
    back: a stand-in for a network whose planted feet slide."""

    name = "sliding"

    def infill(self, context, target, target_mask, gap, style):
        frames = np.repeat(context[:, -1:], gap, axis=1)
        frames[..., 0] += 0.05 * np.sin(np.pi * np.arange(1, gap + 1) / (gap + 1))
        return F.fix_effectors(frames)


def _plan_skate(foot_lock: bool) -> float:
    """Stance-foot speed of what the runtime generator executes standing for 3 s."""
    style = StyleStats("default", g1.DEFAULT_Q_RAD.copy(), (0.74, 0.76, 0.79))
    gen = InbetweeningGenerator(_SlidingInbetweener(), {"default": style}, RuntimeConfig(foot_lock=foot_lock))
    stand = _standing_frame()
    state = RobotState(q_rad=g1.DEFAULT_Q_RAD.copy(), base_pos_w_m=np.array([0.0, 0.0, stand[2]]))
    gen.reset(state)
    executed = []
    for i in range(150):
        state.t_s = i / 50
        gen.update(Command(), state)
        executed.append(gen.history[-1].copy())
    frames = np.array(executed)
    assert gen.stats.replans >= 2
    return E.foot_quality(frames[None], 50.0)[0]


def test_the_runtime_generator_holds_its_plans_stance_feet():
    free, held = _plan_skate(False), _plan_skate(True)
    assert free > 0.05
    assert held < 0.2 * free
