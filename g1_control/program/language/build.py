"""Step building: one clause of tokens (grammar.py) -> behaviour steps.

Stage 6 of the parser (parser.py): each clause's words are sorted into slots (verb, direction,
quantities, places, hand, speed, count, styles) and the verb builds its step; a word that no slot
of that verb takes is an error. "while" joins two parts of a clause into a Parallel step, counts
and "repeat" make Repeat steps; `BuildState` carries what earlier clauses established (the last
place named, the object in hand).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from g1_control.program.exceptions import InstructionError
from g1_control.program.language import lexicon as L
from g1_control.program.language.grammar import (
    DIRECTIONS,
    MAIN_VERBS,
    PREPOSITIONS,
    SOURCE_PREPS,
    TARGET_PREPS,
    Tok,
    join_words,
)
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

_AMBIGUOUS = {"CARRY": "carry", "LIFT": "lift", "CLIMB": "climb"}
"""Verbs that are a style when no object is named ("walk forward carrying")."""
LOCOMOTION_VERBS = frozenset({"WALK", "TURN", "FACE", "WAIT"})


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
    circle: list = field(default_factory=list)
    """An angle that came from "circle" ("walk in a circle": a path; "spin a full circle": a turn)."""
    sizes: list = field(default_factory=list)
    """RADIUS / DIAMETER: what the clause's length measures ("a circle with a radius of 2 m")."""
    out: list = field(default_factory=list)
    """"reach out": forward unless a direction is named."""
    other: list = field(default_factory=list)


