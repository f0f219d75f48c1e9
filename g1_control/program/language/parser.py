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

See g1_control/program/README.md for the grammar and the conventions it fills in.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from g1_control.program.exceptions import InstructionError, ProgramError, UnknownWordError
from g1_control.program.language import lexicon as L
from g1_control.program.program import Program
from g1_control.program.steps import (
    Height,
    Parallel,
    Pick,
    Place,
    Reach,
    Repeat,
    Stand,
    Step,
    StepDown,
    StepUp,
    Style,
    Turn,
    Walk,
)

_WORD_RE = re.compile(r"\d+(?:\.\d+)?|\.\d+|[a-z]+(?:'[a-z]+)?|°|/|[,;.!?]|\S")
_DIGITS_RE = re.compile(r"^(?:\d+(?:\.\d+)?|\.\d+)$")
_NEGATIVE_RE = re.compile(r"(?<![\w.])[-\u2212]\s*(?:\d+(?:\.\d+)?|\.\d+)(?:\s*(?:°|[a-z]+))?")
"""A signed number ('-3', '− 2.5 meters'): hyphens are word joints elsewhere ("ninety-degree")."""
SENTENCE_ENDS = frozenset(";.!?")
DIRECTIONS = frozenset({"forward", "backward", "left", "right", "up", "down"})
PREPOSITIONS = frozenset({"to", "toward", "towards", "onto", "on", "into", "in", "at", "from", "off", "of", "for",
                          "by", "with", "near"})
TARGET_PREPS = frozenset({"to", "toward", "towards", "onto", "on", "into", "in", "at", "near", "by"})
SOURCE_PREPS = frozenset({"from", "off"})
"""Where a picked object is ("from the table", "off the shelf"): no step of its own."""
MAIN_VERBS = frozenset({"WALK", "TURN", "FACE", "WAIT", "REACH", "PICK", "PLACE", "CARRY", "LIFT", "CLIMB",
                        "STEPUP", "STEPDOWN", "SELECT", "HEIGHTSET"})
_AMBIGUOUS = {"CARRY": "carry", "LIFT": "lift", "CLIMB": "climb"}
"""Verbs that are a style when no object is named ("walk forward carrying")."""
LOCOMOTION_VERBS = frozenset({"WALK", "TURN", "FACE", "WAIT"})


class Tok:
    __slots__ = ("i0", "i1", "kind", "value")

    def __init__(self, kind: str, value, i0: int, i1: int) -> None:
        self.kind, self.value, self.i0, self.i1 = kind, value, i0, i1

    def __repr__(self) -> str:
        return f"{self.kind}:{self.value!r}"


@dataclass
class _Slots:
    """The words of one clause part, sorted by role. Lists hold (value, token)."""

    verbs: list = field(default_factory=list)
    styles: list = field(default_factory=list)
    heights: list = field(default_factory=list)
    select: list = field(default_factory=list)
    directions: list = field(default_factory=list)
    back: list = field(default_factory=list)
    around: list = field(default_factory=list)
    sideways: list = field(default_factory=list)
    places: list = field(default_factory=list)
    """((preposition or None, name or 'IT'), token)."""
    hands: list = field(default_factory=list)
    speed_words: list = field(default_factory=list)
    lengths: list = field(default_factory=list)
    angles: list = field(default_factory=list)
    headings: list = field(default_factory=list)
    durations: list = field(default_factory=list)
    timeouts: list = field(default_factory=list)
    speeds: list = field(default_factory=list)
    rates: list = field(default_factory=list)
    numbers: list = field(default_factory=list)
    counts: list = field(default_factory=list)
    body: list = field(default_factory=list)
    shapes: list = field(default_factory=list)
    other: list = field(default_factory=list)


