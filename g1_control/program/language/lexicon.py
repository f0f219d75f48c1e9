"""The words the instruction parser knows: phrases -> canonical tokens, numbers, units, fillers, places.

Every table is data. A phrase line reads "pattern | pattern => TOKEN TOKEN"; patterns are written
without filler words (they are dropped first), the longest pattern wins. Canonical tokens are upper
case (WALK, TURN, STYLE:wave, HAND:left, ...); words a phrase does not rewrite (numbers, units,
prepositions) pass through in lower case.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

FILLERS = frozenset(["please", "kindly", "the", "your", "you", "yourself", "robot", "now", "just", "ok", "okay", "hey", "also", "again", "carefully", "still", "can", "could", "would", "my", "its",
                     "here", "there", "me", "us", "little", "some",
                     # issue 27's everyday set: hedges and spoken fillers
                     "about", "roughly", "approximately", "like", "um", "uh", "erm", "so",
                     "alright", "real", "really"])
"""Dropped before anything else ("please", "the", "robot", ...)."""

ARTICLES = frozenset({"a", "an"})
"""Dropped unless they are a number ("a meter", "a couple of", "half a second")."""

PHRASES = """
# connectives
and then | after that | afterwards | afterward | next | finally | lastly | then | and | first of all | first
    | followed by | once done | when done | when finished => THEN
while | as | meanwhile => WHILE
after => AFTER
after reach | after reaching | after arriving at | after arrive at | after get to | after getting to
    | when reach | when get to | when arrive at | once reach | once at | once get to => AFTER WALK to
before => BEFORE
twice => COUNT:2
thrice => COUNT:3
once => COUNT:1
times | time => TIMES
repeat | repeat that | repeat this | repeat it | do that | do this | do it | do that again | do it again
    | do this again | repeat again | once more | do same => REPEAT
until reach | until reaching | until get to | until arrive at | until arriving at | until at => to
until face | until facing => toward
# filler phrases
i want to | i would like to | i to | i'd to | i need to | go ahead and | make sure to | try to | start by | let us | lets
    | keep | keep on | with sides of | sides of | sides | side length of | side length | on each side | each side
    | per side | a bit | bit => 
at same time | simultaneously | in parallel | at once while | together => SAMETIME
square => SHAPE:square
triangle => SHAPE:triangle
rectangle | oblong => SHAPE:rectangle
back and forth | to and fro | backward and forward | backwards and forwards => SHAPE:back_and_forth
radius | radius of | with radius of => RADIUS
diameter | diameter of | with diameter of | across => DIAMETER
# locomotion
walk | walking | walks | go | going | goes | move | moving | moves | head | travel | proceed | come | coming
    | step | stepping | march | marching | sidestep | side step | strafe | shuffle | shuffling | advance
    | advancing | scoot | scooting | pace | pacing | make way | make way over => WALK
jog | jogging | run | running | hurry | hurrying | rush | rushing | dash => WALK SPEED:fast
stroll | strolling | amble | ambling | saunter | sauntering => WALK SPEED:slow
retreat | retreating => WALK backward
return | returning | go back | come back | head back | walk back to | get back | move back => WALK back
approach | approaching => WALK to
back up | backing up | reverse => WALK backward
forward | forwards | ahead | straight ahead | straight | onward => forward
backward | backwards | in reverse => backward
back => back
left | leftward | leftwards | to left | towards left | toward left | counterclockwise | anticlockwise
    | counter clockwise | anti clockwise => left
right | rightward | rightwards | to right | towards right | toward right | clockwise => right
sideways => SIDEWAYS
around | round => around
up | upward | upwards | above => up
over to | over towards | over toward | up to => to
left turn => left
right turn => right
u turn | uturn => ANGLE:180
down | downward | downwards | below | under | beneath => down
turn | turning | turns | spin | spinning | rotate | rotating | pivot | pivoting => TURN
turn to face | turn and face | face | facing | look at | looking at | look towards | look toward => FACE
face other way | turn other way | look other way | face opposite way | face opposite direction => TURN around
quarter turn | quarter of turn => ANGLE:90
half turn | half of turn => ANGLE:180
full turn | full rotation | complete turn | whole turn | full spin | full revolution | complete rotation => ANGLE:360
quarter circle => ANGLE:90 CIRCLE
half circle | semicircle | semi circle => ANGLE:180 CIRCLE
full circle | complete circle | circle | whole circle => ANGLE:360 CIRCLE
heading | at heading | to heading | along heading | with heading | heading of => HEADING
slowly | slow | slower | gently | slow pace | slow speed | leisurely pace | low speed => SPEED:slow
quickly | quick | fast | faster | rapidly | briskly | swiftly | fast pace | quick pace | brisk pace | high speed
    | fast speed => SPEED:fast
