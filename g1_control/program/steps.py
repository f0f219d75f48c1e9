"""The primitive steps of a behaviour program: typed, validated, serialisable.

Units are in the field names (m, s, rad, m/s, rad/s). Angles are stored in radians; text and
`describe()` speak degrees. A field left at its default (None, "forward", ...) is left out of
`to_dict()`, so a hand-written program states only what it means.

Completion conditions follow from the parameters (see `Step.condition`):
distance covered, heading reached, place reached, goal reached (execution layer), time elapsed;
every step also has a timeout (`timeout_s`, or a default from ProgramRunner's RunnerConfig).
"""

from __future__ import annotations

import math
from dataclasses import MISSING, dataclass, fields
from typing import Any, ClassVar

from g1_control.generator.styles import STYLES
from g1_control.program.exceptions import ProgramError

DIRECTIONS = ("forward", "backward", "left", "right")
TURN_DIRECTIONS = ("left", "right")
HANDS = ("left", "right", "both")
POSTURES = ("crouch", "normal", "tall")
MAX_SPEED_MPS = 1.5
MAX_YAW_RATE_RADPS = 2.0
MAX_TURN_RAD = 4 * math.pi
PELVIS_HEIGHT_RANGE_M = (0.3, 0.9)
MAX_REACH_OFFSET_M = 1.0
MAX_REPEAT = 100


def _fmt(x: float | None) -> str:
    return "?" if x is None else f"{x:.3g}"  # None only on a step that fails validation


def _deg(x: float) -> str:
    return f"{math.degrees(x):.3g} deg"


@dataclass  # no fields of its own; makes `fields()` of any Step well-typed
class Step:
    """Base of every step. Subclasses are dataclasses with a class-level `kind`."""

    kind: ClassVar[str] = ""

    # --- validation -------------------------------------------------------------------------
    def validate(self, where: str = "") -> Step:
        """Raise ProgramError naming the step and field of the first bad value; return self."""
        self._check(where or f"step ({self.kind})")
        return self

    def _check(self, where: str) -> None:  # overridden
        raise NotImplementedError

    def condition(self) -> str:
        """What completes the step: 'distance', 'heading', 'place', 'goal', 'time', 'instant',
        'main' (parallel), 'children' (repeat)."""
        raise NotImplementedError

    def describe(self) -> str:
        raise NotImplementedError

    # --- serialisation ----------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind}
        for f in fields(self):
            value = getattr(self, f.name)
            if value is None or (f.default is not MISSING and value == f.default):
                continue
            if isinstance(value, Step):
                value = value.to_dict()
            elif isinstance(value, (list, tuple)) and value and isinstance(value[0], Step):
                value = [s.to_dict() for s in value]
            elif isinstance(value, tuple):
                value = list(value)
            out[f.name] = value
        return out

    @staticmethod
    def from_dict(data: Any, where: str = "step") -> Step:
        """Build (and validate) a step from its dict form; unknown kinds and fields are refused."""
        if not isinstance(data, dict):
            raise ProgramError(f"{where}: a step must be a mapping with a 'kind'; got {type(data).__name__}")
        kind = data.get("kind")
        cls = STEP_TYPES.get(kind) if isinstance(kind, str) else None
        if cls is None:
            raise ProgramError(f"{where}.kind: unknown step kind {kind!r}; known: {', '.join(STEP_TYPES)}")
        where = f"{where} ({kind})"
        known = {f.name: f for f in fields(cls)}
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if key == "kind":
                continue
            if key not in known:
                raise ProgramError(f"{where}: unknown field '{key}'; known: {', '.join(known)}")
            kwargs[key] = _convert(cls, key, value, f"{where}.{key}")
        try:
            step = cls(**kwargs)
        except TypeError as exc:  # a required field is missing
            missing = [n for n, f in known.items() if n not in kwargs and _required(f)]
            raise ProgramError(f"{where}: missing field(s) {', '.join(missing) or '?'}") from exc
        step._check(where)
        return step


def _required(f) -> bool:
    return f.default is MISSING and f.default_factory is MISSING


_STEP_FIELDS = {"main"}
_STEP_LIST_FIELDS = {"alongside", "steps"}
_TUPLE_FIELDS = {"offset_m"}
_INT_FIELDS = {"count"}
_STR_FIELDS = {"direction", "target", "name", "posture", "hand", "hands", "object", "platform"}


