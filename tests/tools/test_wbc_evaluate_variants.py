"""`python -m g1_control.tools.wbc_evaluate --variant g1_23dof`: the WBC figures on the 23-DoF G1."""

from __future__ import annotations

import json

from g1_control.tools.wbc_evaluate import evaluation_launch, main


def test_the_evaluation_runs_on_the_variant_it_is_given(tmp_path, capsys):
    assert evaluation_launch("crouch", variant="g1_23dof").backend.expected_variant == "g1_23dof"
    assert main(["crouch", "--variant", "g1_23dof", "--json", str(tmp_path / "f.json")]) == 0
    row = json.loads((tmp_path / "f.json").read_text())[0]
    assert row["reference"] == "crouch@23dof" and not row["fell"]
    assert row["pelvis_height_rms_m"] < 0.01 and row["joint_rms_rad"] < 0.02  # the 15 cm crouch followed
    assert "crouch@23dof" in capsys.readouterr().out
