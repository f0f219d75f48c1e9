"""The parser's refusals: one clear error, naming the word and the closest known words."""

import pytest

from g1_control.program import InstructionError, InstructionParser, UnknownWordError, parse_instruction


def test_unknown_word_names_it_and_the_closest_known_words():
    with pytest.raises(UnknownWordError) as info:
        parse_instruction("wlak forward two meters")
    assert str(info.value) == "unknown word 'wlak' in \"wlak forward two meters\"; closest known words: walk, walks"
    assert info.value.word == "wlak" and info.value.suggestions == ("walk", "walks")


def test_unknown_word_in_a_long_instruction_quotes_its_neighbourhood():
    with pytest.raises(UnknownWordError) as info:
        parse_instruction("walk forward 2 meters, turn left, and then walk to the tabel while waving")
    # punctuation stays attached in the quote
    with pytest.raises(UnknownWordError, match=r"in \"\.\.\. forward 2 meters, trun left\";"):
        parse_instruction("walk forward 2 meters, trun left")
    with pytest.raises(UnknownWordError) as info:
        parse_instruction("walk forward 2 meters, turn left, and then walk to the tabel while waving")
    assert str(info.value) == ("unknown word 'tabel' in \"... then walk to the tabel while waving\"; "
                               "closest known words: table, travel, take")


def test_unknown_word_with_nothing_close():
    with pytest.raises(UnknownWordError, match=r"^unknown word 'jump' in \"jump forward 1 meter\"; "
                                               r"no known word is close$"):
        parse_instruction("jump forward 1 meter")


def test_only_the_first_unknown_word_is_reported():
    with pytest.raises(UnknownWordError) as info:
        parse_instruction("trun lfet")
    assert info.value.word == "trun"


def test_filler_words_are_ignored():
    assert parse_instruction("robot, please just walk forward the two meters now").to_dict()["steps"] == \
        [{"kind": "walk", "distance_m": 2.0}]


def test_a_place_the_world_does_not_have_is_an_unknown_word():
    parser = InstructionParser.for_places(["crate", "bench"])
    assert parser.parse("pick up the crate and put it on the bench").to_dict()["steps"] == [
        {"kind": "pick", "object": "crate"}, {"kind": "place", "object": "crate", "target": "bench"}]
    with pytest.raises(UnknownWordError, match="'table' in \"walk to the table\" is not a place here; places: "
                       "bench, crate, start") as err:
        parser.parse("walk to the table")
    assert err.value.word == "table" and err.value.suggestions == ("bench", "crate", "start")


@pytest.mark.parametrize("text,message", [
    ("walk forward", "\"walk forward\" needs a distance (\"2 meters\"), a duration (\"for 3 seconds\") or a place "
                     "(\"to the table\")"),
    ("turn", "\"turn\": turn which way? (left, right, around, to a heading or to face a place)"),
    ("pick up", "\"pick up\": pick up what? e.g. \"pick up the box\""),
    ("put it on the table", "\"it\" does not refer to anything yet; name the object"),
    ("walk forward 2 meters for 3 seconds",
     "\"walk forward 2 meters for 3 seconds\": a walk goes a distance, for a time or to a place, not two of them"),
    ("wave while dancing", "\"wave while dancing\": 'while' needs a walk, turn or wait on one side"),
    ("walk forward 2 meters with your left hand", "could not use \"with your left hand\" in "
                                                  "\"walk forward 2 meters with your left hand\""),
    ("turn left 2 meters", "could not use \"2 meters\" in \"turn left 2 meters\""),
    ("turn left 1.5 times", "\"1.5 times\": a count must be a whole number >= 1"),
    ("", "empty instruction: say what to do, e.g. \"walk forward two meters\""),
    ("please", "no action in \"please\": say what to do, e.g. \"walk forward two meters\""),
])
def test_grammar_errors_say_what_is_missing(text, message):
    with pytest.raises(InstructionError) as info:
        parse_instruction(text)
    assert str(info.value) == message


NEGATIVE = ("a negative quantity; durations, distances, angles and counts are sizes; say the direction in words "
            "instead, e.g. \"walk backward 2 meters\", \"turn right 90 degrees\"")


@pytest.mark.parametrize("text, quantity", [
    ("walk forward for -3 seconds", "-3 seconds"),
    ("walk forward -2 meters", "-2 meters"),
    ("turn left -90°", "-90°"),
    ("turn left \u22121.5 turns", "\u22121.5 turns"),
    ("wave -2 times", "-2 times"),
    ("walk forward -.5 m then wave", "-.5 m"),
])
def test_a_negative_quantity_is_refused_naming_it(text, quantity):
    with pytest.raises(InstructionError) as info:
        parse_instruction(text)
    assert str(info.value) == f"\"{quantity}\": {NEGATIVE}"


def test_hyphens_that_join_words_are_no_sign():
    assert parse_instruction("turn left ninety-degrees").describe() == parse_instruction("turn left 90 degrees").describe()
    assert parse_instruction("walk forward 2 meters, then turn left 90 degrees").describe() == \
        parse_instruction("walk forward 2 meters -- then turn left 90 degrees").describe()


def test_values_the_program_refuses_are_refused_at_parse_time():
    with pytest.raises(InstructionError, match=r"pelvis_height_m: must be within \[0.3, 0.9\] m; got 2"):
        parse_instruction("lower your pelvis to 2 meters")