def _convert(cls, key: str, value: Any, where: str) -> Any:
    if key in _STEP_FIELDS:
        return Step.from_dict(value, where)
    if key in _STEP_LIST_FIELDS:
        if not isinstance(value, list):
            raise ProgramError(f"{where}: must be a list of steps; got {type(value).__name__}")
        return [Step.from_dict(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if key in _TUPLE_FIELDS:
        if not isinstance(value, (list, tuple)) or len(value) != 3:
            raise ProgramError(f"{where}: must be 3 numbers (x forward, y left, z up; m); got {value!r}")
        return tuple(_number(v, where) for v in value)
    if key in _INT_FIELDS:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ProgramError(f"{where}: must be a whole number; got {value!r}")
        return value
    if key in _STR_FIELDS:
        if not isinstance(value, str):
            raise ProgramError(f"{where}: must be a string; got {value!r}")
        return value
    return _number(value, where)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ProgramError(f"{where}: must be a number; got {value!r}")
    return float(value)


# --- field checks shared by the steps --------------------------------------------------------
def _positive(where: str, name: str, value: float | None, upper: float | None = None) -> None:
    if value is None:
        return
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ProgramError(f"{where}.{name}: must be a finite number; got {value!r}")
    if value <= 0:
        raise ProgramError(f"{where}.{name}: must be > 0; got {value:g}")
    if upper is not None and value > upper:
        raise ProgramError(f"{where}.{name}: must be <= {upper:g}; got {value:g}")


def _finite(where: str, name: str, value: float | None) -> None:
    if value is None:
        return
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ProgramError(f"{where}.{name}: must be a finite number; got {value!r}")


def _choice(where: str, name: str, value: Any, options: tuple[str, ...]) -> None:
    if value not in options:
        raise ProgramError(f"{where}.{name}: {value!r} is not one of {', '.join(options)}")


def _name(where: str, name: str, value: Any, required: bool) -> None:
    if value is None:
        if required:
            raise ProgramError(f"{where}.{name}: an object name is required")
        return
    if not isinstance(value, str) or not value or value != value.strip() or " " in value:
        raise ProgramError(f"{where}.{name}: must be an object name without spaces (e.g. 'other_table'); "
                           f"got {value!r}")


def _exactly_one(where: str, names: tuple[str, ...], values: tuple[Any, ...]) -> None:
    given = [n for n, v in zip(names, values) if v is not None]
    if len(given) != 1:
        got = "none" if not given else " and ".join(given)
        raise ProgramError(f"{where}: needs exactly one of {', '.join(names)}; got {got}")


def _timeout_text(timeout_s: float | None) -> str:
    return f" (timeout {_fmt(timeout_s)} s)" if timeout_s is not None else ""


# --- the primitives ---------------------------------------------------------------------------
@dataclass
class Walk(Step):
    """Walk a distance, for a time, or to a named place. `direction` is relative to the robot's
    heading when the step starts; `heading_rad` walks forward along a world heading instead.
    A walk to a place stops at the place's standoff distance (World) facing it."""

    kind: ClassVar[str] = "walk"
    distance_m: float | None = None
    duration_s: float | None = None
    target: str | None = None
    direction: str = "forward"
    heading_rad: float | None = None
    speed_mps: float | None = None
    """None: the runner's default speed for the direction."""
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _exactly_one(where, ("distance_m", "duration_s", "target"), (self.distance_m, self.duration_s, self.target))
        _positive(where, "distance_m", self.distance_m)
        _positive(where, "duration_s", self.duration_s)
        _name(where, "target", self.target, required=False)
        _choice(where, "direction", self.direction, DIRECTIONS)
        _finite(where, "heading_rad", self.heading_rad)
        if self.heading_rad is not None and self.direction != "forward":
            raise ProgramError(f"{where}.heading_rad: a walk along a heading goes forward; got direction "
                               f"{self.direction!r}")
        if self.target is not None and (self.direction != "forward" or self.heading_rad is not None):
            raise ProgramError(f"{where}.target: a walk to a place faces it; direction and heading_rad must "
                               "be left out")
        _positive(where, "speed_mps", self.speed_mps, MAX_SPEED_MPS)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "distance" if self.distance_m is not None else "place" if self.target is not None else "time"

    def describe(self) -> str:
        if self.target is not None:
            text = f"walk to {self.target}"
        else:
            how = f"at heading {_deg(self.heading_rad)}" if self.heading_rad is not None else self.direction
            amount = f"{_fmt(self.distance_m)} m" if self.distance_m is not None else f"for {_fmt(self.duration_s)} s"
            text = f"walk {how} {amount}"
        if self.speed_mps is not None:
            text += f" at {_fmt(self.speed_mps)} m/s"
        return text + _timeout_text(self.timeout_s)


@dataclass
class Turn(Step):
    """Turn in place by an angle (left = counter-clockwise), to a world heading, or to face a place."""

    kind: ClassVar[str] = "turn"
    angle_rad: float | None = None
    direction: str = "left"
    heading_rad: float | None = None
    target: str | None = None
    yaw_rate_radps: float | None = None
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _exactly_one(where, ("angle_rad", "heading_rad", "target"), (self.angle_rad, self.heading_rad, self.target))
        _positive(where, "angle_rad", self.angle_rad, MAX_TURN_RAD)
        _choice(where, "direction", self.direction, TURN_DIRECTIONS)
        if self.angle_rad is None and self.direction != "left":
            raise ProgramError(f"{where}.direction: only a turn by an angle has a direction; "
                               "a turn to a heading or a place takes the shorter way")
        _finite(where, "heading_rad", self.heading_rad)
        _name(where, "target", self.target, required=False)
        _positive(where, "yaw_rate_radps", self.yaw_rate_radps, MAX_YAW_RATE_RADPS)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "heading"

    def describe(self) -> str:
        if self.angle_rad is not None:
            text = f"turn {self.direction} {_deg(self.angle_rad)}"
        elif self.heading_rad is not None:
            text = f"turn to heading {_deg(self.heading_rad)}"
        else:
            text = f"turn to face {self.target}"
        if self.yaw_rate_radps is not None:
            text += f" at {math.degrees(self.yaw_rate_radps):.3g} deg/s"
        return text + _timeout_text(self.timeout_s)


@dataclass
class Stand(Step):
    """Stand still (wait) for a time."""

    kind: ClassVar[str] = "stand"
    duration_s: float

    def _check(self, where: str) -> None:
        _positive(where, "duration_s", self.duration_s)

    def condition(self) -> str:
        return "time"

    def describe(self) -> str:
        return f"stand still for {_fmt(self.duration_s)} s"


@dataclass
class Style(Step):
    """An upper-body style (g1_control.generator.styles.STYLES). With a duration: stand and hold it
    that long, then return to the style before. Without: switch to it for the steps that follow
    (completes at once). Inside a Parallel: held while the main step runs (no duration)."""

    kind: ClassVar[str] = "style"
    name: str
    duration_s: float | None = None

    def _check(self, where: str) -> None:
        if self.name not in STYLES:
            raise ProgramError(f"{where}.name: unknown style {self.name!r}; known styles: {', '.join(STYLES)}")
        _positive(where, "duration_s", self.duration_s)

    def condition(self) -> str:
        return "time" if self.duration_s is not None else "instant"

    def describe(self) -> str:
        if self.duration_s is None:
            return f"style {self.name} from now on"
        return f"{self.name} for {_fmt(self.duration_s)} s"


@dataclass
class Height(Step):
    """Pelvis height: a number, or a posture (crouch / normal / tall; heights in RunnerConfig).
    With a duration: hold it that long, then return to the height before; without: keep it for
    the steps that follow (completes once the runner's settle time has passed)."""

    kind: ClassVar[str] = "height"
    pelvis_height_m: float | None = None
    posture: str | None = None
    duration_s: float | None = None

    def _check(self, where: str) -> None:
        _exactly_one(where, ("pelvis_height_m", "posture"), (self.pelvis_height_m, self.posture))
        if self.pelvis_height_m is not None:
            _finite(where, "pelvis_height_m", self.pelvis_height_m)
            lo, hi = PELVIS_HEIGHT_RANGE_M
            if not lo <= self.pelvis_height_m <= hi:
                raise ProgramError(f"{where}.pelvis_height_m: must be within [{lo}, {hi}] m; "
                                   f"got {self.pelvis_height_m:g}")
        if self.posture is not None:
            _choice(where, "posture", self.posture, POSTURES)
        _positive(where, "duration_s", self.duration_s)

    def condition(self) -> str:
        return "time"

    def describe(self) -> str:
        what = self.posture if self.posture is not None else f"pelvis height {_fmt(self.pelvis_height_m)} m"
        return what + (f" for {_fmt(self.duration_s)} s" if self.duration_s is not None else "")


@dataclass
class Reach(Step):
    """Put a hand at a named place, or at an offset (x forward, y left, z up; m, in the robot's
    heading frame) from that place or, without a place, from the hand's standing position."""

    kind: ClassVar[str] = "reach"
    hand: str = "right"
    target: str | None = None
    offset_m: tuple[float, float, float] | None = None
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _choice(where, "hand", self.hand, HANDS)
        _name(where, "target", self.target, required=False)
        if self.target is None and self.offset_m is None:
            raise ProgramError(f"{where}: needs a target, an offset_m, or both")
        if self.offset_m is not None:
            if len(self.offset_m) != 3:
                raise ProgramError(f"{where}.offset_m: must be 3 numbers; got {self.offset_m!r}")
            for v in self.offset_m:
                _finite(where, "offset_m", v)
            if math.sqrt(sum(v * v for v in self.offset_m)) > MAX_REACH_OFFSET_M:
                raise ProgramError(f"{where}.offset_m: longer than {MAX_REACH_OFFSET_M} m; got {self.offset_m!r}")
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "goal"

    def describe(self) -> str:
        hand = "both hands" if self.hand == "both" else f"{self.hand} hand"
        parts = []
        if self.offset_m is not None:
            parts.append("offset (" + ", ".join(_fmt(v) for v in self.offset_m) + ") m")
        if self.target is not None:
            parts.append(f"{'from' if self.offset_m is not None else 'to'} {self.target}")
        return f"reach with {hand} " + " ".join(parts) + _timeout_text(self.timeout_s)


@dataclass
class Pick(Step):
    """Pick up a named object (the execution layer walks to it, grasps and lifts)."""

    kind: ClassVar[str] = "pick"
    object: str
    hands: str = "both"
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _name(where, "object", self.object or None, required=True)
        _choice(where, "hands", self.hands, HANDS)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "goal"

    def describe(self) -> str:
        hands = "" if self.hands == "both" else f" with the {self.hands} hand"
        return f"pick up {self.object}{hands}" + _timeout_text(self.timeout_s)


@dataclass
class Place(Step):
    """Put a held object on a named surface or point (the execution layer carries it there);
    without a target: put it down in front of the robot."""

    kind: ClassVar[str] = "place"
    object: str
    target: str | None = None
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _name(where, "object", self.object or None, required=True)
        _name(where, "target", self.target, required=False)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "goal"

    def describe(self) -> str:
        where = f"on {self.target}" if self.target is not None else "down"
        return f"place {self.object} {where}" + _timeout_text(self.timeout_s)


@dataclass
class StepUp(Step):
    """Step up onto a named platform."""

    kind: ClassVar[str] = "step_up"
    platform: str
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _name(where, "platform", self.platform or None, required=True)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "goal"

    def describe(self) -> str:
        return f"step up onto {self.platform}" + _timeout_text(self.timeout_s)


@dataclass
class StepDown(Step):
    """Step down from a platform (None: the one the robot stands on)."""

    kind: ClassVar[str] = "step_down"
    platform: str | None = None
    timeout_s: float | None = None

    def _check(self, where: str) -> None:
        _name(where, "platform", self.platform, required=False)
        _positive(where, "timeout_s", self.timeout_s)

    def condition(self) -> str:
        return "goal"

    def describe(self) -> str:
        return "step down" + (f" from {self.platform}" if self.platform else "") + _timeout_text(self.timeout_s)


def _kind_of(value: object) -> str:
    """A step's kind, or the type of what stands where a step should (bad input)."""
    return value.kind if isinstance(value, Step) else type(value).__name__


LOCOMOTION = (Walk, Turn, Stand)
ALONGSIDE = (Style, Height, Reach)


@dataclass
class Parallel(Step):
    """Run upper-body / posture behaviours alongside a locomotion step ("wave while walking to the
    table"). The main step decides completion; the others last as long as it does."""

    kind: ClassVar[str] = "parallel"
    main: Step
    alongside: list[Step]

    def _check(self, where: str) -> None:
        if not isinstance(self.main, LOCOMOTION):
            raise ProgramError(f"{where}.main: must be a walk, turn or stand step; got {_kind_of(self.main)!r}")
        self.main._check(f"{where}.main ({self.main.kind})")
        if not self.alongside:
            raise ProgramError(f"{where}.alongside: needs at least one style, height or reach step")
        for i, s in enumerate(self.alongside):
            w = f"{where}.alongside[{i}] ({s.kind if isinstance(s, Step) else '?'})"
            if not isinstance(s, ALONGSIDE):
                raise ProgramError(f"{w}: only style, height and reach steps run alongside; got {_kind_of(s)!r}")
            if isinstance(s, (Style, Height)) and s.duration_s is not None:
                raise ProgramError(f"{w}.duration_s: a step alongside lasts as long as the main step; leave it out")
            s._check(w)

    def condition(self) -> str:
        return "main"

    def describe(self) -> str:
        side = (s.name if isinstance(s, Style) else s.describe().replace(" from now on", "") for s in self.alongside)
        return self.main.describe() + ", while: " + ", ".join(side)


@dataclass
class Repeat(Step):
    """Run `steps` `count` times in all."""

    kind: ClassVar[str] = "repeat"
    count: int
    steps: list[Step]

    def _check(self, where: str) -> None:
        if isinstance(self.count, bool) or not isinstance(self.count, int) or not 1 <= self.count <= MAX_REPEAT:
            raise ProgramError(f"{where}.count: must be a whole number in [1, {MAX_REPEAT}]; got {self.count!r}")
        if not self.steps:
            raise ProgramError(f"{where}.steps: needs at least one step")
        for i, s in enumerate(self.steps):
            if not isinstance(s, Step):
                raise ProgramError(f"{where}.steps[{i}]: not a step; got {type(s).__name__}")
            s._check(f"{where}.steps[{i}] ({s.kind})")

    def to_dict(self) -> dict[str, Any]:  # count is always written, even at its default
        return {"kind": self.kind, "count": self.count, "steps": [s.to_dict() for s in self.steps]}

    def condition(self) -> str:
        return "children"

    def describe(self) -> str:
        return f"repeat {self.count} times: " + "; ".join(s.describe() for s in self.steps)


STEP_TYPES: dict[str, type[Step]] = {c.kind: c for c in (
    Walk, Turn, Stand, Style, Height, Reach, Pick, Place, StepUp, StepDown, Parallel, Repeat)}


def iter_named_places(step: Step):
    """Yield (field path, name) of every object/place name a step refers to."""
    target = step.target if isinstance(step, (Walk, Turn, Reach, Place)) else None
    obj = step.object if isinstance(step, (Pick, Place)) else None
    platform = step.platform if isinstance(step, (StepUp, StepDown)) else None
    for attr, value in (("target", target), ("object", obj), ("platform", platform)):
        if value:
            yield attr, value
    if isinstance(step, Parallel):
        yield from (("main." + p, n) for p, n in iter_named_places(step.main))
        for i, s in enumerate(step.alongside):
            yield from ((f"alongside[{i}].{p}", n) for p, n in iter_named_places(s))
    if isinstance(step, Repeat):
        for i, s in enumerate(step.steps):
            yield from ((f"steps[{i}].{p}", n) for p, n in iter_named_places(s))


GOAL_STEPS = (Reach, Pick, Place, StepUp, StepDown)
TIMED_STEPS = (Walk, Turn, Reach, Pick, Place, StepUp, StepDown)
"""Steps with a `timeout_s` of their own."""
"""Steps the execution layer carries out (task goals)."""


def iter_steps(step: Step):
    """The step and every step inside it (a parallel's main and alongside, a repeat's steps)."""
    yield step
    if isinstance(step, Parallel):
        yield from iter_steps(step.main)
        for s in step.alongside:
            yield from iter_steps(s)
    if isinstance(step, Repeat):
        for s in step.steps:
            yield from iter_steps(s)
