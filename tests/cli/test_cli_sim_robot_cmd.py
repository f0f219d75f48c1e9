"""g1 sim-robot's own refusals (before anything starts): --record needs MuJoCo's ground truth."""

from g1_control.cli.main import main


def test_record_without_mujoco_is_refused_saying_why(tmp_path, capsys):
    assert main(["sim-robot", "--physics", "mock", "--record", str(tmp_path / "truth.npz")]) == 2
    assert "g1 sim-robot: --record needs --physics mujoco (the ground truth is MuJoCo's)" in capsys.readouterr().err
    assert not (tmp_path / "truth.npz").exists()