class InstructionParser:
    """Parses English instructions into Programs; `places` maps place phrases to place names
    (default: lexicon.DEFAULT_PLACES; a World's names via `for_places`)."""

    def __init__(self, places: dict[str, str] | None = None, conventions: L.Conventions | None = None) -> None:
        self.conv = conventions or L.Conventions()
        self.places = dict(L.DEFAULT_PLACES if places is None else places)
        self.places.setdefault("start", "start")
        table = L.parse_phrase_table(L.PHRASES)
        table += [(tuple(phrase.split()), ("PLACE:" + name,)) for phrase, name in self.places.items()]
        self._phrases: dict[str, list[tuple[tuple[str, ...], tuple[str, ...]]]] = {}
        for words, repl in table:
            self._phrases.setdefault(words[0], []).append((words, repl))
        for cands in self._phrases.values():
            cands.sort(key=lambda wr: -len(wr[0]))
        known = set(L.FILLERS) | set(L.ARTICLES) | set(L.NUMBER_WORDS) | set(L.TENS_WORDS)
        known |= set(L.FRACTION_WORDS) | set(L.NUMBER_GLUE) | set(L.UNITS) | set(L.PER_WORDS)
        known |= {"couple", "pair", "of"} | set(SENTENCE_ENDS) | {","}
        for words, _ in table:
            known.update(words)
        self._known = frozenset(known)
        self._suggest_from = sorted(w for w in known if len(w) >= 3 and w.isalpha() and w not in L.FILLERS)

    @classmethod
    def for_places(cls, names, conventions: L.Conventions | None = None) -> InstructionParser:
        """A parser whose places are these names ('other_table' is said "other table")."""
        places = {n.replace("_", " "): n for n in names}
        places.update({k: v for k, v in L.DEFAULT_PLACES.items() if v == "start"})
        return cls(places, conventions)

    # ------------------------------------------------------------------------------------------
    def parse(self, text: str) -> Program:
        """The validated Program for an instruction; InstructionError (or UnknownWordError) if none."""
        negative = _NEGATIVE_RE.search(text.lower())
        if negative:
            raise InstructionError(f"\"{negative.group(0)}\": a negative quantity; durations, distances, angles and "
                                   "counts are sizes; say the direction in words instead, e.g. \"walk backward 2 "
                                   "meters\", \"turn right 90 degrees\"")
        words = _WORD_RE.findall(text.lower().replace("-", " ").replace("\u2019", "'"))
        if not words:
            raise InstructionError("empty instruction: say what to do, e.g. \"walk forward two meters\"")
        self._check_words(words)
        toks = self._numbers(words)
        toks = self._rewrite(toks, words)
        toks = self._idioms(toks, words)
        state = _State(words)
        steps: list[Step] = []
        for sentence in self._sentences(toks):
            start = len(steps)
            for unit in self._order(self._clauses(sentence, words), words):
                if unit and unit[0].kind == "w" and unit[0].value == "REPEAT":
                    self._repeat(unit, steps, start, state)
                    continue
                steps.extend(self._clause(unit, state))
            state.last_sentence = (start, len(steps))
        if not steps:
            raise InstructionError(f'no action in "{text.strip()}": say what to do, e.g. "walk forward two meters"')
        program = Program(steps, text.strip())
        try:
            return program.validate()
        except ProgramError as exc:  # words that parse into a value the program refuses
            raise InstructionError(f"\"{text.strip()}\": {exc}") from None

    # --- stage 1: words ---------------------------------------------------------------------------
    def _check_words(self, words: list[str]) -> None:
        for i, w in enumerate(words):
            if w in self._known or _DIGITS_RE.match(w):
                continue
            from rapidfuzz import fuzz, process

            found = process.extract(w, self._suggest_from, scorer=fuzz.ratio, limit=3, score_cutoff=60)
            sugg = tuple(s for s, _, _ in found)
            lo, hi = max(0, i - 4), min(len(words), i + 5)
            context = ("... " if lo else "") + _join(words[lo:hi]) + (" ..." if hi < len(words) else "")
            if any(w in phrase.split() for phrase in L.DEFAULT_PLACES):  # a place word, not a place here
                places = sorted({n for n in self.places.values()})
                raise UnknownWordError(f"'{w}' in \"{context}\" is not a place here; places: {', '.join(places)}",
                                       w, tuple(places))
            hint = f"closest known words: {', '.join(sugg)}" if sugg else "no known word is close"
            raise UnknownWordError(f"unknown word '{w}' in \"{context}\"; {hint}", w, sugg)

    # --- stage 2+3: fillers, numbers and units ------------------------------------------------------
    def _numbers(self, words: list[str]) -> list[Tok]:
        out: list[Tok] = []
        n = len(words)
        i = 0
        while i < n:
            w = words[i]
            if w in L.FILLERS:
                i += 1
                continue
            got = _read_number(words, i)
            if got is None:
                if w not in L.ARTICLES:
                    out.append(Tok("w", w, i, i + 1))
                i += 1
                continue
            value, j = got
            if j < n and words[j] in L.UNITS:
                dim, f = L.UNITS[words[j]]
                j += 1
                if j + 2 < n and words[j] == "and" and words[j + 1] in L.ARTICLES and words[j + 2] in L.FRACTION_WORDS:
                    value += L.FRACTION_WORDS[words[j + 2]]
                    j += 3
                if dim in L.RATE_OF and j + 1 < n and words[j] in L.PER_WORDS and L.UNITS.get(words[j + 1], ("",))[0] == "time":
                    f /= L.UNITS[words[j + 1]][1]
                    dim = L.RATE_OF[dim]
                    j += 2
                out.append(Tok("qty", (value * f, dim), i, j))
            elif j < n and words[j] in ("times", "time"):
                if value != int(value) or value < 1:
                    raise InstructionError(f"\"{_join(words[i:j + 1])}\": a count must be a whole number >= 1")
                out.append(Tok("count", int(value), i, j + 1))
                j += 1
            else:
                out.append(Tok("num", value, i, j))
            i = j
        return out

    # --- stage 4: phrases ---------------------------------------------------------------------------
    def _rewrite(self, toks: list[Tok], words: list[str]) -> list[Tok]:
        out: list[Tok] = []
        i, n = 0, len(toks)
        while i < n:
            t = toks[i]
            if t.kind != "w":
                out.append(t)
                i += 1
                continue
            for pattern, repl in self._phrases.get(t.value, ()):
                k = len(pattern)
                if i + k <= n and all(toks[i + m].kind == "w" and toks[i + m].value == pattern[m] for m in range(k)):
                    i0, i1 = t.i0, toks[i + k - 1].i1
                    for r in repl:
                        if r.startswith("PLACE:"):
                            out.append(Tok("place", r[6:], i0, i1))
                        elif r.startswith("ANGLE:"):
                            out.append(Tok("qty", (math.radians(float(r[6:])), "angle"), i0, i1))
                        elif r.startswith("COUNT:"):
                            out.append(Tok("count", int(r[6:]), i0, i1))
                        else:
                            out.append(Tok("w", r, i0, i1))
                    i += k
                    break
            else:
                out.append(t)
                i += 1
        return out

    @staticmethod
    def _idioms(toks: list[Tok], words: list[str]) -> list[Tok]:
        """'take N steps' is a walk; 'make'/'do' + a turn ('make a right', 'do a 180', 'make a quarter
        turn') is a turn; 'do' + a style ('do a little dance') is the style."""
        out: list[Tok] = []
        for i, t in enumerate(toks):
            nxt = toks[i + 1] if i + 1 < len(toks) else None
            if t.kind == "w" and t.value == "PICK" and words[t.i0] in ("take", "taking") and nxt is not None \
                    and nxt.kind == "qty" and words[nxt.i1 - 1] in ("step", "steps"):
                out.append(Tok("w", "WALK", t.i0, t.i1))
                continue
            if t.kind == "w" and t.value in ("make", "do"):
                if nxt is None:
                    out.append(t)
                elif nxt.kind == "num":
                    out.append(Tok("w", "TURN", t.i0, t.i1))
                    toks[i + 1] = Tok("qty", (math.radians(nxt.value), "angle"), nxt.i0, nxt.i1)
                elif (nxt.kind == "qty" and nxt.value[1] == "angle") or (nxt.kind == "w" and nxt.value in ("left", "right")):
                    out.append(Tok("w", "TURN", t.i0, t.i1))
                elif nxt.kind == "w" and (nxt.value == "TURN" or nxt.value.startswith(("STYLE:", "HEIGHT:"))):
                    pass  # "make a turn", "do a little dance": the next word is the action
                else:
                    out.append(t)
                continue
            out.append(t)
        return out

    # --- stage 5: sentences, clauses, order -----------------------------------------------------------
    @staticmethod
    def _sentences(toks: list[Tok]) -> list[list[Tok]]:
        out: list[list[Tok]] = [[]]
        for t in toks:
            if t.kind == "w" and t.value in SENTENCE_ENDS:
                if out[-1]:
                    out.append([])
            else:
                out[-1].append(t)
        return [s for s in out if s]

    @staticmethod
    def _clauses(sentence: list[Tok], words: list[str]) -> list[list[Tok]]:
        raw: list[list[Tok]] = [[]]
        for t in sentence:
            if t.kind == "w" and t.value in (",", "THEN"):
                if raw[-1]:
                    raw.append([])
            else:
                raw[-1].append(t)
        out: list[list[Tok]] = []
        for c in raw:
            if not c:
                continue
            same = [t for t in c if t.kind == "w" and t.value == "SAMETIME"]
            if same and out:  # "walk forward and wave at the same time": one clause joined by 'while'
                out[-1] += [Tok("w", "WHILE", same[0].i0, same[0].i1)] + [t for t in c if t not in same]
                continue
            has_verb = any(_is_verb(t) for t in c)
            if not has_verb and out and any(t.kind == "place" for t in c) and all(
                    t.kind == "place" or (t.kind == "w" and t.value in TARGET_PREPS) for t in c):
                verb = next((t for t in out[-1] if t.kind == "w" and t.value in MAIN_VERBS), None)
                if verb is not None and verb.value == "WALK":  # "walk to the table, then (to) the shelf"
                    out.append([verb] + ([] if c[0].kind == "w" else [Tok("w", "to", c[0].i0, c[0].i0)]) + c)
                    continue
            if not has_verb and out:
                out[-1].extend(c)  # "turn left, twice": words without a verb go on with the clause before
            else:
                out.append(c)
        return out

    @staticmethod
    def _order(clauses: list[list[Tok]], words: list[str]) -> list[list[Tok]]:
        """'X after Y' and 'before Y, X' run Y first; 'after Y, X' and 'X before Y' keep the order."""
        out: list[list[Tok]] = []
        pending_before: list[list[Tok]] = []
        for c in clauses:
            units: list[list[Tok]]
            if c[0].kind == "w" and c[0].value in ("AFTER", "BEFORE"):
                first = c[0].value
                c = c[1:]
                units = [c]
                if first == "BEFORE":
                    pending_before.append(c)
                    continue
            else:
                units = [c]
                for k, t in enumerate(c):
                    if t.kind == "w" and t.value in ("AFTER", "BEFORE") and k > 0:
                        a, b = c[:k], c[k + 1:]
                        units = [b, a] if t.value == "AFTER" else [a, b]
                        break
            for u in units:
                if u:
                    out.append(u)
            while pending_before:
                out.append(pending_before.pop())
        out.extend(pending_before)
        return out

    def _repeat(self, unit: list[Tok], steps: list[Step], start: int, state: _State) -> None:
        count = 2
        for t in unit[1:]:
            if t.kind == "count":
                count = t.value
            elif t.kind == "num" and t.value == int(t.value) and t.value >= 1:
                count = int(t.value)
            else:
                raise InstructionError(f"could not use \"{state.text(t)}\" in \"{state.span(unit)}\"")
        if start == len(steps):  # "... . Repeat that 3 times." repeats the sentence before
            start = state.last_sentence[0]
        body = steps[start:]
        if not body:
            raise InstructionError(f"\"{state.span(unit)}\": nothing before it to repeat")
        if count > 1:
            steps[start:] = [Repeat(count, body)]

    # --- stage 6: one clause -> steps ----------------------------------------------------------------
    def _clause(self, unit: list[Tok], state: _State) -> list[Step]:
        parts: list[list[Tok]] = [[]]
        for t in unit:
            if t.kind == "w" and t.value == "WHILE":
                parts.append([])
            else:
                parts[-1].append(t)
        parts = [p for p in parts if p]
        if len(parts) == 1:
            slots = self._slots(parts[0], state)
            steps = self._build(slots, parts[0], state, alongside=False)
            return self._counted(slots, steps)
        if len(parts) != 2:
            raise InstructionError(f"\"{state.span(unit)}\": one 'while' per clause")
        s0, s1 = (self._slots(p, state) for p in parts)
        loco = [k for k, s in enumerate((s0, s1)) if _main_verb(s) in LOCOMOTION_VERBS]
        if not loco:
            raise InstructionError(f"\"{state.span(unit)}\": 'while' needs a walk, turn or wait on one side")
        k = loco[-1] if len(loco) == 2 else loco[0]
        main_slots, side_slots = (s0, s1) if k == 0 else (s1, s0)
        main_part, side_part = (parts[0], parts[1]) if k == 0 else (parts[1], parts[0])
        main = self._build(main_slots, main_part, state, alongside=False)
        side = self._build(side_slots, side_part, state, alongside=True)
        if len(main) != 1 or len(side) != 1:
            raise InstructionError(f"\"{state.span(unit)}\": 'while' joins one locomotion step and one behaviour")
        m, s = main[0], side[0]
        alongside = s.alongside if isinstance(s, Parallel) else [s]
        step: Step = Parallel(m.main, m.alongside + alongside) if isinstance(m, Parallel) else Parallel(m, alongside)
        for a in alongside:
            if not isinstance(a, (Style, Height, Reach)):
                raise InstructionError(f"\"{state.span(side_part)}\": only a style, a height or a reach can run "
                                       "alongside a walk")
        slots = _Slots(counts=main_slots.counts + side_slots.counts)
        return self._counted(slots, [step])

    @staticmethod
    def _counted(slots: _Slots, steps: list[Step]) -> list[Step]:
        if len(slots.counts) > 1:
            raise InstructionError(f"two counts in one clause: {', '.join(str(c) for c, _ in slots.counts)}")
        if slots.counts and slots.counts[0][0] > 1:
            return [Repeat(slots.counts[0][0], steps)]
        return steps

    def _slots(self, part: list[Tok], state: _State) -> _Slots:
        s = _Slots()
        prep: str | None = None
        pending: str | None = None  # HEADING / WITHIN / in: what the next quantity is
        for t in part:
            kind, v = t.kind, t.value
            if kind == "qty":
                value, dim = v
                if dim == "time":
                    (s.timeouts if pending in ("WITHIN", "in") else s.durations).append((value, t))
                elif dim == "angle":
                    (s.headings if pending == "HEADING" else s.angles).append((value, t))
                elif dim == "length":
                    s.lengths.append((value, t))
                elif dim == "speed":
                    s.speeds.append((value, t))
                else:
                    s.rates.append((value, t))
                pending = None
                continue
            if kind == "num":
                (s.headings if pending == "HEADING" else s.numbers).append((v, t))
                pending = None
                continue
            if kind == "count":
                s.counts.append((v, t))
                continue
            if kind == "place":
                s.places.append(((prep, v), t))
                prep = None
                continue
            pending = None if v not in ("HEADING", "WITHIN", "in") else v
            if v in MAIN_VERBS:
                s.verbs.append((v, t))
            elif v.startswith("STYLE:"):
                s.styles.append((v[6:], t))
            elif v.startswith("HEIGHT:"):
                s.heights.append((v[7:], t))
            elif v.startswith("HAND:"):
                s.hands.append((v[5:], t))
            elif v.startswith("SPEED:"):
                s.speed_words.append((v[6:], t))
            elif v in DIRECTIONS:
                s.directions.append((v, t))
            elif v == "back":
                s.back.append((v, t))
            elif v == "around":
                s.around.append((v, t))
            elif v == "SIDEWAYS":
                s.sideways.append((v, t))
            elif v == "IT":
                s.places.append(((prep, "IT"), t))
                prep = None
            elif v in PREPOSITIONS:
                prep = v
            elif v == "BODY":
                s.body.append((v, t))
            elif v.startswith("SHAPE:"):
                s.shapes.append((v[6:], t))
            elif v in ("STYLEWORD", "HEADING", "WITHIN"):
                pass
            else:
                s.other.append((v, t))
        if s.other:
            word = state.text(s.other[0][1])
            raise InstructionError(f"could not use \"{word}\" in \"{state.span(part)}\"")
        return s

    def _build(self, s: _Slots, part: list[Tok], state: _State, alongside: bool) -> list[Step]:
        """The step(s) of one clause part; every filled slot must be one the verb takes."""
        verb = _main_verb(s)
        where = state.span(part)
        c = self.conv
        used: set[str] = {"counts", "verbs"}

        def take(*names: str) -> None:
            used.update(names)

        def one(name: str, what: str):
            items = getattr(s, name)
            take(name)
            if len(items) > 1:
                raise InstructionError(f"\"{where}\": more than one {what} "
                                       f"(\"{state.text(items[0][1])}\" and \"{state.text(items[1][1])}\")")
            return items[0][0] if items else None

        def place(roles=None):
            take("places")
            out = []
            for (prep, name), t in s.places:
                if roles is not None and prep not in roles:
                    continue
                out.append(state.resolve(name, t))
            return out

        def timeout() -> float | None:
            return one("timeouts", "time limit")

        if verb is None:
            if s.styles and not s.heights:
                verb = "STYLE"
            elif s.heights and not s.styles:
                verb = "HEIGHT"
            elif s.styles and s.heights:
                raise InstructionError(f"\"{where}\": a style and a height without a walk, turn or wait; "
                                       "join them with 'while' to a walk or a wait")
            else:
                raise InstructionError(f"\"{where}\": no action (walk, turn, wait, a style, reach, pick, place, "
                                       "step up/down)")
        steps: list[Step]
        if len(s.verbs) > 1:  # "walk forward carrying": the word that can be a style is one here
            amb = [(v, t) for v, t in s.verbs if v in _AMBIGUOUS]
            s.verbs = [(v, t) for v, t in s.verbs if v not in _AMBIGUOUS] or s.verbs[:1]
            s.styles.extend((_AMBIGUOUS[v], t) for v, t in amb if (v, t) not in s.verbs)
            verb = _main_verb(s)
        if verb in _AMBIGUOUS and not s.places:
            s.styles.insert(0, (_AMBIGUOUS[verb], s.verbs[0][1]))
            s.verbs = []
            verb = "STYLE"
        if verb == "WALK" and any(prep is None for (prep, _), _t in s.places) and \
                any(prep in TARGET_PREPS for (prep, _), _t in s.places):
            steps = self._manipulate(s, "CARRY", where, state, one, place, timeout, take)  # "move the box to X"
        elif verb == "WALK" and s.shapes:
            steps = [self._shape(s, where, one, take)]
        elif verb == "WALK":
            steps = [self._walk(s, where, state, one, place, timeout, take)]
        elif verb in ("TURN", "FACE"):
            steps = [self._turn(s, verb, where, state, one, place, timeout, take)]
        elif verb == "WAIT":
            d = one("durations", "duration")
            if d is None:
                d = one("numbers", "number")
            steps = [Stand(d if d is not None else c.wait_s)]
        elif verb in ("STYLE", "SELECT"):
            if s.hands:
                raise InstructionError(f"\"{where}\": a style is a whole upper-body pose; \"{state.text(s.hands[0][1])}\" "
                                       "cannot be chosen for a style (styles have no hand; the wave waves the right one)")
            name = one("styles", "style")
            if name is None:
                raise InstructionError(f"\"{where}\": which style? known: wave, dance, look around, arms out, "
                                       "guard, arm swing, reach up, carry, lift, climb, default")
            d = one("durations", "duration")
            if d is None:
                d = one("numbers", "number")
            if d is None and verb == "STYLE" and not alongside and name != "default":
                d = c.style_s
            steps = [Style(name, d)]
            s.styles = []
        elif verb in ("HEIGHT", "HEIGHTSET"):
            posture = one("heights", "posture")
            h = one("lengths", "height")
            take("body", "places")
            if s.places:
                raise InstructionError(f"could not use \"{state.text(s.places[0][1])}\" in \"{where}\"")
            if h is None and posture is None:
                raise InstructionError(f"\"{where}\": to what height? e.g. \"lower your pelvis to 0.6 meters\"")
            d = one("durations", "duration")
            steps = [Height(h, None if h is not None else posture, d)]
            s.heights = []
        elif verb == "REACH":
            hand = one("hands", "hand") or "right"
            targets = place()
            if len(targets) > 1:
                raise InstructionError(f"\"{where}\": reach for one place at a time")
            d = one("directions", "direction")
            length = one("lengths", "distance")
            offset: tuple[float, float, float] | None = None
            if d is not None or length is not None:
                if d is None:
                    raise InstructionError(f"\"{where}\": which way? (forward, left, right, up, down)")
                dist = length if length is not None else c.reach_m
                vec = {"forward": (1, 0, 0), "backward": (-1, 0, 0), "left": (0, 1, 0), "right": (0, -1, 0),
                       "up": (0, 0, 1), "down": (0, 0, -1)}[d]
                offset = (float(dist * vec[0]), float(dist * vec[1]), float(dist * vec[2]))
            if not targets and offset is None:
                raise InstructionError(f"\"{where}\": reach for what? a place (\"the cup\") or a direction "
                                       "(\"forward 20 cm\")")
            steps = [Reach(hand, targets[0] if targets else None, offset, timeout())]
        elif verb in ("PICK", "LIFT", "CARRY", "PLACE"):
            steps = self._manipulate(s, verb, where, state, one, place, timeout, take)
        elif verb in ("STEPUP", "CLIMB"):
            names = place()
            if len(names) != 1:
                raise InstructionError(f"\"{where}\": step up onto what? e.g. \"step onto the platform\"")
            steps = [StepUp(names[0], timeout())]
        elif verb == "STEPDOWN":
            names = place()
            if len(names) > 1:
                raise InstructionError(f"\"{where}\": step down from one platform")
            steps = [StepDown(names[0] if names else None, timeout())]
        else:  # pragma: no cover - every verb is handled above
            raise InstructionError(f"\"{where}\": cannot build a step for {verb}")

        # styles and heights left in a locomotion clause run alongside it
        side: list[Step] = []
        if s.styles or s.heights:
            if not isinstance(steps[0], (Walk, Turn, Stand)) or len(steps) != 1:
                t = (s.styles or s.heights)[0][1]
                raise InstructionError(f"could not use \"{state.text(t)}\" in \"{where}\" (a style or height runs "
                                       "alongside a walk, turn or wait)")
            side = [Style(n) for n, _ in s.styles] + [Height(None, p) for p, _ in s.heights]
            take("styles", "heights")
        for name in ("select", "directions", "back", "around", "sideways", "places", "hands", "speed_words",
                     "lengths", "angles", "headings", "durations", "timeouts", "speeds", "rates", "numbers", "body",
                     "shapes"):
            items = getattr(s, name)
            if items and name not in used:
                raise InstructionError(f"could not use \"{state.text(items[0][1])}\" in \"{where}\"")
        if len(s.verbs) > 1:
            raise InstructionError(f"\"{where}\": two actions in one clause (\"{state.text(s.verbs[0][1])}\" and "
                                   f"\"{state.text(s.verbs[1][1])}\"); join them with 'then', 'and' or 'while'")
        if side:
            return [Parallel(steps[0], side)]
        return steps

    def _walk(self, s: _Slots, where, state, one, place, timeout, take) -> Walk:
        c = self.conv
        targets = place()
        if len(targets) > 1:
            raise InstructionError(f"\"{where}\": walk to one place at a time")
        target = targets[0] if targets else None
        take("back", "sideways")
        direction = one("directions", "direction")
        if direction in ("up", "down"):
            raise InstructionError(f"\"{where}\": walk forward, backward, left or right (to step up, say "
                                   "\"step onto the platform\")")
        if s.sideways and direction not in ("left", "right"):
            raise InstructionError(f"\"{where}\": sideways to the left or to the right?")
        if s.back and target is None:
            if direction not in (None, "backward"):
                raise InstructionError(f"\"{where}\": back and {direction}?")
            direction = "backward"
        distance = one("lengths", "distance")
        duration = one("durations", "duration")
        heading = one("headings", "heading")
        if distance is None and duration is None and target is None:
            distance = one("numbers", "number")  # "walk forward 2": meters
        if s.back and target is None and distance is None and duration is None:
            target, direction = "start", None  # "come back", "walk back": to where the program started
        if [distance, duration, target].count(None) < 2:
            raise InstructionError(f"\"{where}\": a walk goes a distance, for a time or to a place, not two of them")
        if distance is None and duration is None and target is None:
            raise InstructionError(f"\"{where}\" needs a distance (\"2 meters\"), a duration (\"for 3 seconds\") "
                                   "or a place (\"to the table\")")
        if target is not None and direction not in (None, "forward"):
            raise InstructionError(f"\"{where}\": a walk to a place faces it; leave out \"{direction}\"")
        speed = one("speeds", "speed")
        word = one("speed_words", "speed")
        if speed is None and word is not None:
            speed = c.slow_mps if word == "slow" else c.fast_mps
        return Walk(distance, duration, target, direction or "forward", heading, speed, timeout())

    def _shape(self, s: _Slots, where, one, take) -> Repeat:
        """'walk a square of 2 meters (to the right)': 4 x (walk the side, turn 90 degrees that way)."""
        one("shapes", "shape")
        side = one("lengths", "side length")
        if side is None:
            side = one("numbers", "number")
        if side is None:
            raise InstructionError(f"\"{where}\": how long are the sides? e.g. \"walk a square of 1 meter\"")
        turn = one("directions", "direction") or "left"
        if turn not in ("left", "right"):
            raise InstructionError(f"\"{where}\": a square turns left or right, not {turn}")
        speed = one("speeds", "speed")
        word = one("speed_words", "speed")
        if speed is None and word is not None:
            speed = self.conv.slow_mps if word == "slow" else self.conv.fast_mps
        return Repeat(4, [Walk(side, speed_mps=speed), Turn(math.pi / 2, turn)])

    def _turn(self, s: _Slots, verb, where, state, one, place, timeout, take) -> Turn:
        c = self.conv
        targets = place()
        if len(targets) > 1:
            raise InstructionError(f"\"{where}\": turn to one place at a time")
        target = targets[0] if targets else None
        direction = one("directions", "direction")
        if direction not in (None, "left", "right"):
            raise InstructionError(f"\"{where}\": turn left or right, not {direction}")
        angle = one("angles", "angle")
        heading = one("headings", "heading")
        if angle is None and heading is None and target is None:
            n = one("numbers", "number")  # "turn left 90": degrees
            if n is not None:
                angle = math.radians(n)
        take("around", "back")
        if (s.around or s.back) and angle is None:
            angle = c.around_rad
        if verb == "FACE" and angle is not None and direction is None and target is None and not s.around:
            heading, angle = angle, None  # "face 90 degrees": a heading
        if angle is None and heading is None and target is None:
            if direction is None:
                raise InstructionError(f"\"{where}\": turn which way? (left, right, around, to a heading or "
                                       "to face a place)")
            angle = c.turn_rad
        if [angle, heading, target].count(None) < 2:
            raise InstructionError(f"\"{where}\": turn by an angle, to a heading or to face a place, not two of them")
        if angle is None and direction is not None:
            raise InstructionError(f"\"{where}\": a turn to a heading or a place takes the shorter way; "
                                   f"leave out \"{direction}\"")
        rate = one("rates", "turn rate")
        word = one("speed_words", "speed")
        if rate is None and word is not None:
            rate = c.slow_radps if word == "slow" else c.fast_radps
        return Turn(angle, direction or "left", heading, target, rate, timeout())

    def _manipulate(self, s: _Slots, verb, where, state, one, place, timeout, take) -> list[Step]:
        take("places", "back")  # "put it back on the table": back adds nothing to a place
        objects: list[str] = []
        targets: list[str] = []
        down = False
        before = state.last_place  # "it" means what was named before this clause ("set the cup on it")
        for (prep, name), t in s.places:
            if prep in SOURCE_PREPS and verb in ("PICK", "LIFT", "CARRY"):
                continue  # "pick up the cup from the table": where it is; the execution layer finds it
            if name == "IT":
                if prep not in TARGET_PREPS and verb in ("PLACE", "CARRY") and state.held is not None:
                    objects.append(state.held)  # "put it down": the object in hand
                    continue
                if before is None:
                    raise InstructionError(f"\"{state.text(t)}\" does not refer to anything yet; name the object")
                (targets if prep in TARGET_PREPS else objects).append(before)
                continue
            (targets if prep in TARGET_PREPS else objects).append(state.resolve(name, t))
        if s.directions:
            d = one("directions", "direction")
            if d == "down" and verb == "PLACE":
                down = True
            elif d != "up" or verb == "PLACE":
                raise InstructionError(f"could not use \"{d}\" in \"{where}\"")
        if len(objects) > 1 or len(targets) > 1:
            raise InstructionError(f"\"{where}\": one object and one place at a time")
        obj = objects[0] if objects else None
        target = targets[0] if targets else None
        hands = one("hands", "hand") or "both"
        limit = timeout()
        if verb in ("PICK", "LIFT") and target is None:
            if obj is None:
                raise InstructionError(f"\"{where}\": pick up what? e.g. \"pick up the box\"")
            state.held = obj
            return [Pick(obj, hands, limit)]
        if verb == "PLACE" or verb == "CARRY" or target is not None:
            if obj is None:
                obj = state.held
            if obj is None:
                raise InstructionError(f"\"{where}\": put down what? nothing has been picked up")
            if target is None and not down and verb != "PLACE":
                state.held = obj
                return [Pick(obj, hands, limit)]  # "carry the box": pick it up
            steps: list[Step] = []
            if verb != "PLACE" and state.held != obj:
                steps.append(Pick(obj, hands))
            steps.append(Place(obj, target, limit))
            state.held = None
            return steps
        raise InstructionError(f"\"{where}\": pick up or put down what?")  # pragma: no cover