within | in under | in less than | at most | no more than | no longer than => WITHIN
wait | waiting | pause | pausing | stay | staying | rest | resting | stop | stopping | halt | hold | stand
    | standing | stand still | stay still | hold still | keep still | remain | stay put | freeze | wait there
    | hang on | hold on | chill => WAIT
# styles
wave | waving | waves | wave hand | wave hands | waving hand | wave hello | wave goodbye | say hello
    | wave your hand => STYLE:wave
dance | dancing | dances => STYLE:dance
look around | looking around | looks around | glance around | glancing around => STYLE:look_around
swing arms | swinging arms | arm swing | arms swinging | swing arm | swinging arm => STYLE:arm_swing
arms out | arms spread | spread arms | spreading arms | stretch arms out | stretch out arms | hold arms out
    | holding arms out | put arms out | with arms out | arms outstretched | outstretched arms
    | with arms spread | arms wide | with outstretched arms | arms spread out | spread arms out
    | spread out arms | with arms spread out | arms stretched out | with arms stretched out => STYLE:arms_out
guard | guard up | put guard up | raise guard | guarding | on guard | with guard up => STYLE:guard
reach up | reaching up | raise arms | raising arms | raise hands | raising hands | hands up | arms up
    | put hands up | put arms up | lift arms | with hands up | with arms up | arms raised | with arms raised
    | raised arms | with raised arms | hold arms up | hold hands up | arms in air | hands in air => STYLE:reach_up
arms down | lower arms | relax arms | put arms down | normal style | default style | default => STYLE:default
carry | carrying | carries | bring | bringing | deliver | delivering | haul | hauling => CARRY
lift | lifting => LIFT
climb | climbing => CLIMB
style | pose | mode | posture | stance => STYLEWORD
use | using style | switch to | change to | switch into | change into | set style to | set style | adopt
    | assume | switch | go into | get into => SELECT
# height
crouch | crouching | crouched | squat | squatting | duck | ducking | get down | crouch down | squat down
    | go low | get low | bend knees | bend down | crouch low | crouch down low | squat low | squat down low
    | get down low | duck down => HEIGHT:crouch
stand up | get up | rise | straighten up | normal height | get back up | stand back up | come back up
    | get up again | stand up again => HEIGHT:normal
stand tall | stand up tall | stand up straight | stand straight | standing tall | stand at full height
    | stand upright => HEIGHT:tall
lower | raise | set height | set pelvis height | height | set pelvis | change height => HEIGHTSET
pelvis | body | hips | hip | torso | pelvis height => BODY
# manipulation and stepping
reach | reaching | touch | touching | stretch | stretching | extend | extending => REACH
reach out | reaching out | stretch out | extend out => REACH OUT
pick up | picking up | pick | grab | grabbing | grasp | grasping | take | taking | take hold of
    | get hold of | collect | fetch | lift up => PICK
put | putting | place | placing | set | set down | put down | drop off | leave | deposit | lay | lay down
    | place down | drop | dropping | drop down => PLACE
step up onto | step up on | step up to | step up | step onto | step on | climb onto | climb on
    | climb up onto | climb up on | climb up | get on | get onto | get up on | get up onto | go up onto
    | go up on | mount | step on top of | climb on top of => STEPUP
step down from | step down off | step down | step off | step off of | get off | get off of | get down from
    | climb down from | climb down off | climb down | climb off | go down from | step down off of
    | get down off | get down off of | step back down | get back down | come back down | climb back down
    | step down again => STEPDOWN
