import numpy as np
import pytest

from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.formats.bvh import read_bvh

BVH = """HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Spine
  {
    OFFSET 0.0 10.0 0.0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0.0 5.0 0.0
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 10.0 0.0 0.0
    CHANNELS 3 Zrotation Yrotation Xrotation
    JOINT LeftLeg
    {
      OFFSET 0.0 -40.0 0.0
      CHANNELS 3 Zrotation Yrotation Xrotation
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 0 0 0 0 0 0 0 0 0
100 90 0 90 0 0 0 0 0 0 0 0 90 0 0
"""


def test_positions_units_axes_and_rotation_order(tmp_path):
    path = tmp_path / "tiny.bvh"
    path.write_text(BVH)
    motion = read_bvh(path)  # cm -> m, y-up -> z-up
    assert motion.joint_names == ("Hips", "Spine", "LeftUpLeg", "LeftLeg")
    assert motion.fps == pytest.approx(30.0, rel=1e-5)
    p = motion.positions_w_m
    # frame 0: hips 0.9 m up, spine 0.1 m above, left hip 0.1 m along +x, knee 0.4 m below the hip
    np.testing.assert_allclose(p[0, 0], [0, 0, 0.9], atol=1e-12)
    np.testing.assert_allclose(p[0, 1], [0, 0, 1.0], atol=1e-12)
    np.testing.assert_allclose(p[0, 3], [0.1, 0, 0.5], atol=1e-12)
    # frame 1: root turned 90 deg about (BVH) z, hip bent 90 deg about z: knee swings to +x of the hip
    np.testing.assert_allclose(p[1, 0], [1.0, 0, 0.9], atol=1e-12)
    np.testing.assert_allclose(p[1, 2], [1.0, 0.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(p[1, 3], [1.4, 0.0, 1.0], atol=1e-9)


def test_missing_channels_are_named(tmp_path):
    path = tmp_path / "nochan.bvh"
    path.write_text(BVH.replace("    CHANNELS 3 Zrotation Yrotation Xrotation\n    End", "    End"))
    with pytest.raises(MotionFormatError, match="joint 'Spine' has 0 rotation channels; expected 3"):
        read_bvh(path)
    path.write_text(BVH.replace("0 90 0 0 0 0 0 0 0 0 0 0 0 0 0\n", "0 90 0 0 0 0 0 0 0 0 0 0\n"))
    with pytest.raises(MotionFormatError, match="frame 0 has 12 values; the hierarchy declares 15 channels"):
        read_bvh(path)


def test_nan_and_frame_count(tmp_path):
    path = tmp_path / "bad.bvh"
    path.write_text(BVH.replace("100 90 0 90", "100 nan 0 90"))
    with pytest.raises(MotionFormatError, match="bad.bvh: frame 1 contains NaN"):
        read_bvh(path)
    path.write_text(BVH.replace("Frames: 2", "Frames: 3"))
    with pytest.raises(MotionFormatError, match="header says 3 frames but the file has 2"):
        read_bvh(path)
    path.write_text(BVH.replace("Frames: 2", "Frames: 0"))
    with pytest.raises(MotionFormatError, match="zero frames"):
        read_bvh(path)