class StepBuilder:
    """Builds the steps of clauses with the conventions `conv` (defaults a sentence leaves open)."""

    def __init__(self, conv: L.Conventions) -> None:
        self.conv = conv

    def repeat(self, unit: list[Tok], steps: list[Step], start: int, state: BuildState) -> None:
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
    def clause(self, unit: list[Tok], state: BuildState) -> list[Step]:
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

    def _slots(self, part: list[Tok], state: BuildState) -> _Slots:
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
                prep = None  # "use both hands to pick up the box": the 'to' was the verb's, not the box's
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
            elif v == "CIRCLE":
                s.circle.append((v, t))
            elif v in ("RADIUS", "DIAMETER"):
                s.sizes.append((v, t))
            elif v == "OUT":
                s.out.append((v, t))
            elif v in ("STYLEWORD", "HEADING", "WITHIN"):
                pass
            else:
                s.other.append((v, t))
        if s.other:
            word = state.text(s.other[0][1])
            raise InstructionError(f"could not use \"{word}\" in \"{state.span(part)}\"")
        return s

    def _build(self, s: _Slots, part: list[Tok], state: BuildState, alongside: bool) -> list[Step]:
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

        if len(s.verbs) > 1 and s.verbs[0][0] == "SELECT" and s.hands:  # "use your left hand to touch the cup"
            s.verbs = s.verbs[1:]
            verb = _main_verb(s)
        if verb is None and s.hands and not (s.styles or s.heights or s.places or s.lengths or s.directions):
            state.pending_hand = one("hands", "hand")  # "with your left hand, reach out to the left"
            return []
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
        elif verb == "WALK" and s.circle:
            steps = [self._circle(s, where, one, take)]
        elif verb == "WALK" and s.shapes:
            steps = self._shape(s, where, one, take)
        elif verb == "WALK" and _moves_an_object(s):  # "move the box 1 meter to the right"
            obj = state.resolve(s.places[0][0][1], s.places[0][1])
            s.places = []
            steps = [] if state.held == obj else [Pick(obj)]
            steps += [self._walk(s, where, state, one, place, timeout, take), Place(obj)]
            state.held = None
        elif verb == "WALK":
            steps = [self._walk(s, where, state, one, place, timeout, take)]
        elif verb in ("TURN", "FACE"):
            steps = [self._turn(s, verb, where, state, one, place, timeout, take)]
        elif verb == "WAIT" and s.places and all(prep is None for (prep, _), _t in s.places):  # "hold the box"
            steps = self._manipulate(s, "PICK", where, state, one, place, timeout, take)
        elif verb == "WAIT":
            d = one("durations", "duration")
            if d is None:
                d = one("numbers", "number")
            steps = [Stand(d if d is not None else c.wait_s)]
        elif verb in ("STYLE", "SELECT", "HEIGHTSET") and s.hands and not s.body and \
                (verb == "HEIGHTSET" or s.styles[0][0] in ("reach_up", "lift")):
            # "reach up with the right hand", "raise your left hand", "lift your right hand 20 cm": that hand
            hand = one("hands", "hand")
            lowered = verb == "HEIGHTSET" and state.text(s.verbs[0][1]).startswith("lower")
            dist = one("lengths", "distance")
            dist = c.reach_m if dist is None else dist
            steps = [Reach(hand, None, (0.0, 0.0, -dist if lowered else dist), timeout())]
            s.styles = []
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
            hand = one("hands", "hand") or state.pending_hand or "right"
            state.pending_hand = None
            targets = place()
            if len(targets) > 1:
                raise InstructionError(f"\"{where}\": reach for one place at a time")
            take("out")
            d = one("directions", "direction")
            if d is None and s.out:
                d = "forward"
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
        elif verb == "PLACE" and s.hands and state.held is None and s.places and \
                all(prep in TARGET_PREPS for (prep, _), _t in s.places):
            # "put your right hand on the table": nothing in hand, a hand named: a reach to the place
            hand = one("hands", "hand")
            targets = place()
            steps = [Reach(hand, targets[0], None, timeout())]
        elif verb in ("PICK", "LIFT", "CARRY", "PLACE") and (s.lengths or s.durations) and \
                any(d in ("forward", "backward", "left", "right") for d, _ in s.directions):
            # "carry the box forward 3 meters", "take it 2 meters to the left": pick (unless held), walk
            walk_slots = _Slots(directions=s.directions, lengths=s.lengths, durations=s.durations,
                                speed_words=s.speed_words, speeds=s.speeds)
            s.directions, s.lengths, s.durations, s.speed_words, s.speeds = [], [], [], [], []
            held = state.held
            steps = self._manipulate(s, "PICK", where, state, one, place, timeout, take)
            if len(steps) == 1 and isinstance(steps[0], Pick) and steps[0].object == held:
                steps = []  # already in hand: just walk with it
            steps.append(self._walk(walk_slots, where, state, _one_of(walk_slots, where, state), lambda *_: [],
                                    lambda: None, lambda *_: None))
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
                     "shapes", "circle", "sizes", "out"):
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
        if state.held is not None:  # "walk backward 1 meter with it": the held box comes along
            s.places = [p for p in s.places if not (p[0][0] == "with" and p[0][1] in ("IT", state.held))]
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

    def _speed(self, one) -> float | None:
        speed = one("speeds", "speed")
        word = one("speed_words", "speed")
        if speed is None and word is not None:
            speed = self.conv.slow_mps if word == "slow" else self.conv.fast_mps
        return speed

    def _shape(self, s: _Slots, where, one, take) -> list[Step]:
        """'walk a square of 2 meters (to the right)': 4 x (walk the side, turn 90 degrees that way); a
        triangle 3 x (side, 120 degrees); 'a rectangle 2 by 1 meters' 2 x (long, 90, short, 90); 'back and
        forth 2 meters': the distance forward, then backward (facing the same way)."""
        shape = one("shapes", "shape")
        take("lengths", "numbers")
        sides = [v for v, t in sorted(s.lengths + s.numbers, key=lambda vt: vt[1].i0)]  # as said: "3 by 2 meters"
        if not sides or len(sides) > (2 if shape == "rectangle" else 1):
            example = {"rectangle": "a rectangle 2 meters by 1 meter", "back_and_forth": "back and forth 2 meters"}
            raise InstructionError(f"\"{where}\": how long are the sides? e.g. \"walk "
                                   f"{example.get(shape, f'a {shape} of 1 meter')}\"")
        speed = self._speed(one)
        if shape == "back_and_forth":
            return [Walk(sides[0], speed_mps=speed), Walk(sides[0], direction="backward", speed_mps=speed)]
        turn = one("directions", "direction") or "left"
        if turn not in ("left", "right"):
            raise InstructionError(f"\"{where}\": a {shape} turns left or right, not {turn}")
        if shape == "rectangle":
            long, short = sides if len(sides) == 2 else (sides[0], sides[0])
            return [Repeat(2, [Walk(long, speed_mps=speed), Turn(math.pi / 2, turn), Walk(short, speed_mps=speed),
                               Turn(math.pi / 2, turn)])]
        corners = {"square": 4, "triangle": 3}[shape]
        return [Repeat(corners, [Walk(sides[0], speed_mps=speed), Turn(2 * math.pi / corners, turn)])]

    def _circle(self, s: _Slots, where, one, take) -> Repeat:
        """'walk in a circle (with a radius of 2 m) (to the right)': a regular octagon around it, 8 x (walk
        2 pi r / 8, turn 45 degrees that way); a half circle is 4 of those, a quarter 2."""
        take("circle", "sizes")
        arc = one("angles", "circle")
        size = one("lengths", "radius")
        if size is None:
            size = one("numbers", "number")
        radius = 1.0 if size is None else size / 2 if any(v == "DIAMETER" for v, _ in s.sizes) else size
        if radius <= 0:
            raise InstructionError(f"\"{where}\": a circle needs a radius above zero")
        turn = one("directions", "direction") or "left"
        if turn not in ("left", "right"):
            raise InstructionError(f"\"{where}\": a circle turns left or right, not {turn}")
        segments = max(1, round(8 * arc / (2 * math.pi)))
        return Repeat(segments, [Walk(2 * math.pi * radius / 8, speed_mps=self._speed(one)), Turn(math.pi / 4, turn)])

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
        take("around", "back", "circle")
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


