"""The malformed-file corpus (tests/launch/corpus/, >= 50 files): every malformed launch file, policy spec and
motion clip is refused with its loader's own error class and exactly its one-line message naming what
is wrong (tests/launch/corpus/expected.yaml), never a traceback from deeper down. The exact text is asserted:
it is what the operator reads (and a mutation run checks every branch and its words)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from g1_control import errors
from g1_control.launch.schema import load_launch
from g1_control.motion import exceptions as motion_errors
from g1_control.motion.formats.dispatch import load_motion
from g1_control.trackers.policy_spec import load_spec
from tests.paths import REPO

CACHE = str(Path.home() / ".cache" / "g1-control")

CORPUS = REPO / "tests" / "launch" / "corpus"
EXPECTED = yaml.safe_load((CORPUS / "expected.yaml").read_text())
LOADERS = {"launch": load_launch, "policy": load_spec, "clip": load_motion}
CASES = [(kind, name) for kind in LOADERS for name in sorted(EXPECTED[kind])]


def test_the_corpus_is_complete_and_large_enough():
    on_disk = {(kind, p.name) for kind in LOADERS for p in (CORPUS / kind).iterdir()}
    assert on_disk == set(CASES), "every corpus file has an expected message and vice versa"
    assert len(CASES) >= 50
    assert all(sum(k == kind for k, _ in CASES) >= 15 for kind in LOADERS)


@pytest.mark.parametrize(("kind", "name"), CASES, ids=[f"{k}/{n}" for k, n in CASES])
def test_malformed_file_is_refused_with_its_message(kind, name):
    expected = EXPECTED[kind][name]
    error = getattr(errors, expected["error"], None) or getattr(motion_errors, expected["error"])
    with pytest.raises(error) as info:
        LOADERS[kind](CORPUS / kind / name)
    path = CORPUS / kind / name
    message = str(info.value).replace(str(path), "{file}").replace(str(CORPUS), "{corpus}").replace(CACHE, "{cache}")
    assert message == expected["message"]
    assert "\n" not in message, "one line"
