"""The instruction corpus: exact program match, 100 % on the development part, >= 95 % held out."""

import math

import pytest
from corpus_dev import DEV
from corpus_heldout import HELD_OUT

from g1_control.program import InstructionError, Program, parse_instruction
from g1_control.program.steps import STEP_TYPES


def rounded(x):
    if isinstance(x, float):
        return round(x, 6)
    if isinstance(x, list):
        return [rounded(v) for v in x]
    if isinstance(x, dict):
        return {k: rounded(v) for k, v in x.items()}
    return x


def run_corpus(corpus):
    """[(text, expected, got)] for every entry that does not match (expected None: must be refused)."""
    failures = []
    for text, expected in corpus:
        try:
            got = rounded(parse_instruction(text).to_dict()["steps"])
        except InstructionError as exc:
            got = f"InstructionError: {exc}"
        ok = isinstance(got, str) if expected is None else got == rounded(expected)
        if not ok:
            failures.append((text, expected, got))
    return failures


def report(name, corpus, failures):
    rate = 1 - len(failures) / len(corpus)
    print(f"\n{name}: {len(corpus) - len(failures)}/{len(corpus)} exact ({rate:.1%})")
    for text, expected, got in failures:
        print(f"  FAIL {text!r}\n    expected {expected}\n    got      {got}")
    return rate


def test_corpus_size_and_split():
    texts = [t for t, _ in DEV + HELD_OUT]
    assert len(texts) >= 200
    assert len(HELD_OUT) >= 40
    assert len(set(texts)) == len(texts), "an instruction is in the corpus twice"


def test_expected_programs_are_valid_programs():
    """Every expectation is a program that validates and says the same thing back (ProgramError on a bad
    one; a field the program drops or changes shows as a difference)."""
    checked = 0
    for text, expected in DEV + HELD_OUT:
        if expected is not None:
            program = Program.from_dict(expected).validate()
            assert rounded(program.to_dict()["steps"]) == rounded(expected), text
            checked += 1
    assert checked >= 180


def _kinds(step):
    yield step["kind"]
    for key in ("main",):
        if key in step:
            yield from _kinds(step[key])
    for key in ("alongside", "steps"):
        for s in step.get(key, []):
            yield from _kinds(s)


def test_corpus_covers_every_primitive_and_connective():
    kinds = {k for _, exp in DEV + HELD_OUT if exp for s in exp for k in _kinds(s)}
    assert kinds == set(STEP_TYPES)
    words = " ".join(t.lower() for t, _ in DEV + HELD_OUT)
    for connective in (" then ", " and ", " while ", " after ", " before ", " until ", " twice", " times",
                       "and then", ",", ";", ". ", " as "):
        assert connective in words, connective


def test_development_part_matches_exactly():
    failures = run_corpus(DEV)
    report("development", DEV, failures)
    assert not failures, f"{len(failures)} development instructions do not match"


def test_held_out_part_matches_at_least_95_percent():
    failures = run_corpus(HELD_OUT)
    rate = report("held out", HELD_OUT, failures)
    assert rate >= 0.95, f"held-out exact match {rate:.1%} < 95 %"


@pytest.mark.parametrize("text,expected", [t for t in DEV if t[1] is not None][:3])
def test_parsed_programs_round_trip_through_dicts(text, expected):
    program = parse_instruction(text)
    again = Program.from_dict(program.to_dict())
    assert again.to_dict() == program.to_dict()
    assert again.source == text


def test_angles_are_radians():
    step = parse_instruction("turn right ninety degrees").steps[0]
    assert step.angle_rad == pytest.approx(math.pi / 2) and step.direction == "right"