class _State:
    """What the clauses so far have established: the last place named ('it'), the held object."""

    def __init__(self, words: list[str]) -> None:
        self.words = words
        self.last_place: str | None = None
        self.held: str | None = None
        self.last_sentence = (0, 0)

    def text(self, t: Tok) -> str:
        return _join(self.words[t.i0:t.i1])

    def span(self, toks: list[Tok]) -> str:
        return _join(self.words[toks[0].i0:toks[-1].i1]) if toks else ""

    def resolve(self, name: str, t: Tok) -> str:
        if name == "IT":
            if self.last_place is None:
                raise InstructionError(f"\"{self.text(t)}\" does not refer to anything yet; name the object")
            return self.last_place
        self.last_place = name
        return name


def _join(words: list[str]) -> str:
    """Words back into text, punctuation attached to the word before it."""
    out = ""
    for w in words:
        out += w if (w in SENTENCE_ENDS or w == ",") or not out else " " + w
    return out


def _is_verb(t: Tok) -> bool:
    if t.kind != "w":
        return False
    v = t.value
    return v in MAIN_VERBS or v == "REPEAT" or v.startswith(("STYLE:", "HEIGHT:"))


def _main_verb(s: _Slots) -> str | None:
    return s.verbs[0][0] if s.verbs else None


