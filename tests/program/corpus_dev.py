"""Development part of the instruction corpus: the parser was built and tuned against these.

(The held-out part is corpus_heldout.py, written and committed before the parser; see there.)
Each entry: (instruction, expected program steps as dicts, exactly as Program.to_dict() writes them).
"""

import math


def deg(x):
    return math.radians(x)


def walk(**kw):
    return {"kind": "walk", **kw}


def turn(**kw):
    return {"kind": "turn", **kw}


def stand(d):
    return {"kind": "stand", "duration_s": float(d)}


def style(name, d=None):
    out = {"kind": "style", "name": name}
    if d is not None:
        out["duration_s"] = float(d)
    return out


def height(**kw):
    return {"kind": "height", **kw}


def reach(**kw):
    return {"kind": "reach", **kw}


def pick(obj, hands=None, **kw):
    out = {"kind": "pick", "object": obj, **kw}
    if hands:
        out["hands"] = hands
    return out


def place(obj, target=None, **kw):
    out = {"kind": "place", "object": obj, **kw}
    if target:
        out["target"] = target
    return out


def up(p, **kw):
    return {"kind": "step_up", "platform": p, **kw}


def down(p=None, **kw):
    out = {"kind": "step_down", **kw}
    if p:
        out["platform"] = p
    return out


def par(main, *alongside):
    return {"kind": "parallel", "main": main, "alongside": list(alongside)}


def rep(n, *steps):
    return {"kind": "repeat", "count": n, "steps": list(steps)}


