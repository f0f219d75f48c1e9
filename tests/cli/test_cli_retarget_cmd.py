import numpy as np

from g1_control.cli.main import build_parser, main
from g1_control.motion.formats.clip_npz import read_clip_npz
from g1_control.motion.formats.g1_csv import read_g1_csv

BVH_HEADER = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
"""


def _lafan_like_bvh(path, frames=20):
    """A small LAFAN1-skeleton BVH (cm, y-up) of a person standing and raising the left arm."""
    tree = [  # name, parent, offset (cm)
        ("LeftUpLeg", "Hips", (10, -5, 0)), ("LeftLeg", "LeftUpLeg", (0, -42, 0)),
        ("LeftFoot", "LeftLeg", (0, -42, 0)), ("LeftToe", "LeftFoot", (0, -6, 14)),
        ("RightUpLeg", "Hips", (-10, -5, 0)), ("RightLeg", "RightUpLeg", (0, -42, 0)),
        ("RightFoot", "RightLeg", (0, -42, 0)), ("RightToe", "RightFoot", (0, -6, 14)),
        ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 12, 0)), ("Spine2", "Spine1", (0, 12, 0)),
        ("Neck", "Spine2", (0, 15, 0)), ("Head", "Neck", (0, 10, 0)),
        ("LeftShoulder", "Spine2", (5, 12, 0)), ("LeftArm", "LeftShoulder", (12, 0, 0)),
        ("LeftForeArm", "LeftArm", (27, 0, 0)), ("LeftHand", "LeftForeArm", (25, 0, 0)),
        ("RightShoulder", "Spine2", (-5, 12, 0)), ("RightArm", "RightShoulder", (-12, 0, 0)),
        ("RightForeArm", "RightArm", (-27, 0, 0)), ("RightHand", "RightForeArm", (-25, 0, 0)),
    ]
    children = {}
    for name, parent, off in tree:
        children.setdefault(parent, []).append((name, off))
    lines = [BVH_HEADER]

    def emit(name, depth):
        for child, off in children.get(name, []):
            pad = "  " * depth
            lines.append(f"{pad}JOINT {child}\n{pad}{{\n{pad}  OFFSET {off[0]} {off[1]} {off[2]}\n"
                         f"{pad}  CHANNELS 3 Zrotation Yrotation Xrotation\n")
            emit(child, depth + 1)
            lines.append(f"{pad}}}\n")

    emit("Hips", 1)
    lines.append("}\nMOTION\n")
    lines.append(f"Frames: {frames}\nFrame Time: 0.0333333\n")
    order = ["Hips"] + [n for n, _, _ in tree]
    # a pre-order walk gives the channel order
    walk = ["Hips"]

    def pre(name):
        for child, _ in children.get(name, []):
            walk.append(child)
            pre(child)

    pre("Hips")
    assert sorted(walk) == sorted(order)
    for k in range(frames):
        values = [0.0, 92.0, 0.0, 0.0, 0.0, 0.0]
        for name in walk[1:]:
            rot = [0.0, 0.0, 0.0]
            if name == "LeftArm":
                rot[0] = 60.0 * k / frames  # about BVH z: the arm (along +x) rises toward +y (up)
            values += rot
        lines.append(" ".join(f"{v:.4f}" for v in values) + "\n")
    path.write_text("".join(lines))


def test_help_explains_the_command(capsys):
    parser = build_parser()
    try:
        parser.parse_args(["retarget", "--help"])
    except SystemExit:
        pass
    out = capsys.readouterr().out
    assert "--jobs" in out and "BVH" in out and "failures" in out


def test_batch_goes_on_past_bad_files_and_lists_them(tmp_path, capsys):
    good_csv = tmp_path / "good.csv"
    rows = np.zeros((6, 36))
    rows[:, 2] = 0.79
    rows[:, 6] = 1.0
    good_csv.write_text("\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("1,2,3\n")
    bvh = tmp_path / "arm.bvh"
    _lafan_like_bvh(bvh)
    out = tmp_path / "out"
    rc = main(["retarget", str(good_csv), str(bad_csv), str(bvh), "-o", str(out), "--jobs", "1"])
    captured = capsys.readouterr()
    assert rc == 1
    assert "1 file(s) failed" in captured.err and "bad.csv: line 1 has 3 columns" in captured.err
    assert "good.csv" in captured.out and "arm.bvh" in captured.out
    converted = read_clip_npz(out / "good.npz")
    assert converted.num_frames == 6
    arm = read_clip_npz(out / "arm.npz")
    assert arm.num_frames == 20 and arm.fps == 30.0
    # the left arm rose: the G1 left hand ends higher than it started, the right hand did not move up
    hand = arm.body_index("left_wrist_yaw_link")
    other = arm.body_index("right_wrist_yaw_link")
    assert arm.body_pos_w_m[-1, hand, 2] - arm.body_pos_w_m[0, hand, 2] > 0.1
    assert abs(arm.body_pos_w_m[-1, other, 2] - arm.body_pos_w_m[0, other, 2]) < 0.05


def test_single_file_to_csv(tmp_path, capsys):
    bvh = tmp_path / "arm.bvh"
    _lafan_like_bvh(bvh, frames=8)
    rc = main(["retarget", str(bvh), "-o", str(tmp_path / "arm.csv"), "--fps", "50"])
    assert rc == 0
    clip = read_g1_csv(tmp_path / "arm.csv", fps=50.0)
    assert clip.num_frames == 12  # 7 frames at 30 fps = 0.233 s -> 12 frames at 50 fps
    assert "frames/s" in capsys.readouterr().out
