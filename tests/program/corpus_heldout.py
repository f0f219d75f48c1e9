"""Held-out instructions for the text parser (g1_control.program.language).

How this part was made: these 60 instructions and their expected programs were written FIRST,
right after the program format (g1_control/program/steps.py) and the parser's conventions were
fixed (README "Conventions": a bare "turn left" is 90 deg, a style verb alone lasts 3 s, a wait
alone 2 s, "slowly"/"quickly" are 0.25/0.7 m/s and 0.3/1.0 rad/s, "raise your arms" is the
reach_up style, "twice" binds to its own clause, "repeat that N times" to the sentence so far),
and committed before any parser code existed. The parser was then developed against
corpus_dev.py only; this file was not read while developing and is not edited to match the
parser. tests/program/test_program_corpus.py reports its exact-match rate and failures.
"""

import math


def deg(x: float) -> float:
    return math.radians(x)


def walk(**kw):
    return {"kind": "walk", **kw}


def turn(**kw):
    return {"kind": "turn", **kw}


HELD_OUT = [
    ("walk forward three meters", [walk(distance_m=3.0)]),
    ("Please turn right 45 degrees.", [turn(angle_rad=deg(45), direction="right")]),
    ("go backward 1.5 m then wait for 2 seconds",
     [walk(distance_m=1.5, direction="backward"), {"kind": "stand", "duration_s": 2.0}]),
    ("rotate left by 180 degrees and walk forward 2 meters", [turn(angle_rad=deg(180)), walk(distance_m=2.0)]),
    ("wave for five seconds", [{"kind": "style", "name": "wave", "duration_s": 5.0}]),
    ("walk to the table and pick up the box", [walk(target="table"), {"kind": "pick", "object": "box"}]),
    ("pick up the red box and put it on the table",
     [{"kind": "pick", "object": "red_box"}, {"kind": "place", "object": "red_box", "target": "table"}]),
    ("step onto the platform, wait 3 seconds, then step down",
     [{"kind": "step_up", "platform": "platform"}, {"kind": "stand", "duration_s": 3.0}, {"kind": "step_down"}]),
    ("crouch for 4 seconds then stand up",
     [{"kind": "height", "posture": "crouch", "duration_s": 4.0}, {"kind": "height", "posture": "normal"}]),
    ("walk left 50 cm", [walk(distance_m=0.5, direction="left")]),
    ("move right two feet", [walk(distance_m=0.6096, direction="right")]),
    ("turn around and walk back to the start", [turn(angle_rad=deg(180)), walk(target="start")]),
    ("dance for ten seconds", [{"kind": "style", "name": "dance", "duration_s": 10.0}]),
    ("wave while walking forward 2 meters",
     [{"kind": "parallel", "main": walk(distance_m=2.0), "alongside": [{"kind": "style", "name": "wave"}]}]),
    ("walk forward one and a half meters slowly", [walk(distance_m=1.5, speed_mps=0.25)]),
    ("spin right 360 degrees", [turn(angle_rad=deg(360), direction="right")]),
    ("turn left twice", [{"kind": "repeat", "count": 2, "steps": [turn(angle_rad=deg(90))]}]),
    ("walk forward 1 meter and turn left 90 degrees, repeat that four times",
     [{"kind": "repeat", "count": 4, "steps": [walk(distance_m=1.0), turn(angle_rad=deg(90))]}]),
    ("reach for the cup with your left hand", [{"kind": "reach", "hand": "left", "target": "cup"}]),
    ("touch the wall with your right hand", [{"kind": "reach", "target": "wall"}]),
    ("put the box down", [{"kind": "place", "object": "box"}]),
    ("go to the other table", [walk(target="other_table")]),
    ("face the door", [turn(target="door")]),
    ("walk forward for 4 seconds at 0.3 m/s", [walk(duration_s=4.0, speed_mps=0.3)]),
    ("wait 1 second and then turn right",
     [{"kind": "stand", "duration_s": 1.0}, turn(angle_rad=deg(90), direction="right")]),
    ("after walking two meters, turn left", [walk(distance_m=2.0), turn(angle_rad=deg(90))]),
    ("turn right after you walk 3 meters", [walk(distance_m=3.0), turn(angle_rad=deg(90), direction="right")]),
    ("look around for 3 seconds", [{"kind": "style", "name": "look_around", "duration_s": 3.0}]),
    ("switch to the guard style and walk forward 1 m", [{"kind": "style", "name": "guard"}, walk(distance_m=1.0)]),
    ("walk to the box while looking around",
     [{"kind": "parallel", "main": walk(target="box"), "alongside": [{"kind": "style", "name": "look_around"}]}]),
    ("raise your arms", [{"kind": "style", "name": "reach_up", "duration_s": 3.0}]),
    ("lower your pelvis to 0.6 meters", [{"kind": "height", "pelvis_height_m": 0.6}]),
    ("walk back 2 meters", [walk(distance_m=2.0, direction="backward")]),
    ("climb onto the platform", [{"kind": "step_up", "platform": "platform"}]),
    ("get off the platform", [{"kind": "step_down", "platform": "platform"}]),
    ("bring the blue box to the shelf",
     [{"kind": "pick", "object": "blue_box"}, {"kind": "place", "object": "blue_box", "target": "shelf"}]),
    ("turn left 30 degrees three times", [{"kind": "repeat", "count": 3, "steps": [turn(angle_rad=deg(30))]}]),
    ("walk forward 2 meters with your arms out",
     [{"kind": "parallel", "main": walk(distance_m=2.0), "alongside": [{"kind": "style", "name": "arms_out"}]}]),
    ("pause for half a second", [{"kind": "stand", "duration_s": 0.5}]),
    ("turn to face the chair and walk to it", [turn(target="chair"), walk(target="chair")]),
    ("walk forward 80 cm; turn right 90 degrees; walk forward 80 cm",
     [walk(distance_m=0.8), turn(angle_rad=deg(90), direction="right"), walk(distance_m=0.8)]),
    ("grab the ball with both hands", [{"kind": "pick", "object": "ball"}]),
    ("place the ball on the chair", [{"kind": "place", "object": "ball", "target": "chair"}]),
    ("sidestep left 0.3 meters", [walk(distance_m=0.3, direction="left")]),
    ("turn 90 degrees to the right", [turn(angle_rad=deg(90), direction="right")]),
    ("walk forward a couple of meters then dance",
     [walk(distance_m=2.0), {"kind": "style", "name": "dance", "duration_s": 3.0}]),
    ("step back half a meter", [walk(distance_m=0.5, direction="backward")]),
    ("walk quickly to the door", [walk(target="door", speed_mps=0.7)]),
    ("first wave, then walk forward 5 meters",
     [{"kind": "style", "name": "wave", "duration_s": 3.0}, walk(distance_m=5.0)]),
    ("reach forward 20 cm with your right hand", [{"kind": "reach", "offset_m": [0.2, 0.0, 0.0]}]),
    ("rotate 1.57 radians to the left", [turn(angle_rad=1.57)]),
    ("walk 3 meters at 0.6 meters per second", [walk(distance_m=3.0, speed_mps=0.6)]),
    ("swing your arms while walking forward 4 meters",
     [{"kind": "parallel", "main": walk(distance_m=4.0), "alongside": [{"kind": "style", "name": "arm_swing"}]}]),
    ("pick up the box, turn around, and put it on the table",
     [{"kind": "pick", "object": "box"}, turn(angle_rad=deg(180)),
      {"kind": "place", "object": "box", "target": "table"}]),
    ("stand still for 3 seconds", [{"kind": "stand", "duration_s": 3.0}]),
    ("turn right slowly", [turn(angle_rad=deg(90), direction="right", yaw_rate_radps=0.3)]),
    ("crouch and walk forward 1 meter", [{"kind": "height", "posture": "crouch"}, walk(distance_m=1.0)]),
    ("walk forward until you reach the wall", [walk(target="wall")]),
    ("robot, go forward two meters and wave twice",
     [walk(distance_m=2.0), {"kind": "repeat", "count": 2, "steps": [{"kind": "style", "name": "wave",
                                                                      "duration_s": 3.0}]}]),
    ("turn left 90 degrees and walk to the table within 20 seconds",
     [turn(angle_rad=deg(90)), walk(target="table", timeout_s=20.0)]),
]