DEV = [
    # --- walk: distances in digits, words, units -------------------------------------------------
    ("walk forward two meters", [walk(distance_m=2.0)]),
    ("walk forward 2 m", [walk(distance_m=2.0)]),
    ("walk forward 2m", [walk(distance_m=2.0)]),
    ("walk 2.5 meters forward", [walk(distance_m=2.5)]),
    ("walk forward .5 m", [walk(distance_m=0.5)]),
    ("go forward 1 metre", [walk(distance_m=1.0)]),
    ("move forward one meter", [walk(distance_m=1.0)]),
    ("walk forward a meter", [walk(distance_m=1.0)]),
    ("walk ahead 3 meters", [walk(distance_m=3.0)]),
    ("go straight ahead for four meters", [walk(distance_m=4.0)]),
    ("walk straight 1.2 m", [walk(distance_m=1.2)]),
    ("walk forward twenty five centimeters", [walk(distance_m=0.25)]),
    ("walk forward 30 cm", [walk(distance_m=0.3)]),
    ("walk forward 300 mm", [walk(distance_m=0.3)]),
    ("walk forward three feet", [walk(distance_m=0.9144)]),
    ("walk forward 1 foot", [walk(distance_m=0.3048)]),
    ("walk forward 10 ft", [walk(distance_m=3.048)]),
    ("walk forward two and a half meters", [walk(distance_m=2.5)]),
    ("walk forward a meter and a half", [walk(distance_m=1.5)]),
    ("walk forward half a meter", [walk(distance_m=0.5)]),
    ("walk forward a quarter of a meter", [walk(distance_m=0.25)]),
    ("walk forward one point five meters", [walk(distance_m=1.5)]),
    ("walk forward a couple of meters", [walk(distance_m=2.0)]),
    ("walk forward 2", [walk(distance_m=2.0)]),
    ("walk forward twelve meters", [walk(distance_m=12.0)]),
    ("walk forwards 1 meter", [walk(distance_m=1.0)]),
    ("head forward 2 meters", [walk(distance_m=2.0)]),
    ("travel forward 1 meter", [walk(distance_m=1.0)]),
    ("proceed forward 3 m", [walk(distance_m=3.0)]),
    ("step forward half a meter", [walk(distance_m=0.5)]),
    ("walk 2 meters", [walk(distance_m=2.0)]),
    # --- walk: other directions --------------------------------------------------------------------
    ("walk backward 1 meter", [walk(distance_m=1.0, direction="backward")]),
    ("walk backwards two meters", [walk(distance_m=2.0, direction="backward")]),
    ("go back one meter", [walk(distance_m=1.0, direction="backward")]),
    ("step back 30 cm", [walk(distance_m=0.3, direction="backward")]),
    ("back up 1 meter", [walk(distance_m=1.0, direction="backward")]),
    ("move backward half a meter", [walk(distance_m=0.5, direction="backward")]),
    ("walk left one meter", [walk(distance_m=1.0, direction="left")]),
    ("walk to the left 1 m", [walk(distance_m=1.0, direction="left")]),
    ("move to your right 40 cm", [walk(distance_m=0.4, direction="right")]),
    ("step right 0.2 m", [walk(distance_m=0.2, direction="right")]),
    ("sidestep right half a meter", [walk(distance_m=0.5, direction="right")]),
    ("walk sideways to the left 1 meter", [walk(distance_m=1.0, direction="left")]),
    ("strafe left 50 centimeters", [walk(distance_m=0.5, direction="left")]),
    # --- walk: durations, speeds, headings, timeouts -------------------------------------------
    ("walk forward for 3 seconds", [walk(duration_s=3.0)]),
    ("walk forward for five seconds", [walk(duration_s=5.0)]),
    ("walk backward for 2 s", [walk(duration_s=2.0, direction="backward")]),
    ("walk forward for a minute", [walk(duration_s=60.0)]),
    ("walk forward for half a minute", [walk(duration_s=30.0)]),
    ("walk forward 2 meters slowly", [walk(distance_m=2.0, speed_mps=0.25)]),
    ("slowly walk forward 2 meters", [walk(distance_m=2.0, speed_mps=0.25)]),
    ("walk quickly forward 3 meters", [walk(distance_m=3.0, speed_mps=0.7)]),
    ("walk forward 3 meters fast", [walk(distance_m=3.0, speed_mps=0.7)]),
    ("walk forward 2 m at 0.4 m/s", [walk(distance_m=2.0, speed_mps=0.4)]),
    ("walk forward 2 meters at 0.4 meters per second", [walk(distance_m=2.0, speed_mps=0.4)]),
    ("walk forward 2 meters at 40 cm/s", [walk(distance_m=2.0, speed_mps=0.4)]),
    ("walk forward 1 m at half a meter per second", [walk(distance_m=1.0, speed_mps=0.5)]),
    ("walk 2 meters at heading 90 degrees", [walk(distance_m=2.0, heading_rad=deg(90))]),
    ("walk 1 meter heading 45 degrees", [walk(distance_m=1.0, heading_rad=deg(45))]),
    ("walk forward 5 meters within 20 seconds", [walk(distance_m=5.0, timeout_s=20.0)]),
    ("walk forward 5 meters in under 15 seconds", [walk(distance_m=5.0, timeout_s=15.0)]),
    # --- walk to places ---------------------------------------------------------------------------------
    ("walk to the table", [walk(target="table")]),
    ("go to the box", [walk(target="box")]),
    ("walk over to the door", [walk(target="door")]),
    ("head to the shelf", [walk(target="shelf")]),
    ("move toward the chair", [walk(target="chair")]),
    ("walk towards the wall", [walk(target="wall")]),
    ("approach the table", [walk(target="table")]),
    ("walk back to the table", [walk(target="table")]),
    ("go back to the start", [walk(target="start")]),
    ("return to the starting point", [walk(target="start")]),
    ("come back to where you started", [walk(target="start")]),
    ("walk to the other table", [walk(target="other_table")]),
    ("walk slowly to the platform", [walk(target="platform", speed_mps=0.25)]),
    ("walk forward until you reach the table", [walk(target="table")]),
    ("keep walking until you get to the door", [walk(target="door")]),  # part 2: "keep" became a filler
    ("walk to the box within 30 seconds", [walk(target="box", timeout_s=30.0)]),
    # --- turn -------------------------------------------------------------------------------------------------
    ("turn left", [turn(angle_rad=deg(90))]),
    ("turn right", [turn(angle_rad=deg(90), direction="right")]),
    ("turn left ninety degrees", [turn(angle_rad=deg(90))]),
    ("turn right 90 degrees", [turn(angle_rad=deg(90), direction="right")]),
    ("turn right 90°", [turn(angle_rad=deg(90), direction="right")]),
    ("turn left 45 deg", [turn(angle_rad=deg(45))]),
    ("turn left forty-five degrees", [turn(angle_rad=deg(45))]),
    ("turn right one hundred and eighty degrees", [turn(angle_rad=deg(180), direction="right")]),
    ("turn left a hundred and twenty degrees", [turn(angle_rad=deg(120))]),
    ("turn left 90", [turn(angle_rad=deg(90))]),
    ("turn 60 degrees left", [turn(angle_rad=deg(60))]),
    ("turn 30 degrees", [turn(angle_rad=deg(30))]),
    ("turn left by 15 degrees", [turn(angle_rad=deg(15))]),
    ("turn 90 degrees to the left", [turn(angle_rad=deg(90))]),
    ("rotate right 1 radian", [turn(angle_rad=1.0, direction="right")]),
    ("rotate left 0.5 rad", [turn(angle_rad=0.5)]),
    ("spin left 360 degrees", [turn(angle_rad=deg(360))]),
    ("spin around", [turn(angle_rad=deg(180))]),
    ("turn around", [turn(angle_rad=deg(180))]),
    ("turn back", [turn(angle_rad=deg(180))]),
    ("pivot right 45 degrees", [turn(angle_rad=deg(45), direction="right")]),
    ("turn clockwise 90 degrees", [turn(angle_rad=deg(90), direction="right")]),
    ("turn counterclockwise 30 degrees", [turn(angle_rad=deg(30))]),
    ("make a quarter turn to the right", [turn(angle_rad=deg(90), direction="right")]),  # part 2: make/do a turn
    ("do a quarter turn to the right", [turn(angle_rad=deg(90), direction="right")]),
    ("turn a quarter turn to the right", [turn(angle_rad=deg(90), direction="right")]),
    ("turn a half turn", [turn(angle_rad=deg(180))]),
    ("spin a full circle", [turn(angle_rad=deg(360))]),
    ("spin in a full circle to the right", [turn(angle_rad=deg(360), direction="right")]),
    ("turn left slowly", [turn(angle_rad=deg(90), yaw_rate_radps=0.3)]),
    ("quickly turn right", [turn(angle_rad=deg(90), direction="right", yaw_rate_radps=1.0)]),
    ("turn left 90 degrees at 30 degrees per second", [turn(angle_rad=deg(90), yaw_rate_radps=deg(30))]),
    ("turn right 45 degrees at 0.5 rad/s", [turn(angle_rad=deg(45), direction="right", yaw_rate_radps=0.5)]),
    ("turn to heading 90 degrees", [turn(heading_rad=deg(90))]),
    ("turn to heading 0", [turn(heading_rad=0.0)]),
    ("face heading 180 degrees", [turn(heading_rad=deg(180))]),
    ("face the table", [turn(target="table")]),
    ("turn to face the box", [turn(target="box")]),
    ("turn towards the door", [turn(target="door")]),
    ("look at the shelf", [turn(target="shelf")]),
    ("turn until you face the wall", [turn(target="wall")]),
    ("face left", [turn(angle_rad=deg(90))]),
    ("turn right 90 degrees within 5 seconds", [turn(angle_rad=deg(90), direction="right", timeout_s=5.0)]),
    # --- stand / wait ---------------------------------------------------------------------------------
    ("wait", [stand(2)]),
    ("wait 3 seconds", [stand(3)]),
    ("wait for three seconds", [stand(3)]),
    ("wait for 5", [stand(5)]),
    ("pause for 1.5 s", [stand(1.5)]),
    ("stay there for 10 seconds", [stand(10)]),  # part 2: "there"/"here" after a wait are fillers
    ("stay for 10 seconds", [stand(10)]),
    ("stand still", [stand(2)]),
    ("stand still for 4 seconds", [stand(4)]),
    ("hold still for a second", [stand(1)]),
    ("stop for 2 seconds", [stand(2)]),
    ("rest for a minute", [stand(60)]),
    ("wait a couple of seconds", [stand(2)]),
    ("wait one and a half seconds", [stand(1.5)]),
    # --- styles -------------------------------------------------------------------------------------------
    ("wave", [style("wave", 3)]),
    ("wave your hand", [style("wave", 3)]),
    ("wave hello", [style("wave", 3)]),
    ("wave for 2 seconds", [style("wave", 2)]),
    ("dance", [style("dance", 3)]),
    ("dance for 8 seconds", [style("dance", 8)]),
    ("look around", [style("look_around", 3)]),
    ("look around for five seconds", [style("look_around", 5)]),
    ("swing your arms for 4 seconds", [style("arm_swing", 4)]),
    ("spread your arms", [style("arms_out", 3)]),
    ("hold your arms out for 6 seconds", [style("arms_out", 6)]),
    ("put your guard up", [style("guard", 3)]),
    ("put your hands up", [style("reach_up", 3)]),
    ("reach up for 2 seconds", [style("reach_up", 2)]),
    ("lower your arms", [style("default")]),
    ("use the carry style", [style("carry")]),
    ("switch to guard style", [style("guard")]),
    ("change to the arms out style", [style("arms_out")]),
    ("switch to the default style", [style("default")]),
    ("use the wave style for 4 seconds", [style("wave", 4)]),
    ("climb", [style("climb", 3)]),
    ("lift", [style("lift", 3)]),
    ("wave twice", [rep(2, style("wave", 3))]),
    ("dance three times", [rep(3, style("dance", 3))]),
    # --- height ------------------------------------------------------------------------------------------
    ("crouch", [height(posture="crouch")]),
    ("crouch down", [height(posture="crouch")]),
    ("squat for 3 seconds", [height(posture="crouch", duration_s=3.0)]),
    ("get down", [height(posture="crouch")]),
    ("stand up", [height(posture="normal")]),
    ("stand tall", [height(posture="tall")]),
    ("stand up straight", [height(posture="tall")]),
    ("crouch to 0.65 meters", [height(pelvis_height_m=0.65)]),
    ("lower your body to 60 cm", [height(pelvis_height_m=0.6)]),
    ("lower yourself to 0.55 m for 2 seconds", [height(pelvis_height_m=0.55, duration_s=2.0)]),
    ("set your pelvis height to 0.7 m", [height(pelvis_height_m=0.7)]),
    ("raise your pelvis to 0.75 meters", [height(pelvis_height_m=0.75)]),
    # --- reach ------------------------------------------------------------------------------------------
    ("reach for the cup", [reach(target="cup")]),
    ("reach for the ball with your left hand", [reach(hand="left", target="ball")]),
    ("touch the door with both hands", [reach(hand="both", target="door")]),
    ("touch the wall using your left hand", [reach(hand="left", target="wall")]),
    ("reach out with your right hand", [reach(offset_m=[0.3, 0.0, 0.0])]),
    ("reach forward 40 cm", [reach(offset_m=[0.4, 0.0, 0.0])]),
    ("reach 20 cm to the left with your left hand", [reach(hand="left", offset_m=[0.0, 0.2, 0.0])]),
    ("reach right 15 cm with the right hand", [reach(offset_m=[0.0, -0.15, 0.0])]),
    ("reach down 10 cm with your left hand", [reach(hand="left", offset_m=[0.0, 0.0, -0.1])]),
    ("reach 10 cm above the box with your right hand", [reach(target="box", offset_m=[0.0, 0.0, 0.1])]),
    ("reach toward the shelf within 8 seconds", [reach(target="shelf", timeout_s=8.0)]),
    # --- pick / place / bring -----------------------------------------------------------------------
    ("pick up the box", [pick("box")]),
    ("pick the box up", [pick("box")]),
    ("grab the cup with your right hand", [pick("cup", "right")]),
    ("take the ball", [pick("ball")]),
    ("lift the box", [pick("box")]),
    ("grasp the red box with both hands", [pick("red_box")]),
    ("pick up the blue box within 40 seconds", [pick("blue_box", timeout_s=40.0)]),
    ("put the box on the table", [place("box", "table")]),
    ("place the cup on the shelf", [place("cup", "shelf")]),
    ("put the box on top of the platform", [place("box", "platform")]),
    ("set the box down", [place("box")]),
    ("put the cup down", [place("cup")]),
    ("pick up the box and put it down", [pick("box"), place("box")]),
    ("pick up the cup then place it on the table", [pick("cup"), place("cup", "table")]),
    ("grab the ball and put it on the chair", [pick("ball"), place("ball", "chair")]),
    ("bring the box to the table", [pick("box"), place("box", "table")]),
    ("carry the box to the other table", [pick("box"), place("box", "other_table")]),
    ("take the cup to the shelf", [pick("cup"), place("cup", "shelf")]),
    ("pick up the box and bring it to the table", [pick("box"), place("box", "table")]),
    ("pick up the box, then carry it to the other table", [pick("box"), place("box", "other_table")]),
    ("put it on the table", None),  # nothing picked up or named before: "it" refers to nothing
    ("deliver the red box to the chair", [pick("red_box"), place("red_box", "chair")]),
    # --- step up / down ---------------------------------------------------------------------------------
    ("step up onto the platform", [up("platform")]),
    ("step onto the platform", [up("platform")]),
    ("climb up onto the platform", [up("platform")]),
    ("get on the platform", [up("platform")]),
    ("climb the platform", [up("platform")]),
    ("step down", [down()]),
    ("step down from the platform", [down("platform")]),
    ("step off the platform", [down("platform")]),
    ("climb down from the platform", [down("platform")]),
    ("step onto the platform within 20 seconds", [up("platform", timeout_s=20.0)]),
    # --- parallel ("while", gerunds, "with") -------------------------------------------------------------
    ("wave while walking back to the table", [par(walk(target="table"), style("wave"))]),
    ("walk forward 2 meters while waving", [par(walk(distance_m=2.0), style("wave"))]),
    ("walk forward 2 meters waving", [par(walk(distance_m=2.0), style("wave"))]),
    ("walk to the door dancing", [par(walk(target="door"), style("dance"))]),
    ("look around while you walk forward 3 meters", [par(walk(distance_m=3.0), style("look_around"))]),
    ("walk forward 1 meter in guard style", [par(walk(distance_m=1.0), style("guard"))]),
    ("walk backward 1 meter with your hands up", [par(walk(distance_m=1.0, direction="backward"),
                                                       style("reach_up"))]),
    ("walk forward 2 meters carrying", [par(walk(distance_m=2.0), style("carry"))]),
    ("walk forward 1 m crouching", [par(walk(distance_m=1.0), height(posture="crouch"))]),
    ("walk forward 1 m while crouching", [par(walk(distance_m=1.0), height(posture="crouch"))]),
    ("wave while turning left", [par(turn(angle_rad=deg(90)), style("wave"))]),
    ("turn around while swinging your arms", [par(turn(angle_rad=deg(180)), style("arm_swing"))]),
    ("wave as you walk to the box", [par(walk(target="box"), style("wave"))]),
    ("wave while standing still for 3 seconds", [par(stand(3), style("wave"))]),
    ("walk forward 2 m with arms out while looking around",
     [par(walk(distance_m=2.0), style("arms_out"), style("look_around"))]),
    ("reach for the cup while walking to the table", [par(walk(target="table"), reach(target="cup"))]),
    ("wave while walking", None),  # a walk needs a distance, a duration or a place
    ("wave while dancing", None),  # 'while' needs a walk, turn or wait on one side
    # --- connectives, ordering, repeats ------------------------------------------------------------------
    ("walk forward 1 m then turn left", [walk(distance_m=1.0), turn(angle_rad=deg(90))]),
    ("walk forward 1 m and then turn left", [walk(distance_m=1.0), turn(angle_rad=deg(90))]),
    ("walk forward 1 m, turn left, walk forward 1 m",
     [walk(distance_m=1.0), turn(angle_rad=deg(90)), walk(distance_m=1.0)]),
    ("walk forward 1 m; turn left; wave", [walk(distance_m=1.0), turn(angle_rad=deg(90)), style("wave", 3)]),
    ("Walk forward 1 m. Turn left. Wave.", [walk(distance_m=1.0), turn(angle_rad=deg(90)), style("wave", 3)]),
    ("first turn right, then walk forward 2 meters, finally wave",
     [turn(angle_rad=deg(90), direction="right"), walk(distance_m=2.0), style("wave", 3)]),
    ("turn left and after that walk forward 1 m", [turn(angle_rad=deg(90)), walk(distance_m=1.0)]),
    ("wave, afterwards walk forward 2 m", [style("wave", 3), walk(distance_m=2.0)]),
    ("walk forward 2 m, next turn around", [walk(distance_m=2.0), turn(angle_rad=deg(180))]),
    ("wave after you reach the table", [walk(target="table"), style("wave", 3)]),
    ("after turning around, walk to the door", [turn(angle_rad=deg(180)), walk(target="door")]),
    ("wave before walking to the door", [style("wave", 3), walk(target="door")]),
    ("before walking to the door, wave", [style("wave", 3), walk(target="door")]),
    ("turn right 90 degrees twice", [rep(2, turn(angle_rad=deg(90), direction="right"))]),
    ("turn left, twice", [rep(2, turn(angle_rad=deg(90)))]),
    ("walk forward 1 meter two times", [rep(2, walk(distance_m=1.0))]),
    ("walk forward 1 meter 3 times", [rep(3, walk(distance_m=1.0))]),
    ("walk forward 1 meter once", [walk(distance_m=1.0)]),
    ("walk forward 1 m and turn left, then repeat that three times",
     [rep(3, walk(distance_m=1.0), turn(angle_rad=deg(90)))]),
    ("walk forward 1 m and turn right. Repeat this 4 times.",
     [rep(4, walk(distance_m=1.0), turn(angle_rad=deg(90), direction="right"))]),
    ("dance, then do it again", [rep(2, style("dance", 3))]),
    ("wave then turn left, and do that 2 times", [rep(2, style("wave", 3), turn(angle_rad=deg(90)))]),
    ("please walk forward two meters", [walk(distance_m=2.0)]),
    ("robot, please turn left", [turn(angle_rad=deg(90))]),
    ("can you walk forward 1 meter", [walk(distance_m=1.0)]),
    ("I want you to walk to the table", [walk(target="table")]),
    ("now just wave", [style("wave", 3)]),
    ("go ahead and walk forward 1 m", [walk(distance_m=1.0)]),
    ("okay robot, walk to the box and pick it up", [walk(target="box"), pick("box")]),
    # --- multi-step instructions ---------------------------------------------------------------------------
    ("walk forward two meters, then turn left ninety degrees and wave while walking back to the table; "
     "pick up the box and put it on the other table",
     [walk(distance_m=2.0), turn(angle_rad=deg(90)), par(walk(target="table"), style("wave")),
      pick("box"), place("box", "other_table")]),
    ("walk to the platform, step onto it, turn around, wave, and step down",
     [walk(target="platform"), up("platform"), turn(angle_rad=deg(180)), style("wave", 3), down()]),
    ("crouch, pick up the box, stand up and walk to the table",
     [height(posture="crouch"), pick("box"), height(posture="normal"), walk(target="table")]),
    ("turn to face the door, walk to it, and wave for 4 seconds",
     [turn(target="door"), walk(target="door"), style("wave", 4)]),
    ("walk forward 3 meters slowly, turn right 45 degrees, then walk forward 1 meter quickly",
     [walk(distance_m=3.0, speed_mps=0.25), turn(angle_rad=deg(45), direction="right"),
      walk(distance_m=1.0, speed_mps=0.7)]),
    ("go to the shelf, grab the cup with your left hand, and bring it to the table",
     [walk(target="shelf"), pick("cup", "left"), place("cup", "table")]),
    ("look around for 3 seconds, then walk back 1 meter and crouch for 2 seconds",
     [style("look_around", 3), walk(distance_m=1.0, direction="backward"),
      height(posture="crouch", duration_s=2.0)]),
    ("switch to the guard style, walk forward 2 meters and switch to the default style",
     [style("guard"), walk(distance_m=2.0), style("default")]),
    ("wait 2 seconds, reach for the ball with your right hand, then pick it up",
     [stand(2), reach(target="ball"), pick("ball")]),
    ("walk forward 1 m and turn left 90 degrees, repeat that 4 times, then dance",
     [rep(4, walk(distance_m=1.0), turn(angle_rad=deg(90))), style("dance", 3)]),
    # --- part 2: constructs from the second held-out set's failures (corpus_phrasing.py), in other sentences ---
    # distances in steps (0.3 m each; corpus_phrasing.py's conventions)
    ("take three steps forward", [walk(distance_m=0.9)]),
    ("take one step to the right", [walk(distance_m=0.3, direction="right")]),
    ("walk four steps backward", [walk(distance_m=1.2, direction="backward")]),
    ("take a step forward and wave", [walk(distance_m=0.3), style("wave", 3)]),
    # back without a distance or a place: back to the start
    ("walk forward 3 meters and then come back", [walk(distance_m=3.0), walk(target="start")]),
    ("go to the door and come back", [walk(target="door"), walk(target="start")]),
    ("turn around and go back", [turn(angle_rad=deg(180)), walk(target="start")]),
    # make / do a turn
    ("make a right and walk forward 1 meter", [turn(angle_rad=deg(90), direction="right"), walk(distance_m=1.0)]),
    ("make a left turn", [turn(angle_rad=deg(90))]),
    ("do a 90 to the left", [turn(angle_rad=deg(90))]),
    ("do a 360", [turn(angle_rad=deg(360))]),
    ("make a u-turn", [turn(angle_rad=deg(180))]),
    ("walk forward 1 m, then make a half turn", [walk(distance_m=1.0), turn(angle_rad=deg(180))]),
    # pace, here, me, little
    ("walk to the door at a brisk pace", [walk(target="door", speed_mps=0.7)]),
    ("go forward 2 meters at a slow speed", [walk(distance_m=2.0, speed_mps=0.25)]),
    ("stay here for 4 seconds", [stand(4)]),
    ("wave to me for 2 seconds", [style("wave", 2)]),
    ("do a little wave", [style("wave", 3)]),
    # shapes
    ("walk a square of 2 meters", [rep(4, walk(distance_m=2.0), turn(angle_rad=deg(90)))]),
    ("walk in a 1.5 meter square to the right", [rep(4, walk(distance_m=1.5), turn(angle_rad=deg(90), direction="right"))]),
    # at the same time; keep; spread out; low; back up again
    ("turn left and look around at the same time", [par(turn(angle_rad=deg(90)), style("look_around"))]),
    ("walk backward 1 meter and swing your arms simultaneously",
     [par(walk(distance_m=1.0, direction="backward"), style("arm_swing"))]),
    ("turn right with your arms spread out", [par(turn(angle_rad=deg(90), direction="right"), style("arms_out"))]),
    ("keep your hands up while turning left", [par(turn(angle_rad=deg(90)), style("reach_up"))]),
    ("squat low for 2 seconds", [height(posture="crouch", duration_s=2.0)]),
    ("crouch for 2 seconds and get back up", [height(posture="crouch", duration_s=2.0), height(posture="normal")]),
    # places: up to, a second place after "then", sources, back, move/drop as carry and put
    ("go up to the chair", [walk(target="chair")]),
    ("go to the door, then to the chair", [walk(target="door"), walk(target="chair")]),
    ("walk to the box and then the table", [walk(target="box"), walk(target="table")]),
    ("grab the ball from the chair", [pick("ball")]),
    ("take the cup off the table and bring it to the shelf", [pick("cup"), place("cup", "shelf")]),
    ("carry the ball back to the chair", [pick("ball"), place("ball", "chair")]),
    ("place the cup back on the shelf", [place("cup", "shelf")]),
    ("move the red box onto the shelf", [pick("red_box"), place("red_box", "shelf")]),
    ("pick up the ball and drop it", [pick("ball"), place("ball")]),
    ("turn to face the shelf, walk to it, and set the cup on it",
     [turn(target="shelf"), walk(target="shelf"), place("cup", "shelf")]),
    ("wave with your right hand", None),  # the wave is the right hand's; a hand named with a style is refused
    # --- words the parser refuses -----------------------------------------------------------------------
    ("jump forward 1 meter", None),
    ("walk forward 2 parsecs", None),
    ("turn up 30 degrees", None),
    ("pick up", None),
    ("walk forward 2 meters for 3 seconds", None),
    ("turn", None),
]
