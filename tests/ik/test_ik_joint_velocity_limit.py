import numpy as np
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import JointVelocityLimit
from g1_control.robot import g1


def test_box_is_velocity_times_dt():
    conf = Configuration()
    box = JointVelocityLimit().compute(conf, 0.02)
    np.testing.assert_allclose(box.upper[6:], g1.VELOCITY_LIMIT_RADPS * 0.02)
    np.testing.assert_allclose(box.lower[6:], -g1.VELOCITY_LIMIT_RADPS * 0.02)


def test_anchor_counts_motion_already_made_in_the_tick():
    conf = Configuration()
    limit = JointVelocityLimit(scale=0.5)
    limit.set_anchor(conf.joint_q_rad.copy())
    moved = conf.q.copy()
    moved[7] += 0.1  # left hip pitch already moved 0.1 rad this tick
    conf.update(moved)
    box = limit.compute(conf, 0.01)
    reach = 0.5 * g1.VELOCITY_LIMIT_RADPS[0] * 0.01
    assert box.upper[6] == pytest.approx(reach - 0.1)
    assert box.lower[6] == pytest.approx(-reach - 0.1)


def test_bad_limits_are_refused():
    with pytest.raises(LimitDefinitionError, match="positive finite limits"):
        JointVelocityLimit(velocity_limit_radps=0.0)
    with pytest.raises(LimitDefinitionError, match="dt_s > 0"):
        JointVelocityLimit().compute(Configuration(), 0.0)