left hand | left arm | with left hand | with left arm | using left hand | using left arm => HAND:left
right hand | right arm | with right hand | with right arm | using right hand | using right arm => HAND:right
both hands | both arms | two hands | with both hands | with both arms | with two hands | using both hands
    | using two hands | two handed | with two arms => HAND:both
it | that | them | this one | that one => IT
# prepositions and glue (kept as lower-case words)
to | toward | towards | onto | on | into | in | at | from | off | of | for | by | with | near => PREP
on top of => onto
next to | in front of | beside => near
"""
"""Rewrites, longest first. "=> PREP" keeps the words themselves (they are glue with a role)."""

NUMBER_WORDS = {
    "zero": 0, "one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8,
    "nine": 9, "ten": 10, "eleven": 11, "twelve": 12, "thirteen": 13, "fourteen": 14, "fifteen": 15,
    "sixteen": 16, "seventeen": 17, "eighteen": 18, "nineteen": 19,
}
TENS_WORDS = {"twenty": 20, "thirty": 30, "forty": 40, "fifty": 50, "sixty": 60, "seventy": 70, "eighty": 80,
              "ninety": 90}
FRACTION_WORDS = {"half": 0.5, "quarter": 0.25}
NUMBER_GLUE = frozenset({"hundred", "point", "and"})

# unit word -> (dimension, factor to SI)
UNITS: dict[str, tuple[str, float]] = {}
for _words, _dim, _f in (
    ("m meter meters metre metres", "length", 1.0),
    ("cm centimeter centimeters centimetre centimetres", "length", 0.01),
    ("mm millimeter millimeters millimetre millimetres", "length", 0.001),
    ("ft foot feet", "length", 0.3048),
    ("deg degree degrees °", "angle", math.pi / 180),
    ("rad rads radian radians", "angle", 1.0),
    ("s sec secs second seconds", "time", 1.0),
    ("min mins minute minutes", "time", 60.0),
    ("mps", "speed", 1.0),
    ("step steps", "length", 0.3),
):
    for _w in _words.split():
        UNITS[_w] = (_dim, _f)
STEP_M = 0.3
"""'N steps' as a distance: this much per step (UNITS['step'])."""
RATE_OF = {"length": "speed", "angle": "yaw_rate"}
PER_WORDS = frozenset({"per", "a", "/", "every", "each"})

DEFAULT_PLACES: dict[str, str] = {
    "box": "box", "red box": "red_box", "blue box": "blue_box", "table": "table", "other table": "other_table",
    "platform": "platform", "chair": "chair", "shelf": "shelf", "cup": "cup", "ball": "ball", "door": "door",
    "wall": "wall", "window": "window", "crate": "crate", "bottle": "bottle", "basket": "basket", "bin": "bin",
    "desk": "desk", "counter": "counter", "couch": "couch", "stairs": "stairs", "start": "start", "starting point": "start", "starting position": "start",
    "start position": "start", "where started": "start", "beginning": "start",
}
"""Place phrases -> names when the parser is given no world (a World's names are used instead)."""


@dataclass(frozen=True)
class Conventions:
    """Values the parser fills in when the words leave them open (README "Conventions")."""

    turn_rad: float = math.pi / 2
    """"turn left": a quarter turn."""
    around_rad: float = math.pi
    style_s: float = 3.0
    """"wave": 3 s of the style (standing)."""
    wait_s: float = 2.0
    reach_m: float = 0.3
    """"reach forward": 30 cm from the hand's standing position."""
    slow_mps: float = 0.25
    fast_mps: float = 0.7
    slow_radps: float = 0.3
    fast_radps: float = 1.0


def parse_phrase_table(text: str) -> list[tuple[tuple[str, ...], tuple[str, ...]]]:
    """Phrase lines -> [(pattern words, replacement tokens)] (continuation lines start with '|')."""
    lines: list[str] = []
    for raw in text.splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("|") and lines:
            lines[-1] += " " + line
        else:
            lines.append(line)
    out = []
    for line in lines:
        lhs, _, rhs = line.partition("=>")
        repl = tuple(rhs.split())
        for pattern in lhs.split("|"):
            words = tuple(pattern.split())
            if words:
                out.append((words, words if repl == ("PREP",) else repl))
    return out
