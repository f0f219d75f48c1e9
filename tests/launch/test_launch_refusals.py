"""Launch files that used to pass `--check` are refused with one line naming the key."""

from __future__ import annotations

import pytest

from g1_control.errors import LaunchFileError
from g1_control.launch.schema import load_launch

BASE = """name: t
input:
  type: scripted
  timeline:
    - {duration_s: 1.0, vx_mps: 0.3}
"""

CASES = {
    "lowlevel_zero": (BASE + "rates: {lowlevel_hz: 0}\n", "rates.lowlevel_hz: 0"),
    "unknown_style": (BASE.replace("vx_mps: 0.3}", "vx_mps: 0.3, style: moonwalk}"),
                      "input.timeline[0].style: unknown style 'moonwalk'"),
    "duplicate_key": (BASE + "name: u\n", "duplicate key 'name'"),
    "negative_limit": (BASE + "limits: {max_vx_mps: -1.0}\n", "limits.max_vx_mps: -1.0"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_launch_file_is_refused_with_one_line_naming_the_key(tmp_path, case):
    text, expected = CASES[case]
    path = tmp_path / f"{case}.yaml"
    path.write_text(text)
    with pytest.raises(LaunchFileError) as info:
        load_launch(path)
    message = str(info.value)
    assert expected in message and "\n" not in message, message


def test_binary_junk_is_refused_without_a_traceback(tmp_path):
    path = tmp_path / "junk.yaml"
    path.write_bytes(bytes(range(256)) * 4)
    with pytest.raises(LaunchFileError, match="not a UTF-8 text file"):
        load_launch(path)
