"""The instruction language's grammar: words, numbers and units, phrases, sentences and clauses.

Stages 1-5 of the parser (parser.py), each a single pass over the words:
1. words: lower case, split into words, numbers and punctuation; every word must be known
   (else UnknownWordError naming it and the closest known words, by rapidfuzz);
2. fillers dropped ("please", "the", "robot", ...);
3. numbers and units: "two", "1.5", "one and a half", "a couple of", "half a", "ninety degrees",
   "30 cm", "0.3 meters per second", "3 times" -> quantities in SI units and counts;
4. phrases -> canonical tokens, longest first ("pick up" -> PICK, "other table" -> a place);
5. sentences (". ; ! ?") -> clauses (", then and afterwards next finally"), "after"/"before"
   reorder clauses, "while"/"as" join two parts of a clause (the step builder, build.py, makes
   them a Parallel step).
The result is a list of clauses, each a list of tokens (Tok); build.py turns them into steps.
"""

from __future__ import annotations

import math
import re

from g1_control.program.exceptions import InstructionError, UnknownWordError
from g1_control.program.language import lexicon as L

_WORD_RE = re.compile(r"\d+(?:\.\d+)?|\.\d+|[a-z]+(?:'[a-z]+)?|°|/|[,;.!?]|\S")
_DIGITS_RE = re.compile(r"^(?:\d+(?:\.\d+)?|\.\d+)$")
NEGATIVE_RE = re.compile(r"(?<![\w.])[-\u2212]\s*(?:\d+(?:\.\d+)?|\.\d+)(?:\s*(?:°|[a-z]+))?")
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


class Tok:
    __slots__ = ("i0", "i1", "kind", "value")

    def __init__(self, kind: str, value, i0: int, i1: int) -> None:
        self.kind, self.value, self.i0, self.i1 = kind, value, i0, i1

    def __repr__(self) -> str:
        return f"{self.kind}:{self.value!r}"


def split_words(text: str) -> list[str]:
    """Stage 1: the instruction's words, numbers and punctuation (lower case)."""
    return _WORD_RE.findall(text.lower().replace("-", " ").replace("\u2019", "'"))


class Grammar:
    """Stages 1-5 (module docstring) for one set of place phrases (`places`: phrase -> name)."""

    def __init__(self, places: dict[str, str]) -> None:
        self.places = places
        table = L.parse_phrase_table(L.PHRASES)
        table += [(tuple(phrase.split()), ("PLACE:" + name,)) for phrase, name in places.items()]
        self._phrases: dict[str, list[tuple[tuple[str, ...], tuple[str, ...]]]] = {}
        for words, repl in table:
            self._phrases.setdefault(words[0], []).append((words, repl))
        for cands in self._phrases.values():
            cands.sort(key=lambda wr: -len(wr[0]))
        known = set(L.FILLERS) | set(L.ARTICLES) | set(L.NUMBER_WORDS) | set(L.TENS_WORDS)
        known |= set(L.FRACTION_WORDS) | set(L.NUMBER_GLUE) | set(L.UNITS) | set(L.PER_WORDS)
        known |= {"couple", "pair", "few", "of"} | set(SENTENCE_ENDS) | {","}
        for words, _ in table:
            known.update(words)
        self._known = frozenset(known)
        self._suggest_from = sorted(w for w in known if len(w) >= 3 and w.isalpha() and w not in L.FILLERS)

    # --- stage 1: words ---------------------------------------------------------------------------
    def check_words(self, words: list[str]) -> None:
        for i, w in enumerate(words):
            if w in self._known or _DIGITS_RE.match(w):
                continue
            from rapidfuzz import fuzz, process

            found = process.extract(w, self._suggest_from, scorer=fuzz.ratio, limit=3, score_cutoff=60)
            sugg = tuple(s for s, _, _ in found)
            lo, hi = max(0, i - 4), min(len(words), i + 5)
            context = ("... " if lo else "") + join_words(words[lo:hi]) + (" ..." if hi < len(words) else "")
            if any(w in phrase.split() for phrase in L.DEFAULT_PLACES):  # a place word, not a place here
                places = sorted({n for n in self.places.values()})
                raise UnknownWordError(f"'{w}' in \"{context}\" is not a place here; places: {', '.join(places)}",
                                       w, tuple(places))
            hint = f"closest known words: {', '.join(sugg)}" if sugg else "no known word is close"
            raise UnknownWordError(f"unknown word '{w}' in \"{context}\"; {hint}", w, sugg)

    # --- stage 2+3: fillers, numbers and units ------------------------------------------------------
    def numbers(self, words: list[str]) -> list[Tok]:
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
                    raise InstructionError(f"\"{join_words(words[i:j + 1])}\": a count must be a whole number >= 1")
                out.append(Tok("count", int(value), i, j + 1))
                j += 1
            else:
                out.append(Tok("num", value, i, j))
            i = j
        return out

    # --- stage 4: phrases ---------------------------------------------------------------------------
    def rewrite(self, toks: list[Tok], words: list[str]) -> list[Tok]:
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
    def idioms(toks: list[Tok], words: list[str]) -> list[Tok]:
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
    def sentences(toks: list[Tok]) -> list[list[Tok]]:
        out: list[list[Tok]] = [[]]
        for t in toks:
            if t.kind == "w" and t.value in SENTENCE_ENDS:
                if out[-1]:
                    out.append([])
            else:
                out[-1].append(t)
        return [s for s in out if s]

    @staticmethod
    def clauses(sentence: list[Tok], words: list[str]) -> list[list[Tok]]:
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
            if not has_verb and out and _another_leg(c, out[-1]):  # "walk 2 m, then sideways to the right 1 m"
                out.append([next(t for t in out[-1] if t.kind == "w" and t.value == "WALK")] + c)
                continue
            if not has_verb and out:
                out[-1].extend(c)  # "turn left, twice": words without a verb go on with the clause before
            else:
                out.append(c)
        return out

    @staticmethod
    def order(clauses: list[list[Tok]], words: list[str]) -> list[list[Tok]]:
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

def join_words(words: list[str]) -> str:
    """Words back into text, punctuation attached to the word before it."""
    out = ""
    for w in words:
        out += w if (w in SENTENCE_ENDS or w == ",") or not out else " " + w
    return out


def _another_leg(clause: list[Tok], before: list[Tok]) -> bool:
    """A verbless clause with its own direction and distance or time, after a walk with both: a walk of its own."""
    def leg(c: list[Tok]) -> bool:
        moves = any(t.kind == "qty" and t.value[1] in ("length", "time") for t in c)
        return moves and any(t.kind == "w" and (t.value in DIRECTIONS or t.value == "SIDEWAYS") for t in c)

    walks = any(t.kind == "w" and t.value == "WALK" for t in before)
    return walks and leg(clause) and leg(before)


def _is_verb(t: Tok) -> bool:
    if t.kind != "w":
        return False
    v = t.value
    return v in MAIN_VERBS or v == "REPEAT" or v.startswith(("STYLE:", "HEIGHT:"))


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
        if nxt == "few" and w in L.ARTICLES:  # "a few seconds": three
            return 3.0, k + 1
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
