"""Dex3-1 facts (g1_control/robot/dex3.py) against the hand URDF read another way (pinocchio)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

from g1_control.robot import dex3


def _urdf() -> str:
    from g1_control.robot import description

    return str(description.description_dir() / dex3.HAND_URDF_RELATIVE)


def _pinocchio_hand():
    import pinocchio as pin

    return pin.buildModelFromUrdf(_urdf())


@pytest.mark.parametrize("side", dex3.SIDES)
def test_limits_and_order_are_the_urdfs(side):
    model = _pinocchio_hand()
    names = dex3.joint_names(side)
    file_order = [j.get("name") for j in ET.parse(_urdf()).getroot().iter("joint")
                  if j.get("name").startswith(f"{side}_hand_") and j.get("type") == "revolute"]
    assert list(names) == file_order  # message order = the joints' order in the URDF (thumb, middle, index)
    lim = dex3.hand_limits(side)
    for i, name in enumerate(names):
        jid = model.getJointId(name)
        idx = model.joints[jid].idx_q
        assert lim.q_min_rad[i] == pytest.approx(model.lowerPositionLimit[idx])
        assert lim.q_max_rad[i] == pytest.approx(model.upperPositionLimit[idx])
        assert lim.effort_nm[i] == pytest.approx(model.effortLimit[model.joints[jid].idx_v])
    assert lim.effort_nm[0] == pytest.approx(2.45) and np.all(lim.effort_nm[1:] == pytest.approx(1.4))


def test_hands_close_in_mirrored_directions():
    left, right = dex3.hand_limits("left"), dex3.hand_limits("right")
    np.testing.assert_array_equal(left.closing_sign, [0, 1, 1, -1, -1, -1, -1])
    np.testing.assert_array_equal(right.closing_sign, -left.closing_sign)
    np.testing.assert_allclose(left.closed_rad, [0, 1.0472, 1.7453, -1.5708, -1.7453, -1.5708, -1.7453], atol=1e-4)
    assert np.all((left.open_rad >= left.q_min_rad) & (left.open_rad <= left.q_max_rad))


def test_topics_and_bad_sides():
    assert dex3.cmd_topic("left") == "rt/dex3/left/cmd" and dex3.state_topic("right") == "rt/dex3/right/state"
    with pytest.raises(ValueError, match="hand side must be 'left' or 'right'; got 'middle'"):
        dex3.joint_names("middle")  # type: ignore[arg-type]
