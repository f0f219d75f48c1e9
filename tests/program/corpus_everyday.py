"""Third held-out set (issue 27): instructions in the words people use, written before any parser change.

How this set was made: written from the program format (g1_control/program/steps.py), the grammar
README's conventions and the first two sets (so as NOT to repeat their phrasings), and committed
before the parser was read for it or changed. It is not edited to match the parser: its first
score is the blind figure (tests/program/test_program_everyday.py prints it and every miss).
It adds what a new user tries first: paraphrases and slang for walking ("jog", "stroll", "scoot"),
filler words ("hey", "like", "um", "alright"), hands named for reaching, circles and other path
shapes, carrying while walking, "stance" and "mode" for styles, and things that must be refused.

Conventions decided here, before writing (beyond those of the README and corpus_phrasing.py):
- "jog" / "run" / "hurry" = the quick walk (0.7 m/s; the robot does not run); "stroll" / "amble" /
  "real slow" = the slow walk (0.25 m/s); "march" / "advance" / "scoot" / "shuffle" = walk;
  "retreat" = walk backward.
- "about", "roughly", "like", "around" (before a number), "hey", "um", "so", "alright", "for me",
  "I'd like you to" are fillers.
- A circle is a regular octagon: "walk in a circle" = 8 x (walk 2 pi R / 8, turn 45 deg), R = 1 m
  unless a radius or diameter is given, left unless "to the right"/"clockwise"; a half circle is 4 of
  those. "a triangle with N m sides" = 3 x (walk N, turn 120); "a rectangle A by B" = 2 x (walk A,
  turn 90, walk B, turn 90); shapes turn left unless told otherwise. "back and forth N m" = walk N
  forward, then N backward (facing the same way); "N times" repeats the pair.
- "X stance" / "X mode" = the X style; "take a guard stance and walk ..." runs them in order (the
  style alone lasts 3 s, standing), "walk ... in a guard stance" runs them together.
- "a few seconds" = 3 s.
- Corrected after the blind run (two expectations that contradicted conventions in force before
  this set was written, not parser behaviour adopted after the fact): "switch to X" selects a style
  until another is chosen (corpus_dev.py "switch to guard style"), so "switch to guard mode" and
  "put your arms down" (back to the default style) carry no duration. Both were misses in the blind run.
- A named hand turns a style verb into a reach with that hand: "reach up with the right hand" /
  "raise your left hand" = a reach of 0.3 m up with that hand ("reach up" with no hand stays the
  reach_up style); "lift your right hand 20 cm" = a reach 0.2 m up; "stretch your right arm forward" =
  a reach 0.3 m forward; "put your right hand on the table" = a reach to the table with that hand.
- Carrying while walking: "carry the box forward 3 m and put it down" = pick box, walk 3 m, place box;
  "move the box 1 m to the right" = pick, walk 1 m right, place (no target); "grab the box and walk
  ... with it" = pick, walk; "fetch X" = pick X; "haul" = carry.
- "get down off/from the platform" is a step down (not a crouch); "get up on X" a step up onto X.
- "duck" / "get low" = crouch; "straighten up" = stand up (normal height).
- "face the other way" = turn 180 deg; "do a full turn" = 360 deg.
- "hang on" / "stay put" / "chill" = wait; "please stop" = a wait alone (2 s).
- Refused (expected None): unknown movements (fly, jump, hop, backflip, zigzag, figure eight),
  negative quantities, speeds above 1.5 m/s, turns beyond 720 deg.
"""

import math

from tests.program.corpus_steps import deg, down, height, par, pick, place, reach, rep, stand, style, turn, up, walk

STEP_M = 0.3
QUICK, SLOW = 0.7, 0.25
R_DEFAULT = 1.0


def octagon_side(radius_m: float = R_DEFAULT) -> float:
    return 2 * math.pi * radius_m / 8