class BuildState:
    """What the clauses so far have established: the last place named ('it'), the held object."""

    def __init__(self, words: list[str]) -> None:
        self.words = words
        self.last_place: str | None = None
        self.held: str | None = None
        self.last_sentence = (0, 0)
        self.pending_hand: str | None = None
        """A hand named in a clause of its own ("with your left hand, reach ..."), for the next reach."""

    def text(self, t: Tok) -> str:
        return join_words(self.words[t.i0:t.i1])

    def span(self, toks: list[Tok]) -> str:
        return join_words(self.words[toks[0].i0:toks[-1].i1]) if toks else ""

    def resolve(self, name: str, t: Tok) -> str:
        if name == "IT":
            if self.last_place is None:
                raise InstructionError(f"\"{self.text(t)}\" does not refer to anything yet; name the object")
            return self.last_place
        self.last_place = name
        return name


def _main_verb(s: _Slots) -> str | None:
    return s.verbs[0][0] if s.verbs else None


def _moves_an_object(s: _Slots) -> bool:
    """'move the box 1 meter to the right': one object (no preposition), a distance or time, no target."""
    return (len(s.places) == 1 and s.places[0][0][0] is None and bool(s.lengths or s.durations)
            and any(d in ("forward", "backward", "left", "right") for d, _ in s.directions))


def _one_of(s: _Slots, where: str, state: BuildState):
    """The `one(slot, what)` reader of _build for a slot set of its own."""
    def one(name: str, what: str):
        items = getattr(s, name)
        if len(items) > 1:
            raise InstructionError(f"\"{where}\": more than one {what} "
                                   f"(\"{state.text(items[0][1])}\" and \"{state.text(items[1][1])}\")")
        return items[0][0] if items else None
    return one
