"""The library build gates every piece on `g1 check`'s acceptance figures: a piece that fails is
repaired through the IK (admitted only if it then passes) or left out with its mirror, and the
build and `g1 library show` say which and why (issue 23)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from g1_control.cli.main import main
from g1_control.library import builder
from g1_control.library.builder import LibraryConfig, build_library, gate_reasons
from g1_control.motion.clip import MotionClip
from g1_control.retarget.metrics import compute_metrics, failures

SUNK_FROM_S = 2.0
SUNK_M = 0.05


def _sunk(clip: MotionClip) -> MotionClip:
    """The same rollout with the whole robot 5 cm lower from SUNK_FROM_S on: feet in the floor."""
    root = clip.root_pos_w_m.copy()
    root[round(SUNK_FROM_S * clip.fps):, 2] -= SUNK_M
    return MotionClip.from_joint_trajectory(clip.fps, root, clip.root_quat_wxyz, clip.joint_pos_rad,
                                            source=clip.source, style=clip.style, tags=clip.tags)


@pytest.fixture(scope="module")
def rollout():
    """One short physics rollout of the walking policy (default style), shared by the builds below."""
    return builder.rollout_job(("default", 100, 5.0, 30.0))


@pytest.fixture(scope="module")
def libraries(rollout, tmp_path_factory):
    clip, info = rollout
    assert clip is not None
    patch = pytest.MonkeyPatch()
    patch.setattr(builder, "rollout_job", lambda task: (_sunk(clip), info))
    try:
        base = dict(rollout_seconds=5.0, rollouts_per_style=1, rollout_styles=("default",), dance=False, demo=False,
                    clip_seconds=1.0)
        gated = build_library(tmp_path_factory.mktemp("gated"), LibraryConfig(**base, repair=False), progress=False)
        open_ = build_library(tmp_path_factory.mktemp("open"), LibraryConfig(**base, gate=False), progress=False)
        repaired = build_library(tmp_path_factory.mktemp("repaired"), LibraryConfig(**base), progress=False)
    finally:
        patch.undo()
    return gated, open_, repaired


def test_pieces_that_fail_g1_check_are_left_out_with_their_mirrors_and_named(libraries, rollout):
    gated, _, _ = libraries
    source = rollout[0].source
    names = {e.name for e in gated.entries}
    assert names == {f"{source}_00", f"{source}_00_mirror", f"{source}_01", f"{source}_01_mirror"}
    left_out = gated.index["gate"]["left_out"]
    assert [e["name"] for e in left_out] == [f"{source}_02", f"{source}_03", f"{source}_04"]
    for e in left_out:
        assert any("of frames with a link > 1 cm inside the floor or the scene, up to" in r for r in e["reasons"]), e
    assert left_out[0]["split"] == "test"  # the held-out piece is left out too: it is not moved to train


def test_without_the_gate_every_piece_is_admitted(libraries):
    _, open_, _ = libraries
    assert len(open_.entries) == 10
    assert open_.index["gate"] == {"checked": False, "repair": True, "repaired": [], "left_out": []}


def test_the_admitted_pieces_pass_g1_check(libraries):
    gated, _, _ = libraries
    for entry in gated.entries:
        assert gate_reasons(gated.load(entry)) == []


def test_g1_library_show_says_which_and_why(libraries, capsys):
    gated, _, _ = libraries
    assert main(["library", "show", str(gated.root)]) == 0
    out = capsys.readouterr().out
    assert "library gate: 3 piece(s) left out (and their mirrors): they fail `g1 check`" in out
    assert "(default, test): 100% of frames with a link > 1 cm inside the floor or the scene, up to 5." in out


def test_g1_check_agrees_with_the_gate_on_a_left_out_piece(libraries, tmp_path):
    from g1_control.motion.formats.clip_npz import write_clip_npz

    gated, _, _ = libraries
    piece = gated.load(gated.entries[0])  # an admitted piece, sunk 5 cm as a whole
    whole = MotionClip.from_joint_trajectory(piece.fps, piece.root_pos_w_m - [0.0, 0.0, SUNK_M], piece.root_quat_wxyz,
                                             piece.joint_pos_rad, source="sunk", style=piece.style)
    write_clip_npz(whole, tmp_path / "sunk.npz")
    assert main(["check", str(tmp_path / "sunk.npz"), "--json", str(tmp_path / "report.json")]) == 1
    report = json.loads((tmp_path / "report.json").read_text())[0]
    assert report["passes"] is False and gate_reasons(whole)


def test_failures_name_exactly_the_figures_passes_checks(rollout):
    metrics = compute_metrics(rollout[0])
    assert metrics.passes() and failures(metrics) == []
    sunk = compute_metrics(_sunk(rollout[0]))
    assert not sunk.passes() and len(failures(sunk)) >= 1
    assert np.isclose(sunk.penetration_fraction, 1 - round(SUNK_FROM_S * 30) / rollout[0].num_frames, atol=0.02)


def test_with_the_repair_the_failing_pieces_come_back_through_the_ik_and_pass(libraries, rollout):
    _, _, repaired = libraries
    source = rollout[0].source
    assert len(repaired.entries) == 10 and repaired.index["gate"]["left_out"] == []
    records = repaired.index["gate"]["repaired"]
    assert [r["name"] for r in records] == [f"{source}_02", f"{source}_03", f"{source}_04"]
    assert all("inside the floor" in r["reasons"][0] and r["joint_deviation_mean_rad"] < 0.2 for r in records)
    for entry in repaired.entries:
        clip = repaired.load(entry)
        assert gate_reasons(clip) == [], entry.name
        if entry.name.removesuffix("_mirror").endswith(("_02", "_03", "_04")):
            assert "ik_repaired" in clip.tags
            feet = clip.body_pos_w_m[:, [clip.body_index(b) for b in ("left_ankle_roll_link", "right_ankle_roll_link")]]
            assert feet[..., 2].min() > 0.0, "lifted out of the floor (the ankle links sit ~4 cm above their soles)"


def test_g1_library_show_lists_the_repairs(libraries, capsys):
    _, _, repaired = libraries
    assert main(["library", "show", str(repaired.root)]) == 0
    out = capsys.readouterr().out
    assert "library gate: 3 piece(s) failed `g1 check` and were repaired through the IK (admitted, tagged ik_repaired)" \
        in out and "repaired: joints moved" in out


def test_the_dance_pieces_the_issue_names_are_repaired_or_left_out_by_measurement():
    """Real data: the WBT dance clip's 8 s pieces 3 (43 % of frames in the floor, 70 % sliding, 25
    self-collision frames) and 10 (the one the IK repair leaves at 3 % sliding)."""
    from g1_control.library.builder import cut, gate_piece
    from g1_control.library.dance import extract_dance

    pieces = cut(extract_dance(fps=30.0), 8.0)
    admitted, record = gate_piece(pieces[3])
    assert record["reasons"][0].startswith("43% of frames with a link > 1 cm inside the floor or the scene, up to 5.4 cm")
    assert admitted is not None and gate_reasons(admitted) == [] and "after_repair" not in record
    left, record = gate_piece(pieces[10])
    assert left is None and record["after_repair"] and "sliding" in record["after_repair"][0]
    assert gate_piece(pieces[0]) == (pieces[0], {})  # dance_00 passes as it is