def _read_number(words: list[str], i: int) -> tuple[float, int] | None:
    """A number starting at words[i]: (value, index after it), or None. Articles count as one only
    before a unit, "hundred", "half"/"quarter" or "couple of"."""
    n = len(words)

    def at(k: int) -> str:
        return words[k] if k < n else ""

    w = words[i]
    if _DIGITS_RE.match(w):
        value, j = float(w), i + 1
    elif w in L.ARTICLES or w in ("couple", "pair"):
        k = i + 1 if w in L.ARTICLES else i
        nxt = at(k)
        if nxt in ("couple", "pair"):
            return 2.0, k + 2 if at(k + 1) == "of" else k + 1
        if nxt == "hundred":
            value, j = 100.0, k + 1
            if at(j) == "and" and (at(j + 1) in L.NUMBER_WORDS or at(j + 1) in L.TENS_WORDS):
                j += 1
            if at(j) in L.TENS_WORDS or at(j) in L.NUMBER_WORDS:
                rest = _read_number(words, j)
                if rest is not None:
                    value += rest[0]
                    j = rest[1]
            return value, j
        if nxt in L.FRACTION_WORDS:
            return _fraction(words, k)
        if nxt in L.UNITS and w in L.ARTICLES:
            return 1.0, i + 1
        return None
    elif w in L.FRACTION_WORDS:
        return _fraction(words, i)
    elif w in L.TENS_WORDS or w in L.NUMBER_WORDS:
        if w in L.TENS_WORDS:
            value, j = float(L.TENS_WORDS[w]), i + 1
            if 1 <= L.NUMBER_WORDS.get(at(j), 0) <= 9:
                value += L.NUMBER_WORDS[at(j)]
                j += 1
        else:
            value, j = float(L.NUMBER_WORDS[w]), i + 1
        if at(j) == "hundred":
            value *= 100
            j += 1
            k = j + 1 if at(j) == "and" else j
            if at(k) in L.TENS_WORDS or at(k) in L.NUMBER_WORDS:
                rest = _read_number(words, k)
                if rest is not None:
                    value += rest[0]
                    j = rest[1]
        if at(j) == "point":
            digits = []
            j2 = j + 1
            while at(j2) in L.NUMBER_WORDS and L.NUMBER_WORDS[at(j2)] <= 9:
                digits.append(str(L.NUMBER_WORDS[at(j2)]))
                j2 += 1
            if digits:
                value = float(f"{int(value)}.{''.join(digits)}")
                j = j2
    else:
        return None
    # "one and a half", "2 and a quarter"
    if at(j) == "and" and at(j + 1) in L.ARTICLES and at(j + 2) in L.FRACTION_WORDS:
        value += L.FRACTION_WORDS[at(j + 2)]
        j += 3
    return value, j


def _fraction(words: list[str], i: int) -> tuple[float, int] | None:
    """'half a meter', 'half of a meter', 'a quarter of a turn' (only before a unit)."""
    n = len(words)
    value = L.FRACTION_WORDS[words[i]]
    j = i + 1
    if j < n and words[j] == "of":
        j += 1
    if j < n and words[j] in L.ARTICLES:
        j += 1
    if j < n and words[j] in L.UNITS:
        return value, j
    return None


_DEFAULT: InstructionParser | None = None


def parse_instruction(text: str, places=None) -> Program:
    """Parse with the default place names, or with `places` (names, e.g. World.names())."""
    global _DEFAULT
    if places is not None:
        return InstructionParser.for_places(places).parse(text)
    if _DEFAULT is None:
        _DEFAULT = InstructionParser()
    return _DEFAULT.parse(text)
