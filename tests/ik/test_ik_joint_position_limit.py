import numpy as np
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import INF, JointPositionLimit
from g1_control.robot import g1


def test_box_is_distance_to_each_limit_and_base_is_free():
    conf = Configuration()
    box = JointPositionLimit(margin_rad=0.01).compute(conf, 0.02)
    np.testing.assert_allclose(box.lower[6:], g1.Q_MIN_RAD + 0.01 - conf.joint_q_rad)
    np.testing.assert_allclose(box.upper[6:], g1.Q_MAX_RAD - 0.01 - conf.joint_q_rad)
    assert np.all(box.lower[:6] == -INF) and np.all(box.upper[:6] == INF)


def test_margin_larger_than_range_is_refused():
    with pytest.raises(LimitDefinitionError, match="q_max - q_min > 2 \\* margin"):
        JointPositionLimit(margin_rad=0.3)
