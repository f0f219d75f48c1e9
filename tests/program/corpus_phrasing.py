"""Second held-out set: instructions phrased the way other people write them.

How this part was made: written by a second engineer (issue 15, part 2) from the program format
(g1_control/program/steps.py), the grammar README and the development corpus's phrasings (so as to
phrase things DIFFERENTLY from both existing corpora), and committed before that engineer read or
changed any parser code. It is not edited to match the parser; the parser is fixed on the
development side only (corpus_dev.py), and tests/program/test_program_phrasing.py reports the
exact-match rate and lists the failures.

Conventions decided here, before writing (beyond the part-1 ones in the README):
- "a step" / "N steps" as a distance is STEP_M = 0.3 m per step.
- "come back" / "walk back" / "go back" WITHOUT a distance or a place is a walk back to "start"
  (where the program began); with a distance ("walk back 2 m") it stays a backward walk.
- "make a right" / "make a left" / "turn to your right" are 90-degree turns; "do a 180" is 180 deg.
- "stop" alone at the end of an instruction is a wait alone (2 s, part-1 convention).
- "anticlockwise" = left, "clockwise" = right.
- "from the table" after a pick names where the object is; it adds no step (the execution layer
  walks to the object itself).
- "move / lift X onto|to Y" with an object X is a carry (pick X, place X on Y).
- "drop X" is "put X down" (place without a target).
- "walk in a square with N m sides" is 4 x (walk N m, turn left 90 deg).
- There is one wave style (the right hand): "wave with your left hand" must be REFUSED (expected
  None), not silently run with the right hand.
- A typo must be refused (UnknownWordError), never guessed.
"""

from tests.program.corpus_steps import deg, height, par, pick, place, rep, stand, style, turn, walk

STEP_M = 0.3


