import numpy as np
import pytest

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import LimitDefinitionError
from g1_control.ik.limits import BaseVelocityLimit


def test_base_box_shrinks_by_the_displacement_since_the_anchor():
    conf = Configuration()
    limit = BaseVelocityLimit(max_linear_mps=1.0, max_angular_radps=2.0)
    limit.set_anchor(conf.q)
    moved = conf.q.copy()
    moved[0] += 0.005
    conf.update(moved)
    box = limit.compute(conf, 0.01)
    assert box.upper[0] == pytest.approx(0.01 - 0.005)
    assert box.lower[0] == pytest.approx(-0.01 - 0.005)
    np.testing.assert_allclose(box.upper[3:6], 0.02)


def test_nonpositive_limits_are_refused():
    with pytest.raises(LimitDefinitionError, match="positive limits"):
        BaseVelocityLimit(max_linear_mps=0.0)