EVERYDAY = [
    # --- walking: paraphrases and slang ------------------------------------------------------------
    ("jog to the left for 3 seconds", [walk(duration_s=3.0, direction="left", speed_mps=QUICK)]),
    ("jog forward 2 meters", [walk(distance_m=2.0, speed_mps=QUICK)]),
    ("run forward two meters", [walk(distance_m=2.0, speed_mps=QUICK)]),
    ("stroll forward for five seconds", [walk(duration_s=5.0, speed_mps=SLOW)]),
    ("amble ahead 1 meter", [walk(distance_m=1.0, speed_mps=SLOW)]),
    ("march forward 4 meters", [walk(distance_m=4.0)]),
    ("scoot over to the right half a meter", [walk(distance_m=0.5, direction="right")]),
    ("shuffle left 30 cm", [walk(distance_m=0.3, direction="left")]),
    ("advance two meters", [walk(distance_m=2.0)]),
    ("retreat one meter", [walk(distance_m=1.0, direction="backward")]),
    ("walk backwards a couple of meters", [walk(distance_m=2.0, direction="backward")]),
    ("take five steps backward", [walk(distance_m=5 * STEP_M, direction="backward")]),
    ("could you walk forward about 2 meters please", [walk(distance_m=2.0)]),
    ("walk roughly three meters forward", [walk(distance_m=3.0)]),
    ("go straight ahead for 4 seconds", [walk(duration_s=4.0)]),
    ("walk forward 2 meters real slow", [walk(distance_m=2.0, speed_mps=SLOW)]),
    ("hurry to the door", [walk(target="door", speed_mps=QUICK)]),
    ("walk over to the table", [walk(target="table")]),
    ("head over to the shelf", [walk(target="shelf")]),
    ("make your way to the door", [walk(target="door")]),
    ("walk towards the window", [walk(target="window")]),
    ("walk forward at 1 meter per second for 3 seconds", [walk(duration_s=3.0, speed_mps=1.0)]),
    ("walk forward six feet", [walk(distance_m=6 * 0.3048)]),
    ("walk forward 2 meters and then sideways to the right 1 meter",
     [walk(distance_m=2.0), walk(distance_m=1.0, direction="right")]),
    ("step to the side, to the left, 40 centimeters", [walk(distance_m=0.4, direction="left")]),
    ("back up slowly for 2 seconds", [walk(duration_s=2.0, direction="backward", speed_mps=SLOW)]),
    # --- turning ---------------------------------------------------------------------------------------
    ("face the other way", [turn(angle_rad=deg(180))]),
    ("rotate 30 degrees to the right", [turn(angle_rad=deg(30), direction="right")]),
    ("turn right 3 times", [rep(3, turn(angle_rad=deg(90), direction="right"))]),
    ("pivot left forty five degrees", [turn(angle_rad=deg(45))]),
    ("spin to your left", [turn(angle_rad=deg(90))]),
    ("turn to face the door", [turn(target="door")]),
    ("do a full turn to the right", [turn(angle_rad=deg(360), direction="right")]),
    ("turn right a quarter turn", [turn(angle_rad=deg(90), direction="right")]),
    ("turn around slowly", [turn(angle_rad=deg(180), yaw_rate_radps=0.3)]),
    ("quickly turn around twice", [rep(2, turn(angle_rad=deg(180), yaw_rate_radps=1.0))]),
    ("turn sixty degrees clockwise", [turn(angle_rad=deg(60), direction="right")]),
    ("look at the box", [turn(target="box")]),
    # --- path shapes -----------------------------------------------------------------------------------
    ("walk in a circle to the right",
     [rep(8, walk(distance_m=octagon_side()), turn(angle_rad=deg(45), direction="right"))]),
    ("walk in a circle", [rep(8, walk(distance_m=octagon_side()), turn(angle_rad=deg(45)))]),
    ("walk in a circle with a radius of 2 meters", [rep(8, walk(distance_m=octagon_side(2.0)), turn(angle_rad=deg(45)))]),
    ("walk a circle of 1 meter diameter clockwise",
     [rep(8, walk(distance_m=octagon_side(0.5)), turn(angle_rad=deg(45), direction="right"))]),
    ("walk a half circle to the left", [rep(4, walk(distance_m=octagon_side()), turn(angle_rad=deg(45)))]),
    ("walk a triangle with 2 meter sides", [rep(3, walk(distance_m=2.0), turn(angle_rad=deg(120)))]),
    ("walk in a square with 1 m sides to the right",
     [rep(4, walk(distance_m=1.0), turn(angle_rad=deg(90), direction="right"))]),
    ("walk a rectangle 2 meters by 1 meter",
     [rep(2, walk(distance_m=2.0), turn(angle_rad=deg(90)), walk(distance_m=1.0), turn(angle_rad=deg(90)))]),
    ("walk back and forth 2 meters three times",
     [rep(3, walk(distance_m=2.0), walk(distance_m=2.0, direction="backward"))]),
    ("pace back and forth 1 meter", [walk(distance_m=1.0), walk(distance_m=1.0, direction="backward")]),
    # --- styles: stance, mode, fillers ----------------------------------------------------------------
    ("guard stance and walk backward one meter", [style("guard", 3), walk(distance_m=1.0, direction="backward")]),
    ("walk forward 2 meters in a guard stance", [par(walk(distance_m=2.0), style("guard"))]),
    ("switch to guard mode", [style("guard")]),
    ("dance for ten seconds", [style("dance", 10)]),
    ("do a little dance", [style("dance", 3)]),
    ("wave hello", [style("wave", 3)]),
    ("wave at me for 5 seconds", [style("wave", 5)]),
    ("walk forward three meters while waving", [par(walk(distance_m=3.0), style("wave"))]),
    ("walk to the door swinging your arms", [par(walk(target="door"), style("arm_swing"))]),
    ("walk forward 2 meters with your hands up", [par(walk(distance_m=2.0), style("reach_up"))]),
    ("look around for a few seconds", [style("look_around", 3)]),
    ("glance around", [style("look_around", 3)]),
    ("put your arms down", [style("default")]),
    ("spread your arms while you turn around", [par(turn(angle_rad=deg(180)), style("arms_out"))]),
    # --- height -----------------------------------------------------------------------------------------
    ("squat down for five seconds", [height(posture="crouch", duration_s=5.0)]),
    ("duck down", [height(posture="crouch")]),
    ("get low and walk forward 1 meter", [height(posture="crouch"), walk(distance_m=1.0)]),
    ("walk forward 1 meter crouched", [par(walk(distance_m=1.0), height(posture="crouch"))]),
    ("lower your hips to 0.6 m", [height(pelvis_height_m=0.6)]),
    ("straighten up", [height(posture="normal")]),
    ("crouch to 65 centimeters and wait 2 seconds", [height(pelvis_height_m=0.65), stand(2)]),
    # --- reaching with a named hand ---------------------------------------------------------------------
    ("reach up with the right hand", [reach(offset_m=[0.0, 0.0, 0.3])]),
    ("reach up with your left hand", [reach(hand="left", offset_m=[0.0, 0.0, 0.3])]),
    ("raise your left hand", [reach(hand="left", offset_m=[0.0, 0.0, 0.3])]),
    ("stretch your right arm forward", [reach(offset_m=[0.3, 0.0, 0.0])]),
    ("touch the box with the right hand", [reach(target="box")]),
    ("use your left hand to touch the cup", [reach(hand="left", target="cup")]),
    ("put your right hand on the table", [reach(target="table")]),
    ("reach 25 centimeters forward with both hands", [reach(hand="both", offset_m=[0.25, 0.0, 0.0])]),
    ("with your left hand, reach out to the left", [reach(hand="left", offset_m=[0.0, 0.3, 0.0])]),
    ("lift your right hand 20 cm", [reach(offset_m=[0.0, 0.0, 0.2])]),
    ("reach for the shelf with the left hand", [reach(hand="left", target="shelf")]),
    # --- carrying while walking --------------------------------------------------------------------------
    ("carry the box forward three meters and put it down", [pick("box"), walk(distance_m=3.0), place("box")]),
    ("pick up the box, walk two meters, and set it down", [pick("box"), walk(distance_m=2.0), place("box")]),
    ("grab the box and walk backward 1 meter with it", [pick("box"), walk(distance_m=1.0, direction="backward")]),
    ("pick up the box and take it 2 meters to the left",
     [pick("box"), walk(distance_m=2.0, direction="left")]),
    ("haul the box over to the shelf", [pick("box"), place("box", "shelf")]),
    ("lift the box, turn around, and put it on the table",
     [pick("box"), turn(angle_rad=deg(180)), place("box", "table")]),
    ("hold the box and walk forward for 4 seconds", [pick("box"), walk(duration_s=4.0)]),
    ("pick up the crate and carry it 2 meters forward", [pick("crate"), walk(distance_m=2.0)]),
    ("move the box 1 meter to the right", [pick("box"), walk(distance_m=1.0, direction="right"), place("box")]),
    ("fetch the ball", [pick("ball")]),
    ("drop the box on the table", [place("box", "table")]),
    ("carry the box 2 meters forward, then turn left and put it on the shelf",
     [pick("box"), walk(distance_m=2.0), turn(angle_rad=deg(90)), place("box", "shelf")]),
    # --- steps and platforms ------------------------------------------------------------------------------
    ("step up on the step", [up("step")]),
    ("get up on the box", [up("box")]),
    ("step down from the platform", [down("platform")]),
    ("get down off the platform", [down("platform")]),
    ("climb onto the platform and then step back down", [up("platform"), down()]),
    # --- fillers ------------------------------------------------------------------------------------------
    ("hey robot, could you please walk forward like two meters", [walk(distance_m=2.0)]),
    ("ok so first turn left and then walk forward 3 meters", [turn(angle_rad=deg(90)), walk(distance_m=3.0)]),
    ("I'd like you to turn right", [turn(angle_rad=deg(90), direction="right")]),
    ("go ahead and take three steps forward for me", [walk(distance_m=3 * STEP_M)]),
    ("um, walk forward 1 meter", [walk(distance_m=1.0)]),
    ("alright, now wave", [style("wave", 3)]),
    ("please stop", [stand(2)]),
    ("hang on for 4 seconds", [stand(4)]),
    ("stay put for three seconds", [stand(3)]),
    ("chill for 5 seconds", [stand(5)]),
    ("walk forward 1 meter, wait a sec, then walk back", [walk(distance_m=1.0), stand(1), walk(target="start")]),
    # --- must be refused -----------------------------------------------------------------------------------
    ("fly to the door", None),
    ("hop onto the platform", None),
    ("do a backflip", None),
    ("zigzag forward 3 meters", None),
    ("walk in a figure eight", None),
    ("walk forward for -3 seconds", None),
    ("walk forward minus 2 meters", None),
    ("walk forward 2 meters at 5 m/s", None),
    ("turn left 5000 degrees", None),
    ("jog with your left hand", None),
]
