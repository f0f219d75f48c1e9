"""The third held-out set (corpus_everyday.py, issue 27): instructions in the words people use.

Written and committed before the parser was changed for it; its first score is the blind figure
(g1_control/program/README.md). Run with -s to see the score and every miss."""

from corpus_everyday import EVERYDAY
from test_program_corpus import report, run_corpus

from g1_control.program import Program

BLIND_SCORE = 58 / 118
"""Exact matches of the parser as it was when the set was written (the floor this test guards)."""


def test_everyday_set_is_large_enough_unique_and_valid():
    assert len(EVERYDAY) >= 100
    assert len({t for t, _ in EVERYDAY}) == len(EVERYDAY)
    for _text, expected in EVERYDAY:
        if expected is not None:
            Program.from_dict(expected)


def test_everyday_set_score_never_drops():
    failures = run_corpus(EVERYDAY)
    rate = report("everyday (third held-out set)", EVERYDAY, failures)
    assert rate >= BLIND_SCORE, f"everyday exact match {rate:.1%} < {BLIND_SCORE:.1%}"
