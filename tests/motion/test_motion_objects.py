"""Objects a clip handles: shape distances, edits carry the track along, metrics check contacts."""

import numpy as np
import pytest

from g1_control.motion.clip import MotionClip
from g1_control.motion.edit import concatenate, slice_clip
from g1_control.motion.exceptions import InvalidClipError, MotionFormatError
from g1_control.motion.formats.clip_npz import read_clip_npz, write_clip_npz
from g1_control.motion.mirror import mirror
from g1_control.motion.objects import ObjectShape, ObjectTrack, read_obj_vertices
from g1_control.motion.resample import resample
from g1_control.retarget.metrics import compute_metrics, format_table, object_hand_distances, plot_metrics
from g1_control.robot import g1

BOX = ObjectShape.box("box", (0.2, 0.15, 0.1))


def test_box_distance_is_exact_over_faces_and_negative_inside():
    points = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, -0.25, 0.05], [0.0, 0.0, 0.35], [0.19, 0.0, 0.0]])
    np.testing.assert_allclose(BOX.signed_distance(points), [-0.1, 0.1, 0.1, 0.25, -0.01], atol=1e-12)


def test_hull_of_a_meshes_vertices_is_the_box(tmp_path):
    corners = np.array([[x, y, z] for x in (-0.2, 0.2) for y in (-0.15, 0.15) for z in (-0.1, 0.1)])
    inner = np.random.default_rng(0).uniform(-0.1, 0.1, (50, 3)) * [1.0, 0.7, 0.5]
    obj = tmp_path / "box.obj"
    obj.write_text("# test mesh\n" + "".join(f"v {x} {y} {z}\n" for x, y, z in np.vstack([corners, inner]))
                   + "f 1 2 3\n")
    hull = ObjectShape.from_points("box", read_obj_vertices(obj))
    probe = np.random.default_rng(1).uniform(-0.5, 0.5, (200, 3))
    inside_or_face = np.abs(probe).max(axis=1) < 0.5  # compare where the box formula is exact too
    faces = (np.abs(probe) <= [0.2, 0.15, 0.1]).sum(axis=1) >= 2
    pick = inside_or_face & faces
    np.testing.assert_allclose(hull.signed_distance(probe[pick]), BOX.signed_distance(probe[pick]), atol=1e-9)


def test_bad_meshes_are_refused_with_the_file_named(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 zero\n")
    with pytest.raises(MotionFormatError, match="bad.obj:1: vertex line"):
        read_obj_vertices(bad)
    with pytest.raises(MotionFormatError, match="span no volume"):
        ObjectShape.from_points("flat", np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]]))


def test_track_distance_follows_the_object_pose():
    yaw = np.pi / 2  # turned 90 degrees: the box's 0.2 m half-length now lies along world y
    track = ObjectTrack(BOX, [[1.0, 2.0, 0.5]], [[np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]])
    points = np.array([[[1.0, 2.0 + 0.25, 0.5], [1.0 + 0.25, 2.0, 0.5]]])
    np.testing.assert_allclose(track.distance(points), [[0.05, 0.10]], atol=1e-12)


def _clip_with_object(t: int = 40) -> MotionClip:
    """A standing G1 holding a box between its hands: each hand 3 cm outside a face, labelled in contact."""
    from g1_control.ik.configuration import Configuration
    from g1_control.robot import description

    root = np.tile([0.0, 0.0, g1.DEFAULT_PELVIS_HEIGHT_M], (t, 1))
    quat = np.tile([1.0, 0.0, 0.0, 0.0], (t, 1))
    joints = np.tile(g1.DEFAULT_Q_RAD, (t, 1))
    clip = MotionClip.from_joint_trajectory(30.0, root, quat, joints, source="hold")
    conf = Configuration(description.pinocchio_q(root[0], quat[0], joints[0]))
    left, right = (conf.frame_placement(conf.frame_id(f"{s}_rubber_hand")).translation for s in ("left", "right"))
    assert abs(left[0] - right[0]) < 1e-9 and abs(left[2] - right[2]) < 1e-9  # symmetric stance
    half_width = 0.5 * abs(left[1] - right[1]) - 0.03
    shape = ObjectShape.box("box", (0.1, half_width, 0.1))
    clip.object = ObjectTrack(shape, np.tile(0.5 * (left + right), (t, 1)), quat.copy(), np.ones((t, 2), dtype=bool))
    return clip.validate()