PHRASING = [
    # --- distances in steps, "come back", "make a right" -------------------------------------
    ("take two steps forward", [walk(distance_m=2 * STEP_M)]),
    ("take a step back", [walk(distance_m=STEP_M, direction="backward")]),
    ("take 3 steps to the left", [walk(distance_m=3 * STEP_M, direction="left")]),
    ("walk forward 2 m and come back", [walk(distance_m=2.0), walk(target="start")]),
    ("walk forward 2 meters, turn around, and walk back",
     [walk(distance_m=2.0), turn(angle_rad=deg(180)), walk(target="start")]),
    ("go 3 meters straight, then make a right", [walk(distance_m=3.0), turn(angle_rad=deg(90), direction="right")]),
    ("make a left", [turn(angle_rad=deg(90))]),
    ("turn to your right", [turn(angle_rad=deg(90), direction="right")]),
    ("do a 180", [turn(angle_rad=deg(180))]),
    ("turn 45° to your left", [turn(angle_rad=deg(45))]),
    ("rotate ninety degrees clockwise", [turn(angle_rad=deg(90), direction="right")]),
    ("turn 90 degrees anticlockwise", [turn(angle_rad=deg(90))]),
    ("move forward by 1.5 meters", [walk(distance_m=1.5)]),
    ("walk a meter forward", [walk(distance_m=1.0)]),
    ("walk 2 meters to the right", [walk(distance_m=2.0, direction="right")]),
    ("walk two meters ahead and then spin around", [walk(distance_m=2.0), turn(angle_rad=deg(180))]),
    ("back up two meters then turn around", [walk(distance_m=2.0, direction="backward"), turn(angle_rad=deg(180))]),
    ("walk forward for 2 meters at a slow pace", [walk(distance_m=2.0, speed_mps=0.25)]),
    ("walk forward five metres at 0.5 metres per second", [walk(distance_m=5.0, speed_mps=0.5)]),
    ("walk backwards for 3 seconds, then walk forwards for 3 seconds",
     [walk(duration_s=3.0, direction="backward"), walk(duration_s=3.0)]),
    ("go left 1 meter, go right 1 meter",
     [walk(distance_m=1.0, direction="left"), walk(distance_m=1.0, direction="right")]),
    ("walk forward 1m, then sidestep to the right by 50cm",
     [walk(distance_m=1.0), walk(distance_m=0.5, direction="right")]),
    ("turn right by ninety degrees, walk 4 metres, and then stop",
     [turn(angle_rad=deg(90), direction="right"), walk(distance_m=4.0), stand(2)]),
    ("walk in a square with 1 meter sides", [rep(4, walk(distance_m=1.0), turn(angle_rad=deg(90)))]),
    ("go forward 2 meters, do it 3 times", [rep(3, walk(distance_m=2.0))]),
    ("walk 2 m, turn 90° left, walk 2 m, turn 90° left, walk 2 m",
     [walk(distance_m=2.0), turn(angle_rad=deg(90)), walk(distance_m=2.0), turn(angle_rad=deg(90)),
      walk(distance_m=2.0)]),
    ("turn left, walk forward 1 meter, turn right, walk forward 1 meter",
     [turn(angle_rad=deg(90)), walk(distance_m=1.0), turn(angle_rad=deg(90), direction="right"),
      walk(distance_m=1.0)]),
    # --- waiting, styles, posture ----------------------------------------------------------
    ("wait here for ten seconds", [stand(10)]),
    ("stay put for 3 s", [stand(3)]),
    ("dance for 5 secs", [style("dance", 5)]),
    ("wave at me", [style("wave", 3)]),
    ("wave with your left hand", None),  # there is no left-hand wave; must be refused, not run with the right
    ("walk forward 1 meter, then do a little dance", [walk(distance_m=1.0), style("dance", 3)]),
    ("go forward 2 meters while waving your hand", [par(walk(distance_m=2.0), style("wave"))]),
    ("walk forward 2 meters and wave at the same time", [par(walk(distance_m=2.0), style("wave"))]),
    ("walk to the table with your arms spread out", [par(walk(target="table"), style("arms_out"))]),
    ("keep your arms up while you walk forward 1 meter", [par(walk(distance_m=1.0), style("reach_up"))]),
    ("crouch while walking backward 1 m", [par(walk(distance_m=1.0, direction="backward"), height(posture="crouch"))]),
    ("crouch down low and wait there for 5 seconds", [height(posture="crouch"), stand(5)]),
    ("squat down, then get back up", [height(posture="crouch"), height(posture="normal")]),
    ("stand up tall for 3 seconds", [height(posture="tall", duration_s=3.0)]),
    ("lower your hips to 0.6 m", [height(pelvis_height_m=0.6)]),
    ("walk forward 1.5 m, crouch for 2 s, stand back up, and turn right",
     [walk(distance_m=1.5), height(posture="crouch", duration_s=2.0), height(posture="normal"),
      turn(angle_rad=deg(90), direction="right")]),
    # --- places, objects, platforms --------------------------------------------------------
    ("walk up to the box", [walk(target="box")]),
    ("walk to the table, then the shelf", [walk(target="table"), walk(target="shelf")]),
    ("Could you please head over to the table and grab the red box?", [walk(target="table"), pick("red_box")]),
    ("pick up the cup from the table", [pick("cup")]),
    ("pick the cup up off the shelf and put it on the table", [pick("cup"), place("cup", "table")]),
    ("walk over to the shelf, pick up the cup, then bring it back to the table",
     [walk(target="shelf"), pick("cup"), place("cup", "table")]),
    ("go to the box and pick it up with your left hand", [walk(target="box"), pick("box", "left")]),
    ("grab the box and take it over to the shelf", [pick("box"), place("box", "shelf")]),
    ("move the box to the other table", [pick("box"), place("box", "other_table")]),
    ("lift the box onto the table", [pick("box"), place("box", "table")]),
    ("put the box back on the table", [place("box", "table")]),
    ("put down the box", [place("box")]),
    ("drop the ball", [place("ball")]),
    ("face the table, then walk over to it and put the box on it",
     [turn(target="table"), walk(target="table"), place("box", "table")]),
    ("turn towards the platform and climb onto it", [turn(target="platform"), {"kind": "step_up",
                                                                               "platform": "platform"}]),
    ("get up on the platform", [{"kind": "step_up", "platform": "platform"}]),
    ("get down from the platform", [{"kind": "step_down", "platform": "platform"}]),
    # --- a typo ------------------------------------------------------------------------------
    ("trun left 90 degrees", None),
]
