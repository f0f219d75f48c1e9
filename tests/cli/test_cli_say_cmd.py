"""`g1 say`: the program printed (--dry-run), refused words named, a short run judged by ground truth."""

import json

from g1_control.cli.main import main


def test_dry_run_prints_the_program_only(capsys, tmp_path):
    out_json = tmp_path / "program.json"
    rc = main(["say", "walk forward two meters, then turn left ninety degrees and wave while walking back 1 m",
               "--dry-run", "--json", str(out_json)])
    out = capsys.readouterr().out
    assert rc == 0
    assert "1. walk forward 2 m\n2. turn left 90 deg\n3. walk backward 1 m, while: wave" in out
    assert "running" not in out
    assert json.loads(out_json.read_text())["steps"][0] == {"kind": "walk", "distance_m": 2.0}


def test_an_unknown_word_is_named_with_the_closest_known_ones(capsys):
    rc = main(["say", "wlak forward 2 meters", "--dry-run"])
    err = capsys.readouterr().err
    assert rc == 1 and "unknown word 'wlak'" in err and "walk" in err


def test_places_the_launch_file_does_not_have_are_refused_before_running(capsys):
    # a place word the parser knows, but not in the scene g1 say picks for it (sim_scene_program)
    rc = main(["say", "walk to the chair"])
    captured = capsys.readouterr()
    assert rc == 1 and "'chair' in \"walk to the chair\" is not a place here; places: box, door" in captured.err
    assert "running" not in captured.out


def test_say_runs_in_mujoco_and_prints_each_steps_outcome(capsys, tmp_path):
    rc = main(["say", "turn left 45 degrees, then wait one second", "--no-video", "--out", str(tmp_path),
               "--json", str(tmp_path / "say.json")])
    out = capsys.readouterr().out
    assert rc == 0, out
    assert "1. turn left 45 deg: completed" in out and "ground truth: turned" in out and "OK" in out
    assert "2. stand still for 1 s: completed" in out
    assert "no fall" in out and "2/2 met by ground truth" in out
    saved = json.loads((tmp_path / "say.json").read_text())
    assert saved["finished"] and not saved["fell"] and len(saved["steps"]) == 2
