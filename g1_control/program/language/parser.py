"""English instruction -> behaviour Program, by rules (no model).

Stages, each a single pass over the words:
1. words: lower case, split into words, numbers and punctuation; every word must be known
   (else UnknownWordError naming it and the closest known words, by rapidfuzz);
2. fillers dropped ("please", "the", "robot", ...);
3. numbers and units: "two", "1.5", "one and a half", "a couple of", "half a", "ninety degrees",
   "30 cm", "0.3 meters per second", "3 times" -> quantities in SI units and counts;
4. phrases -> canonical tokens, longest first ("pick up" -> PICK, "other table" -> a place);
5. sentences (". ; ! ?") -> clauses (", then and afterwards next finally"), "after"/"before"
   reorder clauses, "while"/"as" join two parts of a clause into a Parallel step;
6. each clause's words are sorted into slots (verb, direction, quantities, places, hand, speed,
   count, styles) and the verb builds its step; a word that no slot of that verb takes is an error.

Stages 1-5 are the grammar (grammar.py), stage 6 the step building (build.py); this module runs
them in order and validates the Program. See g1_control/program/README.md for the grammar and the
conventions it fills in.
"""

from __future__ import annotations

from g1_control.program.exceptions import InstructionError, ProgramError
from g1_control.program.language import lexicon as L
from g1_control.program.language.build import BuildState, StepBuilder
from g1_control.program.language.grammar import NEGATIVE_RE, Grammar, split_words
from g1_control.program.program import Program
from g1_control.program.steps import Step


class InstructionParser:
    """Parses English instructions into Programs; `places` maps place phrases to place names
    (default: lexicon.DEFAULT_PLACES; a World's names via `for_places`)."""

    def __init__(self, places: dict[str, str] | None = None, conventions: L.Conventions | None = None) -> None:
        self.conv = conventions or L.Conventions()
        self.places = dict(L.DEFAULT_PLACES if places is None else places)
        self.places.setdefault("start", "start")
        self.grammar = Grammar(self.places)
        self.builder = StepBuilder(self.conv)

    @classmethod
    def for_places(cls, names, conventions: L.Conventions | None = None) -> InstructionParser:
        """A parser whose places are these names ('other_table' is said "other table")."""
        places = {n.replace("_", " "): n for n in names}
        places.update({k: v for k, v in L.DEFAULT_PLACES.items() if v == "start"})
        return cls(places, conventions)

    # ------------------------------------------------------------------------------------------
    def parse(self, text: str) -> Program:
        """The validated Program for an instruction; InstructionError (or UnknownWordError) if none."""
        grammar, builder = self.grammar, self.builder
        negative = NEGATIVE_RE.search(text.lower())
        if negative:
            raise InstructionError(f"\"{negative.group(0)}\": a negative quantity; durations, distances, angles and "
                                   "counts are sizes; say the direction in words instead, e.g. \"walk backward 2 "
                                   "meters\", \"turn right 90 degrees\"")
        words = split_words(text)
        if not words:
            raise InstructionError("empty instruction: say what to do, e.g. \"walk forward two meters\"")
        grammar.check_words(words)
        toks = grammar.numbers(words)
        toks = grammar.rewrite(toks, words)
        toks = grammar.idioms(toks, words)
        state = BuildState(words)
        steps: list[Step] = []
        for sentence in grammar.sentences(toks):
            start = len(steps)
            for unit in grammar.order(grammar.clauses(sentence, words), words):
                if unit and unit[0].kind == "w" and unit[0].value == "REPEAT":
                    builder.repeat(unit, steps, start, state)
                    continue
                steps.extend(builder.clause(unit, state))
            state.last_sentence = (start, len(steps))
        if not steps:
            raise InstructionError(f'no action in "{text.strip()}": say what to do, e.g. "walk forward two meters"')
        program = Program(steps, text.strip())
        try:
            return program.validate()
        except ProgramError as exc:  # words that parse into a value the program refuses
            raise InstructionError(f"\"{text.strip()}\": {exc}") from None


_DEFAULT: InstructionParser | None = None


def parse_instruction(text: str, places=None) -> Program:
    """Parse with the default place names, or with `places` (names, e.g. World.names())."""
    global _DEFAULT
    if places is not None:
        return InstructionParser.for_places(places).parse(text)
    if _DEFAULT is None:
        _DEFAULT = InstructionParser()
    return _DEFAULT.parse(text)
