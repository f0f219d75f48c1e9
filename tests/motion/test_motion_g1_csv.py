import numpy as np
import pytest
from test_motion_clip import make_clip

from g1_control.motion.exceptions import MotionFormatError
from g1_control.motion.formats.g1_csv import read_g1_csv, write_g1_csv


def _write_rows(path, rows):
    path.write_text("\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")


def _unitree_like_rows(t=12, seed=0):
    rng = np.random.default_rng(seed)
    rows = np.zeros((t, 36))
    rows[:, :3] = [0.1, -0.2, 0.79] + 0.01 * rng.standard_normal((t, 3))
    quat = rng.standard_normal((t, 4)) * 0.05 + [0.0, 0.0, 0.0, 1.0]
    rows[:, 3:7] = quat / np.linalg.norm(quat, axis=1, keepdims=True)  # x y z w
    rows[:, 7:] = rng.uniform(-0.2, 0.2, (t, 29))
    return rows


def test_csv_to_clip_to_csv_is_exact(tmp_path):
    src = tmp_path / "walk.csv"
    rows = _unitree_like_rows()
    # Unitree's files carry ~6-7 significant digits: write them that way
    src.write_text("\n".join(",".join(f"{v:.6f}" for v in r) for r in rows) + "\n")
    clip = read_g1_csv(src)
    out = tmp_path / "again.csv"
    write_g1_csv(clip, out)
    a = np.loadtxt(src, delimiter=",")
    b = np.loadtxt(out, delimiter=",")
    assert np.array_equal(a, b)  # bit for bit
    again = read_g1_csv(out)
    assert again.equals(clip.__class__(**{**clip.__dict__, "source": "again.csv"}))


def test_quaternion_order_is_xyzw_in_the_file(tmp_path):
    rows = _unitree_like_rows(t=3)
    _write_rows(tmp_path / "q.csv", rows)
    clip = read_g1_csv(tmp_path / "q.csv")
    np.testing.assert_array_equal(clip.root_quat_wxyz, rows[:, [6, 3, 4, 5]])
    np.testing.assert_array_equal(clip.joint_pos_rad, rows[:, 7:])


def test_wrong_column_count_names_file_and_line(tmp_path):
    rows = _unitree_like_rows(t=3)
    path = tmp_path / "short.csv"
    text = [",".join(repr(float(v)) for v in r) for r in rows]
    text[1] = ",".join(text[1].split(",")[:30])
    path.write_text("\n".join(text) + "\n")
    with pytest.raises(MotionFormatError, match=r"short.csv: line 2 has 30 columns; a G1 CSV has 36"):
        read_g1_csv(path)


def test_nan_and_empty_files_are_named(tmp_path):
    rows = _unitree_like_rows(t=4)
    rows[2, 10] = np.nan
    _write_rows(tmp_path / "nan.csv", rows)
    with pytest.raises(MotionFormatError, match="nan.csv: frame 2 .* NaN"):
        read_g1_csv(tmp_path / "nan.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(MotionFormatError, match="empty.csv: no frames"):
        read_g1_csv(tmp_path / "empty.csv")


def test_clip_written_as_csv_reads_back_equal(tmp_path):
    clip = make_clip()
    write_g1_csv(clip, tmp_path / "c.csv")
    back = read_g1_csv(tmp_path / "c.csv", fps=clip.fps)
    np.testing.assert_array_equal(back.joint_pos_rad, clip.joint_pos_rad)
    np.testing.assert_array_equal(back.root_quat_wxyz, clip.root_quat_wxyz)