def test_metrics_count_kept_contacts_and_catch_a_lost_object():
    clip = _clip_with_object()
    dist = object_hand_distances(clip)
    np.testing.assert_allclose(dist, 0.03, atol=1e-6)  # the metric's hand points are the rubber-hand frames
    m = compute_metrics(clip)
    assert m.object_contact_frames == 2 * clip.num_frames and m.object_contacts_kept == m.object_contact_frames
    assert m.object_contact_preserved_fraction == 1.0 and m.passes()
    assert abs(m.max_object_gap_m - 0.03) < 1e-6 and m.max_object_penetration_m == 0.0
    lost = clip.copy()
    lost.object.pos_w_m[20:] += [0.0, 0.0, 0.3]  # the box rises out of the hands halfway through
    m = compute_metrics(lost)
    assert m.object_contacts_kept == 2 * 20 and m.object_contact_preserved_fraction == 0.5
    assert not m.passes()
    assert "50.0%" in format_table([m])


def test_clip_without_object_reports_none_and_a_dash():
    clip = _clip_with_object()
    clip.object = None
    m = compute_metrics(clip)
    assert m.object_contact_preserved_fraction is None and m.passes()
    assert format_table([m]).splitlines()[2].split()[-3:-1] == ["-", "-"]


def test_edits_carry_the_object_along(tmp_path):
    clip = _clip_with_object()
    path = tmp_path / "c.npz"
    write_clip_npz(clip, path)
    back = read_clip_npz(path)
    assert back.equals(clip) and back.object.shape.name == "box"
    assert mirror(mirror(clip)).equals(clip)
    mirrored = mirror(clip)
    np.testing.assert_allclose(object_hand_distances(mirrored), object_hand_distances(clip)[:, ::-1], atol=1e-9)
    part = slice_clip(clip, 5, 15)
    assert part.object.num_frames == 10
    np.testing.assert_array_equal(part.object.pos_w_m, clip.object.pos_w_m[5:15])
    joined = concatenate([part, part])
    assert joined.object.num_frames == 20
    np.testing.assert_allclose(object_hand_distances(joined), 0.03, atol=1e-6)  # moved with the second part
    slow = resample(clip, 60.0)
    assert slow.object.num_frames == slow.num_frames
    np.testing.assert_allclose(object_hand_distances(slow), 0.03, atol=1e-6)
    other = part.copy()
    other.object = None
    assert concatenate([part, other]).object is None


def test_object_track_of_the_wrong_length_is_refused():
    clip = _clip_with_object()
    clip.object = clip.object.take(slice(0, 10))
    with pytest.raises(InvalidClipError, match="object pos_w_m has shape"):
        clip.validate()


def test_plot_has_the_object_panel(tmp_path):
    out = plot_metrics(_clip_with_object(), tmp_path / "p.png")
    assert out.stat().st_size > 10_000


def test_top_height_and_support_follow_the_footprint():
    from g1_control.motion.objects import support_height

    step = ObjectShape.box("step", (0.2, 0.2, 0.15)).transformed(np.eye(3), np.array([1.0, 0.0, 0.15]))
    np.testing.assert_allclose(step.top_height(np.array([[1.0, 0.0], [1.19, 0.1], [1.3, 0.0]])), [0.3, 0.3, -np.inf])
    points = np.array([[1.0, 0.0, 0.31], [1.0, 0.0, 0.28], [1.0, 0.0, 0.05], [0.5, 0.0, 0.0]])
    np.testing.assert_allclose(support_height((step,), points, 0.0, reach_m=0.05), [0.3, 0.3, 0.0, 0.0])


def test_scene_penetration_is_counted_and_scenes_survive_edits(tmp_path):
    clip = _clip_with_object()
    clip.object = None
    foot = clip.body_pos_w_m[0, clip.body_index("left_ankle_roll_link")]
    clean = compute_metrics(clip)
    # a 10 cm plate under the left foot: its sole spheres (3.5 cm below the ankle frame) end up inside
    plate = ObjectShape.box("plate", (0.2, 0.1, 0.05)).transformed(np.eye(3), np.array([foot[0], foot[1], 0.05]))
    clip.scene = (plate,)
    m = compute_metrics(clip)
    assert m.penetration_fraction == 1.0 and m.max_penetration_m > 0.02 > clean.max_penetration_m
    path = tmp_path / "s.npz"
    write_clip_npz(clip, path)
    back = read_clip_npz(path)
    assert back.equals(clip) and back.scene[0].name == "plate"
    assert mirror(mirror(clip)).equals(clip)
    assert compute_metrics(mirror(clip)).max_penetration_m == pytest.approx(m.max_penetration_m, abs=1e-9)
    joined = concatenate([clip, clip])  # the second part starts where the first ended: same place here
    assert len(joined.scene) == 1
    assert resample(clip, 60.0).scene[0].equals(plate)
