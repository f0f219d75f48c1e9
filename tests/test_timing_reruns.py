"""The suite's rerun of `timing` tests that failed on this host's timing (tests/conftest.py): the
failures CI has printed match HOST_TIMING_FAILURES, a failure of the code does not, and a run of
pytest reruns only what matches, only `timing` tests, and fails what keeps failing."""

from __future__ import annotations

import re

import pytest

from tests.conftest import HOST_TIMING_FAILURES, TIMING_RERUNS
from tests.paths import REPO

pytest_plugins = ["pytester"]

HOST_TIMING = [
    # stop 40's CI, as pytest-rerunfailures matches them ("<exception type>: <message>")
    "AssertionError: 10 deadline overruns within 1.0 s (13 ms late)\nassert ('publisher' in '10 deadline",
    "PreflightRefused: preflight failed (state_stream, motion_service): nothing was sent to the robot; fix them",
    "PreflightRefused: preflight failed (state_stream): nothing was sent to the robot",
    "AssertionError: no line matching 'hold -> control' within 60 s; got:\n[   1.20 s] ramp -> damping: stale_state: "
    "newest state is 272.7 ms old (limit 250 ms)",
]
THE_CODE = [
    "AssertionError: the deploy ended as planned (control time over) with a second publisher",
    "PreflightRefused: preflight failed (joint_limits): nothing was sent to the robot",
    "PreflightRefused: preflight failed (state_stream, joint_limits): nothing was sent to the robot",
    "AssertionError: [  24.14 s] control -> damping: fall: pelvis at 0.31 m (limit 0.40)",
    "AssertionError: RobotState.mode_machine changed from 5 to 4 (another DoF variant, or a second publisher)",
]


@pytest.mark.parametrize("text", HOST_TIMING)
def test_host_timing_failures_match(text):
    assert any(re.search(p, text) for p in HOST_TIMING_FAILURES), text


@pytest.mark.parametrize("text", THE_CODE)
def test_failures_of_the_code_do_not_match(text):
    assert not any(re.search(p, text) for p in HOST_TIMING_FAILURES), text


def test_only_timing_tests_failing_on_host_timing_are_rerun(pytester):
    pytester.makeconftest(f"import sys\nsys.path.insert(0, {str(REPO)!r})\n"
                          "from tests.conftest import pytest_collection_modifyitems  # noqa: F401\n")
    pytester.makeini("[pytest]\nmarkers =\n    timing: t\n")
    pytester.makepyfile(test_probe="""
        import pytest

        runs = {"late_once": 0}

        @pytest.mark.timing
        def test_late_once():
            runs["late_once"] += 1
            assert runs["late_once"] > 1, "10 deadline overruns within 1.0 s (13 ms late)"

        @pytest.mark.timing
        def test_always_late():
            assert False, "10 deadline overruns within 1.0 s (13 ms late)"

        @pytest.mark.timing
        def test_wrong():
            assert False, "the deploy ended as planned"

        def test_late_but_not_timing():
            assert False, "10 deadline overruns within 1.0 s (13 ms late)"
    """)
    result = pytester.runpytest_subprocess("-q", "-rR")
    outcomes = result.parseoutcomes()
    assert (outcomes.get("passed"), outcomes.get("failed"), outcomes.get("rerun")) == (1, 3, 1 + TIMING_RERUNS), \
        result.stdout.str()[-2000:]
