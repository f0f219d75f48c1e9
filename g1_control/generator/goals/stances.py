"""Where to stand, how low to go and how far to lean to hold a box at a place: a small search over
stances, each solved by the whole-body IK and scored by its reach and balance (issue 25).

A box is held by both hands on two of its side faces, the robot square to the other two; a place
is where the box is (a pick) or where it goes (a place), on a support (a table or platform top) or
on the floor. The candidates:
  heading   square to a face of the box whose outward normal is within 60 deg of the support's
            edge nearest to the box (pick from a support), any face (pick from the floor), facing
            the support's nearest edge (place on a support), or the robot's own way (place on the floor)
  gap       from the middle of the soles to the box's near face
  side      on the box's centre line; only where no stance on it is kept at any level (a pick from a
            support whose edge the heading meets more than ~12 deg aslant: SIDE_MIN_SIN), again
            SIDE_STEPS_M off it, toward where the edge is farther: held square to its faces, a box
            turned to the edge brings a stance on its line in on the diagonal, the pelvis or a knee
            within the edge's rules (40 of 80 `g1 bench objects --carry` picks were refused so)
  pelvis    standing (nominal height), then lower in steps down to a squat at 0.42 m
  torso     upright, or leaning forward (pelvis pitched 0.4 rad, waist pulled forward 0.45 rad)
  deep      hands below DEEP_BELOW_M: a deep squat (pelvis DEEP_PELVIS_M, knees forward, heels down), the
            trunk bent as DEEP_BENDS says, most upright first; the only kind tried for hands below
            LOWEST_GRASP_M (a floor box, a low table's); kept when, besides the checks below, the soles
            stay flat on the ground (FLAT_SOLE_M / FLAT_SOLE_RAD), the leg joints stay
            DEEP_LIMIT_MARGIN_RAD inside their limits, the pelvis stays at DEEP_MIN_PELVIS_M or higher
            (above the fall monitor's 0.40 m), tilts DEEP_MAX_TILT_RAD at most, and every joint's static
            torque (gravity, the box's weight at the hands, the ground's reaction under the CoM) is
            within its actuator's limit (`static_torques`); picks and places (DEEP_PICKS_ONLY: picks only)
  standing leaning  last, for a light box held at SQUAT_BELOW_M or higher on a support: standing off its edge
            (soles' middle STAND_LEAN_GAPS_M from the box, the pelvis beyond MIN_EDGE_CLEARANCE_M),
            the pelvis pitched STAND_LEAN_PELVIS_RAD and the waist leaning to reach in
Each candidate is solved from the standing pose at its stance: both hands on the grasp points
(and, for a pick, again lifted), the CoM over the soles shifted for the box's weight; it is kept
when the hands are within FEASIBLE_RESIDUAL_M, the CoM within FEASIBLE_COM_M of its target and no
leg, trunk or arm point comes into the support's top or the box (for a pick, also standing at the
stance upright, the arms swung back as the robot steps in: ARMS_BACK, no arm under the top). The highest pelvis with a kept
candidate wins (standing is easier on the controller than squatting), and among those the distance
of issue 17's pick when kept, else the smallest reach residual and CoM error. When none is kept the place is refused before
anything moves, with the reason and the closest pose.

The search and the hold poses built on it run as planner jobs (GoalContext.compute: inline in
lockstep, or in the planner's own process beside a wall-clock loop): top-level functions
fn(poses, *args) with picklable arguments (`plan_stance`, `grasp_hold_poses`, `release_hold_poses`);
each finds its StancePlanner for the PosePlanner it is given (`stance_planner`, built once).

Hands go at the box's centre height, or higher on a low box (centre below LOW_BOX_Z_M): up to a
quarter of its height, keeping HAND_BELOW_TOP_M below its top.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from itertools import pairwise

import numpy as np

from g1_control.generator.goals.box import Approach, grasp_width, hand_points
from g1_control.generator.goals.poses import (
    PELVIS_CAP_ABOVE_NOMINAL_M,
    WAIST,
    PosePlanner,
    ReachRefused,
    Sole,
    flat_soles,
)
from g1_control.ik.whole_body import LEG_LIGHT_POSTURE_WEIGHT
from g1_control.robot import g1
from g1_control.robot.dynamics import HAND_FRAMES, SOLE_FRAMES
from g1_control.rotations import rot_z
from g1_control.scene import Block, Box

GAPS_M = (0.22, 0.16, 0.28)
"""Middle of the soles to the box's near face."""
PREFERRED_CENTER_M = 0.366
"""From the soles' middle to the box's centre in the pick of issue 17 (measured in physics with a
0.3 m box): the first gap tried and kept when it works (not closer than the smallest gap)."""
LEAN_WAIST_RAD = 0.45
"""Leaning: the waist's pitch pull (its limit is 0.52)."""
LEAN_PELVIS_RAD = 0.4
"""Leaning: the pelvis's pitch target (a soft one)."""
UPRIGHT, LEAN, STAND_LEAN, DEEP = 0, 1, 2, 3
"""How a candidate bends (Candidate.lean): upright, leaning (squatting), leaning standing, or a deep squat
(DEEP + k: its trunk bent as DEEP_BENDS[k])."""
DEEP_BENDS = ((0.3, 0.0), (0.45, 0.15), (0.6, 0.3), (0.7, 0.5))
"""Deep squat: (the pelvis's pitch target, the waist's pitch pull) rad, most upright first. The waist
pitch (35 N m) carries the trunk: at the trunk's full bend (0.7 + 0.5, stop 34's squat) the upper body
alone needs ~35 N m of it, and in lockstep MuJoCo the trunk rested on the joint's 0.52 rad stop."""
DEEP_PELVIS_M = (0.50, 0.47)
"""Deep squat: the pelvis heights tried (above the ground; the IK lets it give FEASIBLE_PELVIS_M below,
DEEP_MIN_PELVIS_M is the least it may end at)."""
DEEP_BELOW_M = 0.50
"""Hands below this (above the ground): the deep squat is tried too (the squats reach ~0.45 m at best)."""
DEEP_MIN_PELVIS_M = 0.44
"""A deep squat's pose keeps the pelvis this high: the fall monitor calls 0.40 m a fall (FallConfig), and
the whole-body controller sank a planned squat ~3 cm below its plan (measured, stop 34)."""
DEEP_MAX_TILT_RAD = 0.85
"""A deep squat's pelvis tilt at most (the safety layer calls 1.0 rad a fall)."""
DEEP_PICKS_ONLY = False
"""True: the deep squat picks only; a place is not planned from it (a place's hands below
LOWEST_GRASP_M stay refused). It was True while a carry into a deep-squat place fell in the
correcting steps (bench objects seed 9 trial 1: a 0.5 kg, 0.45 m tall box to go on the floor); the
cause was the footstep plan taking the soles' micrometres above the floor for a step down
(stepping.LEVEL_CHANGE_M): it leaned the pelvis 0.3 rad with the box held high. With that fixed the
same trial sets its box down (1.6 cm off); seed 8 trial 3 set its box down from a deep squat (2.4 cm)."""
DEEP_TORQUE_SHARE = 1.0
"""A deep squat's static joint torques at most this share of the actuators' limits (g1.EFFORT_LIMIT_NM).
Stop 34 lifted 0.3 and 0.8 kg floor boxes from its squat (trunk 0.7 + 0.5 rad) but not 1.2-2.0 kg
(hips and wrists ~0.2 rad behind the plan; 3 kg fell); the waist pitch needs 35 N m there without a
box, 41 N m with 1.5 kg (measured, this search's poses)."""
DEEP_LIMIT_MARGIN_RAD = 0.05
"""A deep squat's leg joints this far inside their position limits at least, room for the controller
to move them (the IK keeps 0.02 rad; hip pitch works at ~-2.2 of -2.53 rad, ankle pitch ~-0.5 of -0.87;
the waist may be pulled near its 0.52, DEEP_BENDS)."""
HOLD_TORQUE_SHARE = 1.0
"""A pick's lifted pose (squatting or standing; a deep squat keeps DEEP_TORQUE_SHARE) keeps each joint's
static torque (`static_torques`: gravity, the box's weight at the hands) within this share of its
actuator's limit (inf: not checked). A pick that "did not come up" (the hands 8-15 cm below the plan
after the lift, the box set back down) was the waist pitch (35 N m) saturating while it lifted a box held
at arm's length (`g1 bench objects` 85.7, traced: the waist at its limit from the lift on). Over seeds
80-99 the search's lifted pose had a static share of 1.00-1.66 in the 13 picks that did not come up,
0.48-0.97 in the picks that came up, and two exceptions (94.7 at 1.02 and 93.3 at 1.17 came up).
Measured on the trials whose pick plan the check changes (stop 45; the others were not run again):
seeds 90-99 (18 trials) inf -> 1.0: placed 2 -> 1 (93.3 refused), falls 3 -> 2, did not come
up 9 -> 0; seeds 100-119, not looked at before (35 trials): placed 4 -> 4 (the same four), falls 7 -> 3,
did not come up 21 -> 1. At 0.95 seeds 90-99 gave placed 1, falls 0. A leaning squat's trunk alone
takes ~0.85-0.9 of the waist's limit, so light boxes are lifted leaning and heavier ones are refused (2 kg
on a 0.53 m table: tests/generator/test_gen_goal_stances.py). A leaning place's pose (the box held where it goes) keeps the
same share: a 2.7 kg box leaned to a 0.31 m table put the waist at its 35 N m while the hands went 20 cm
below the plan and the box fell over (167.15, traced; its static share 1.3). Checked on every place, it
also refused upright places of 4.4-5.3 kg boxes onto tables that are placed (147.7, 180.13, 182.13), and
refused the upright squats that fall setting 1.9-5.1 kg boxes on 0.34-0.40 m supports (176.18, 182.2,
183.15): those are not checked now."""
FLAT_SOLE_M = 0.005
FLAT_SOLE_RAD = 0.03
"""A deep squat's soles within this of where they stand, flat (the heels down: the ankles' dorsiflexion
limit otherwise lifts them)."""
STAND_LEAN_PELVIS_RAD = 0.15
"""Standing leaning: the pelvis's pitch target (the waist pulls LEAN_WAIST_RAD). Only for hands at
SQUAT_BELOW_M or higher (stop 34, objects34: a 1.0 kg box on a 0.63 m table, hands at 0.72 m, kept
only standing leaning and the robot fell stepping in)."""
STAND_LEAN_GAPS_M = (0.28, 0.34)
"""Standing leaning: the soles' middle this far from the box (a box whose near face is within ~0.15 m
of a table's edge leaves an upright stance's pelvis closer than MIN_EDGE_CLEARANCE_M: bench objects
seeds 7, 8, 9, 13-15: 15 of 60 picks from 0.72-0.95 m tables were refused so)."""
CONTINUATION_STEP_M = 0.08
SQUAT_PELVIS_M = (0.66, 0.60, 0.55)
"""Pelvis heights tried below standing (the fall monitor calls 0.40 m a fall; a leaning squat
planned at 0.46 m sank to 0.40 m under the whole-body controller, measured)."""
FEASIBLE_PELVIS_M = 0.05
MIN_PELVIS_M = 0.51
MAX_TILT_RAD = 0.75
"""The pelvis's tilt a pose may have (the safety layer calls 1.0 rad a fall)."""
SQUAT_BELOW_M = 0.85
"""Hands below this (above the ground): squatting is tried too (standing, the pelvis may sink only
STANDING_GIVE_M: a box on a 0.64 m table reached standing with the pelvis 11 cm down, bench objects
seed 8, is a squat and is tried as one)."""
LEAN_BELOW_M = 0.7
"""Hands below this: leaning (squatting) is tried too."""
LEAN_MAX_KG = 3.0
"""Leaning only with a box lighter than this: leaning squats picking 3.2 and 5.6 kg boxes fell at the
lift (bench objects seeds 8 and 9; a 0.5 kg box was picked leaning)."""
MIN_HAND_Z_M = 0.10
"""Hands no lower above the ground (below, the rubber hands strike the floor: a fall by body contact)."""
LOWEST_GRASP_M = 0.40
"""Below this (hands above the ground) only the deep squat is tried: with the pelvis at MIN_PELVIS_M or
higher, no candidate held a box lower than ~0.45 m (measured over the issue 25 scenes and the
tests' boxes); it only cost 5-10 s of CPU to find that out each time."""
FEASIBLE_RESIDUAL_M = 0.02
"""Kept within this (the grasp itself refuses beyond 3 cm from the stance the steps end in)."""
FEASIBLE_COM_M = 0.02
EDGE_CONE_RAD = math.radians(60.0)
LOW_BOX_Z_M = 0.6
HAND_BELOW_TOP_M = 0.07
WAIST_PITCH = g1.JOINT_INDEX["waist_pitch_joint"]
BODY_SEGMENTS = (
    # (frame from, frame to, radius m, meets the box too)
    ("left_hip_pitch_link", "left_knee_link", 0.06, True),
    ("right_hip_pitch_link", "right_knee_link", 0.06, True),
    ("left_knee_link", "left_ankle_roll_link", 0.05, True),
    ("right_knee_link", "right_ankle_roll_link", 0.05, True),
    ("pelvis_contour_link", "torso_link", 0.13, True),  # the trunk needs ~0.18 m from a table (issue 17)
    ("torso_link", "head_link", 0.09, True),
    ("left_shoulder_pitch_link", "left_elbow_link", 0.04, False),
    ("right_shoulder_pitch_link", "right_elbow_link", 0.04, False),
    ("left_elbow_link", "left_wrist_roll_link", 0.035, False),
    ("right_elbow_link", "right_wrist_roll_link", 0.035, False),
)
SIDE_STEPS_M = (0.06,)
"""A pick's stances off the box's centre line (module docstring): the soles' middle this far across the
heading, the box held off to one side (the waist and arms take it; the CoM shift counts it). 0.12 m
was tried too (`g1 bench objects` seeds 130-134, 140-147, the layer): both picks planned from it fell
(145.4, a 2.7 kg box: the far hand never reached its face, the box's weight fed forward threw the robot
back; 131.13 in the carry), the three from 0.06 m were placed (140.8, 146.6, 134.16)."""
SIDE_MAX_KG = 3.0
"""Off the line only a box lighter than this, and upright (not leaning). Measured (`g1 bench objects`
seeds 130-134 and 140-142, the layer): of 6 picks off the line, the 2.0 and 2.1 kg upright ones were
placed; the 5.2-5.4 kg ones fell at the pick or in the carry (3) or did not come up (1), and a 2.0 kg
leaning squat by a 0.33 m table fell stepping in. With these rules and SIDE_STEPS_M, seeds 130-134 and
140-151 (340 trials): 7 picks off the line, all lifted, none fell; 3 placed, 4 refused at the place (the
floor, a 0.18 m table); every other trial as without them."""
SIDE_MIN_SIN = 0.2
"""Stances off the line only where the heading's lateral has at least this share of the edge's normal
(the box turned ~12 deg or more to the edge): square on, a step aside brings the pelvis no farther out."""
TABLE_TOP_THICKNESS_M = 0.04
ARMS_BACK = g1.DEFAULT_Q_RAD.copy()
"""Stepping up to a table: the arms swung back (hand points ~5 cm ahead of the pelvis instead of
17 cm at table height), so the hands cannot catch the table's edge (it threw the robot over,
measured)."""
for _side in ("left", "right"):
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_shoulder_pitch_joint"]] = 0.6
    ARMS_BACK[g1.JOINT_INDEX[f"{_side}_elbow_joint"]] = 0.4
STANDING_GIVE_M = 0.06
"""A standing candidate's pelvis may sink this much below nominal to reach (the grasps of issue 17
gave ~1-3 cm); more is a squat, tried as one with its own checks (a 'standing' pose that sank to
0.54 m with the knees at 1.7 rad under a 0.53 m table fell stepping in: bench objects seed 8)."""
MIN_KNEE_RAD = 0.3
"""Knees bent at least this much in a hold pose (a straight knee is singular for the controller; a
reach to a box on a 0.91 m table with one knee at 0.02 rad fell: bench objects seed 8)."""
KNEE_EDGE_CLEARANCE_M = 0.08
"""Knees this far (horizontally) outside a support whose top is above them: stepping in, the swing
knee rises and comes forward (knees 0.00-0.06 m from the edge: four falls on bench objects seed 8)."""
KNEES = (g1.JOINT_INDEX["left_knee_joint"], g1.JOINT_INDEX["right_knee_joint"])
KNEE_HEIGHT_M = 0.35
MIN_EDGE_CLEARANCE_M = 0.18
"""The pelvis stays this far from a support whose top is above the knees: issue 17's measured rule
(box.MIN_EDGE_CLEARANCE_M); closer, the stepping-in knees met 0.53-0.63 m tables and the robot fell
(g1 bench objects seed 8, measured). Not for a top the legs pass under (ABOVE_LEGS_M): there only the
trunk can meet it (TRUNK_EDGE_CLEARANCE_M)."""
ABOVE_LEGS_M = 0.02
"""A table whose top's underside is this much or more above the pelvis (the hold pose's) is above the
legs: the thighs, knees and shins stay below the pelvis stepping in (the stepping knee rises to
~0.55 m), so they pass under its top and the knee and pelvis rules above do not apply; the 0.80-0.95 m
tables (bench objects' "high") have their underside at 0.76-0.91 m, the standing pelvis at 0.756 m."""
STANDING_PELVIS_M = 0.756
"""The G1's pelvis height standing (nominal pose). The legs pass under a top only if its underside is
ABOVE_LEGS_M above this too, not just above a squatting hold pose's pelvis: the robot walks in upright,
and a squat brings the knees forward under a mid-height top (bench objects 29.9: a 0.67 m table, a
squat stance near it allowed by the hold pose's 0.55-0.60 m pelvis, fell stepping in; measured)."""
TRUNK_EDGE_CLEARANCE_M = 0.15
"""The pelvis stays this far from a top above the legs: the trunk's widest at the top's height
(pelvis to chest, 0.76-1.2 m standing) is 0.11 m from the pelvis's axis (the G1's collision meshes,
measured in the nominal pose), plus 4 cm: the steps end within 3 cm of the planned stance (the grasp
refuses beyond) and the trunk sways ~1 cm. With the 0.18 m rule (and the knee rule), bench objects
seeds 9-16 refused 12 of 25 picks from 0.80-0.95 m tables before anything moved: 10 on the pelvis (4
at 0.15-0.18 m; 6 at 0.00-0.10 m, the box turned 31-48 deg to the edge: held square to its faces, no
stance keeps the trunk off), 2 on the knees."""


@dataclass
class HoldPose:
    q: np.ndarray
    residual_m: float
    """The farther hand from its point."""
    com_error_m: float
    """The CoM (xy) from its target over the soles."""
    pelvis_error_m: float
    tilt_rad: float
    """The pelvis's tilt from upright."""


def box_com_shift(mass_kg: float, robot_kg: float, ahead_m: float, left_m: float = 0.0) -> np.ndarray:
    """Where the robot's own CoM goes (heading frame) so that robot and box together stand over the
    soles: back by the box's share of the mass times how far ahead of the soles it is held (and to
    the right by that share of how far left of them it is)."""
    return np.array([-mass_kg / robot_kg * ahead_m, -mass_kg / robot_kg * left_m])


class StanceRefused(ReachRefused):
    """No stance holds the box at its place (the message gives the reason and the closest pose)."""


@dataclass
class Candidate:
    heading: float
    mid_xy: np.ndarray
    gap_m: float
    pelvis_z_m: float
    lean: int
    """UPRIGHT, LEAN, STAND_LEAN or DEEP + k (DEEP_BENDS[k])."""
    preferred: bool = False
    side_m: float = 0.0
    """The soles' middle this far to the left (across the heading) of the box's centre line."""
    residual_m: float = math.inf
    com_error_m: float = math.inf
    collision: str | None = None
    poses: list[np.ndarray] = field(default_factory=list)
    """The hold pose (and, for a pick, the lifted one) at this stance."""

    @property
    def feasible(self) -> bool:
        return self.residual_m <= FEASIBLE_RESIDUAL_M and self.com_error_m <= FEASIBLE_COM_M and self.collision is None

    @property
    def score(self) -> float:
        return self.residual_m + self.com_error_m + (0.05 if self.collision else 0.0)

    def describe(self) -> str:
        side = f" and {abs(self.side_m):.2f} m to its {'left' if self.side_m > 0 else 'right'}" if self.side_m else ""
        return (f"heading {math.degrees(self.heading):.0f} deg, soles' middle {self.gap_m:.2f} m from the box{side}, "
                f"pelvis {self.pelvis_z_m:.2f} m, {BENDS[int(self.lean)]}: hands "
                f"{self.residual_m * 100:.1f} cm off, CoM {self.com_error_m * 100:.1f} cm off"
                + (f", {self.collision}" if self.collision else ""))


@dataclass
class StancePlan:
    """The stance chosen to hold a box at a place, and how the body holds it there."""

    approach: Approach
    chosen: Candidate
    width_m: float
    """The box's extent across the heading (between the palms)."""
    hand_dz_m: float
    """Hands this far above the box's centre."""
    tried: int
    ground_z_m: float = 0.0
    """The ground under the stance (the pelvis heights are world heights above it)."""

    @property
    def pelvis_z_m(self) -> float:
        return self.chosen.pelvis_z_m

    @property
    def lean(self) -> int:
        return self.chosen.lean


def hand_height(box: Box, center_z: float) -> float:
    """Hands above the box's centre (module docstring)."""
    if center_z >= LOW_BOX_Z_M:
        return 0.0
    h = float(box.size[2])
    return max(0.0, min(0.25 * h, h / 2 - HAND_BELOW_TOP_M))


def face_normals(box: Box) -> list[np.ndarray]:
    """The outward normals (world xy) of the box's four side faces."""
    return [np.array([math.cos(box.yaw_rad + k * math.pi / 2), math.sin(box.yaw_rad + k * math.pi / 2)])
            for k in range(4)]


def edge_normal(block: Block, xy_w: np.ndarray) -> np.ndarray:
    """The outward normal (world xy) of the block's side nearest to a point on its top."""
    local = block.local_xy(xy_w)
    half = block.half
    gaps = [half[0] - local[0], half[0] + local[0], half[1] - local[1], half[1] + local[1]]
    n = [np.array([1.0, 0.0]), np.array([-1.0, 0.0]), np.array([0.0, 1.0]), np.array([0.0, -1.0])][int(np.argmin(gaps))]
    c, s = math.cos(block.yaw_rad), math.sin(block.yaw_rad)
    return np.array([c * n[0] - s * n[1], s * n[0] + c * n[1]])


class StancePlanner:
    """plan(...) -> StancePlan, or StanceRefused (module docstring)."""

    def __init__(self, poses: PosePlanner):
        self.poses = poses
        self.ik = poses.ik
        q = self.ik.nominal()
        self._nominal = q
        s = flat_soles(self.ik, q)
        self._mid0 = (s[0][0][:2] + s[1][0][:2]) / 2  # soles' middle relative to the pelvis (heading 0)
        self._soles0 = [(p[:2] - self._mid0, p[2]) for p, _ in s]
        self._frames = {n: self.ik.model.getFrameId(n) for seg in BODY_SEGMENTS for n in seg[:2]}

    # -- the stance ---------------------------------------------------------------------------------
    def stance(self, mid_xy: np.ndarray, heading: float, ground_z: float) -> tuple[np.ndarray, list[Sole]]:
        """The nominal standing pose with the soles' middle at mid_xy, facing heading."""
        c, s = math.cos(heading), math.sin(heading)
        r = np.array([[c, -s], [s, c]])
        q = self._nominal.copy()
        q[:2] = mid_xy - r @ self._mid0
        q[2] += ground_z
        q[3:7] = [0.0, 0.0, math.sin(heading / 2), math.cos(heading / 2)]
        rot = rot_z(np.asarray(heading))
        soles = [(np.array([*(mid_xy + r @ off), ground_z + z]), rot) for off, z in self._soles0]
        return q, soles

    # -- the search ---------------------------------------------------------------------------------
    def plan(self, box: Box, center_w: np.ndarray, support: Block | None, headings: list[float], *,
             ground_z: float = 0.0, lift_m: float | None = None, press_m: float = 0.01,
             what: str = "hold it", hand_dz_m: float | None = None) -> StancePlan:
        """The stance to hold `box` with its centre at center_w on `support` (None: the floor),
        trying `headings` in order; lift_m: also lift it this much (a pick); hand_dz_m: the hands this
        far above the box's centre (a held box: where the pick took it), None: `hand_height`."""
        center_w = np.asarray(center_w, dtype=float)
        dz = hand_height(box, float(center_w[2])) if hand_dz_m is None else hand_dz_m
        mass = box.mass_kg
        nominal = self.poses.nominal_pelvis_m + ground_z
        grasp_z = float(center_w[2]) + dz - ground_z
        size = f"box '{box.name}' ({'x'.join(f'{s:.2f}' for s in box.size)} m, {mass:.1f} kg, centre {center_w[2]:.2f} m up)"
        if grasp_z < MIN_HAND_Z_M:
            raise StanceRefused(f"{size}: no stance can {what}: the hands would hold it {grasp_z * 100:.0f} cm above "
                                f"the ground (the hands strike the ground below {MIN_HAND_Z_M * 100:.0f} cm); "
                                "closest: none tried")
        deep = lift_m is not None or not DEEP_PICKS_ONLY
        if grasp_z < LOWEST_GRASP_M and not deep:  # one candidate, the deepest, for the closest pose
            heading = headings[0]
            depth = grasp_width(box, heading + math.pi / 2)
            gap = max(GAPS_M[1], PREFERRED_CENTER_M - depth / 2)
            fwd = np.array([math.cos(heading), math.sin(heading)])
            cand = Candidate(heading, center_w[:2] - (gap + depth / 2) * fwd, gap, ground_z + DEEP_PELVIS_M[-1],
                             DEEP + len(DEEP_BENDS) - 1)
            self._evaluate(cand, box, center_w, support, grasp_width(box, heading), dz, mass, ground_z, lift_m,
                           press_m)
            raise StanceRefused(f"{size}: no stance can {what}: the hands would hold it {grasp_z:.2f} m above the "
                                f"ground; below {LOWEST_GRASP_M:.2f} m only a deep squat reaches, and it only picks "
                                f"(a carry into one fell: DEEP_PICKS_ONLY); closest: {cand.describe()}")
        # squatting lowers the hands for a box below the waist; above it, it only costs
        levels = [nominal] + ([ground_z + z for z in SQUAT_PELVIS_M] if grasp_z < SQUAT_BELOW_M else [])
        bent: list[tuple[int, ...]] = [(UPRIGHT, LEAN)] * len(levels)
        if grasp_z < LOWEST_GRASP_M:  # no squat reaches so low (LOWEST_GRASP_M): the deep squat only
            levels, bent = [], []
        if grasp_z < DEEP_BELOW_M and deep:
            levels += [ground_z + z for z in DEEP_PELVIS_M]
            bent += [tuple(DEEP + k for k in range(len(DEEP_BENDS)))] * len(DEEP_PELVIS_M)
        if support is not None and support.height_m > KNEE_HEIGHT_M and mass < LEAN_MAX_KG and grasp_z >= SQUAT_BELOW_M:
            levels.append(nominal)  # last: standing off the support's edge, leaning to reach in
            bent.append((STAND_LEAN,))
        best: Candidate | None = None
        tried = 0
        # on the box's line first, at every level; off it (a pick aslant to an edge) only where no stance on
        # it is kept at any level
        off_line = [(h, self._sides(h, center_w, support, lift_m, mass)) for h in headings]
        passes: tuple[dict[float, tuple[float, ...]], ...] = ({h: (0.0,) for h in headings},
                                                              {h: s for h, s in off_line if s})
        for beside, sides_of in enumerate(passes):
            for pelvis_z, bends in zip(levels, bent, strict=True):
                kept: list[Candidate] = []
                for heading in sides_of:
                    fwd = np.array([math.cos(heading), math.sin(heading)])
                    left = np.array([-fwd[1], fwd[0]])
                    width = grasp_width(box, heading)
                    depth = grasp_width(box, heading + math.pi / 2)
                    for lean in bends:
                        if beside and lean != UPRIGHT:
                            continue  # off the line upright only (SIDE_MAX_KG)
                        if lean == LEAN and (grasp_z > LEAN_BELOW_M or pelvis_z >= nominal - 1e-6 or
                                             mass >= LEAN_MAX_KG):
                            continue  # leaning only helps below the waist, squatting
                        preferred = max(GAPS_M[1], PREFERRED_CENTER_M - depth / 2)
                        gaps = (preferred, *(g for g in GAPS_M if abs(g - preferred) > 0.02))
                        if lean == STAND_LEAN:
                            gaps = STAND_LEAN_GAPS_M
                        for gap in gaps if pelvis_z >= nominal - 1e-6 or lean >= DEEP else [g for g in gaps if g >= 0.2]:
                            for side in sides_of[heading]:
                                mid = center_w[:2] - (gap + depth / 2) * fwd + side * left
                                cand = Candidate(heading, mid, gap, pelvis_z, lean,
                                                 preferred=gap == preferred and not side, side_m=side)
                                self._evaluate(cand, box, center_w, support, width, dz, mass, ground_z, lift_m,
                                               press_m)
                                tried += 1
                                if best is None or cand.score < best.score:
                                    best = cand
                                if cand.feasible:
                                    kept.append(cand)
                                    break  # the nearest side that works
                if kept:
                    chosen = min(kept, key=lambda k: (k.preferred is False, k.residual_m + k.com_error_m))
                    return StancePlan(Approach(chosen.mid_xy, chosen.heading), chosen,
                                      grasp_width(box, chosen.heading), dz, tried, ground_z)
        assert best is not None
        why = best.collision if best.collision and best.residual_m <= FEASIBLE_RESIDUAL_M else \
            f"the hands get only within {best.residual_m * 100:.1f} cm" if best.residual_m > FEASIBLE_RESIDUAL_M else \
            f"the CoM is {best.com_error_m * 100:.1f} cm from over the feet"
        raise StanceRefused(f"{size}: no stance can {what} ({tried} tried, pelvis down to {min(levels):.2f} m): {why}; "
                            f"closest: {best.describe()}")

    def _sides(self, heading: float, center_w: np.ndarray, support: Block | None, lift_m: float | None,
               mass_kg: float) -> tuple[float, ...]:
        """Stances off the box's centre line to try (a pick of a box lighter than SIDE_MAX_KG from a
        support whose edge the heading meets aslant): SIDE_STEPS_M, toward where the stance is farther
        from the edge."""
        if support is None or lift_m is None or mass_kg >= SIDE_MAX_KG:
            return ()
        lateral = np.array([-math.sin(heading), math.cos(heading)])
        away = float(lateral @ edge_normal(support, center_w[:2]))
        if abs(away) < SIDE_MIN_SIN:
            return ()
        return tuple(math.copysign(d, away) for d in SIDE_STEPS_M)

    def _evaluate(self, cand: Candidate, box: Box, center_w: np.ndarray, support: Block | None, width: float,
                  dz: float, mass: float, ground_z: float, lift_m: float | None, press_m: float) -> None:
        q, soles = self.stance(cand.mid_xy, cand.heading, ground_z)
        standing = q.copy()
        c = center_w + np.array([0.0, 0.0, dz])
        depth = grasp_width(box, cand.heading + math.pi / 2)
        shift = box_com_shift(mass, self.poses.mass_kg, cand.gap_m + depth / 2, -cand.side_m)
        targets = [hand_points(c, cand.heading, width, -press_m)]
        if lift_m is not None:
            targets.append(hand_points(c, cand.heading, width, -press_m, dz_m=lift_m))
        worst_res, worst_com = 0.0, 0.0
        for t in targets:
            r = self.hold(q, soles, t, cand.heading, shift, cand.pelvis_z_m, cand.lean)
            q = r.q
            cand.poses.append(q)
            worst_res = max(worst_res, r.residual_m)
            worst_com = max(worst_com, r.com_error_m)
            squat = cand.pelvis_z_m < ground_z + self.poses.nominal_pelvis_m - 1e-6
            deep = cand.lean >= DEEP
            if (squat and r.pelvis_error_m > FEASIBLE_PELVIS_M) or \
                    r.tilt_rad > (DEEP_MAX_TILT_RAD if deep else MAX_TILT_RAD) or \
                    r.q[2] - ground_z < (DEEP_MIN_PELVIS_M if deep else MIN_PELVIS_M):
                cand.collision = cand.collision or f"the pelvis ends at {r.q[2]:.2f} m, tilted {r.tilt_rad:.2f} rad"
            held_kg = mass if len(cand.poses) > 1 or lift_m is None else 0.0
            if deep:
                cand.collision = cand.collision or self.deep_fault(r.q, soles)
            # a deep squat's every pose; otherwise a pick's lifted pose and a leaning place's (the box held there)
            held_pose = len(cand.poses) > 1 if lift_m is not None else cand.lean != UPRIGHT
            most = DEEP_TORQUE_SHARE if deep else HOLD_TORQUE_SHARE if held_pose else math.inf
            if math.isfinite(most):
                cand.collision = cand.collision or self.torque_fault(r.q, soles, held_kg, most)
            if not squat and cand.pelvis_z_m - r.q[2] > STANDING_GIVE_M:
                cand.collision = cand.collision or (f"standing, the pelvis sinks to {r.q[2] - ground_z:.2f} m "
                                                    "(a squat, tried as one)")
            knee = min(float(r.q[7 + k]) for k in KNEES)
            if knee < MIN_KNEE_RAD:
                cand.collision = cand.collision or f"a knee is nearly straight ({knee:.2f} rad)"
            if worst_res > FEASIBLE_RESIDUAL_M or worst_com > FEASIBLE_COM_M:
                break  # not kept anyway: the rest is not worth its time
            if cand.collision is None:
                cand.collision = self.collision(q, box, center_w, support)
        if cand.collision is None and support is not None and lift_m is not None and worst_res <= FEASIBLE_RESIDUAL_M:
            # a pick's stepping in: the robot stands at the stance upright, the arms swung back, before it bends
            # to the hold pose (whose pelvis a reach moves back from the edge): the same rules there
            stand = standing.copy()
            stand[7:] = ARMS_BACK
            if path_meets(self.poses, stand, stand, cand.heading, support, tips=False):
                cand.collision = f"stepping in, an arm passes under the top of '{support.name}'"
        cand.residual_m, cand.com_error_m = worst_res, worst_com

    def deep_fault(self, q: np.ndarray, soles: list[Sole]) -> str | None:
        """What keeps a deep squat's pose from being held (None: nothing): a sole off the ground or
        tipped (the heels up), or a joint within DEEP_LIMIT_MARGIN_RAD of its position limit."""
        for (p, rot), frame in zip(soles, SOLE_FRAMES, strict=True):
            at, r = self.ik.frame_pose(q, frame)
            off = float(np.linalg.norm(at - p))
            tipped = float(np.arccos(np.clip((np.trace(rot.T @ r) - 1.0) / 2.0, -1.0, 1.0)))
            if off > FLAT_SOLE_M or tipped > FLAT_SOLE_RAD:
                return f"the {frame.split('_')[0]} sole is {off * 100:.1f} cm off its place, tipped {tipped:.2f} rad"
        legs = np.array(g1.LEG_JOINTS)
        room = np.minimum(q[7 + legs] - g1.Q_MIN_RAD[legs], g1.Q_MAX_RAD[legs] - q[7 + legs])
        k = int(np.argmin(room))
        if room[k] < DEEP_LIMIT_MARGIN_RAD:
            return f"{g1.JOINT_NAMES[legs[k]]} is {room[k]:.3f} rad from its limit"
        return None

    def static_torques(self, q: np.ndarray, soles: list[Sole], box_kg: float) -> np.ndarray:
        """The joint torques (N m, g1 order) that hold pose q still: gravity, a box of box_kg hanging
        from the two hands in equal shares, and the ground's reaction split equally between the soles,
        its centre of pressure under the CoM of robot and box together."""
        ik, pin = self.ik, self.ik.pin
        model, data = ik.model, ik.data
        pin.computeJointJacobians(model, data, q)
        pin.framesForwardKinematics(model, data, q)
        tau = pin.computeGeneralizedGravity(model, data, q).copy()
        weight = np.array([0.0, 0.0, -box_kg * 9.81 / 2])
        hands = []
        for h in HAND_FRAMES:
            fid = model.getFrameId(h)
            hands.append(data.oMf[fid].translation[:2].copy())
            tau -= pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)[:3].T @ weight
        robot_kg = self.poses.mass_kg
        com = (robot_kg * pin.centerOfMass(model, data, q)[:2] + box_kg * np.mean(hands, axis=0)) / (robot_kg + box_kg)
        mid = np.mean([p[:2] for p, _ in soles], axis=0)
        up = np.array([0.0, 0.0, (robot_kg + box_kg) * 9.81 / 2])
        for (p, _), frame in zip(soles, SOLE_FRAMES, strict=True):
            fid = model.getFrameId(frame)
            at = np.array([*(p[:2] + com - mid), p[2]])
            wrench = np.concatenate([up, np.cross(at - data.oMf[fid].translation, up)])
            tau -= pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED).T @ wrench
        return tau[6:]

    def torque_fault(self, q: np.ndarray, soles: list[Sole], box_kg: float,
                     most: float = DEEP_TORQUE_SHARE) -> str | None:
        """A joint whose static torque (`static_torques`) is beyond `most` of its limit (None: none)."""
        tau = self.static_torques(q, soles, box_kg)
        share = np.abs(tau) / g1.EFFORT_LIMIT_NM
        k = int(np.argmax(share))
        if share[k] > most:
            return (f"{g1.JOINT_NAMES[k]} needs {abs(tau[k]):.0f} N m to hold still (its limit "
                    f"{g1.EFFORT_LIMIT_NM[k]:.0f} N m)")
        return None

    def hold(self, q0: np.ndarray, soles: list[Sole], targets: tuple[np.ndarray, np.ndarray], heading: float,
             com_shift_h: np.ndarray, pelvis_z: float, lean: int) -> HoldPose:
        """Both hands at `targets` (palms in across the heading), the pelvis at pelvis_z, the CoM over the
        soles (shifted by com_shift_h, heading frame); lean (LEAN, STAND_LEAN): the pelvis may pitch
        (STAND_LEAN less) and the waist leans forward. Solved by continuation from q0: the pelvis and the hands move there in steps of at
        most CONTINUATION_STEP_M, each step's IK from the last (one jump into a deep squat lands in
        a wrong local solution, measured: hands 10-60 cm off where the steps get within 1 cm)."""
        pp = self.poses
        posture = g1.DEFAULT_Q_RAD.copy()
        if lean:
            posture[WAIST_PITCH] = DEEP_BENDS[lean - DEEP][1] if lean >= DEEP else LEAN_WAIST_RAD
        weights = LEG_LIGHT_POSTURE_WEIGHT.copy()
        weights[WAIST] = 0.5
        com = pp.com_over(soles, com_shift_h)
        rot = rot_z(np.asarray(heading))
        pitch = DEEP_BENDS[lean - DEEP][0] if lean >= DEEP else \
            {UPRIGHT: 0.0, LEAN: LEAN_PELVIS_RAD, STAND_LEAN: STAND_LEAN_PELVIS_RAD}[int(lean)]
        pelvis_rot = rot @ np.array([[math.cos(pitch), 0.0, math.sin(pitch)], [0.0, 1.0, 0.0],
                                     [-math.sin(pitch), 0.0, math.cos(pitch)]])
        z_cap = min(p[2] for p, _ in soles) + pp.nominal_pelvis_m + PELVIS_CAP_ABOVE_NOMINAL_M
        # standing, the pelvis may give a little (the grasps of issue 17, measured in physics)
        standing = pelvis_z >= z_cap - PELVIS_CAP_ABOVE_NOMINAL_M - 1e-6
        start = [pp.hand_point(q0, i) for i in range(2)]
        move = max(abs(pelvis_z - q0[2]), *(float(np.linalg.norm(targets[i] - start[i])) for i in range(2)))
        steps = max(1, math.ceil(move / CONTINUATION_STEP_M))
        q = q0
        for k in range(1, steps + 1):
            a = k / steps
            hands = [(HAND_FRAMES[i], start[i] + a * (targets[i] - start[i])) for i in range(2)]
            for _ in range(4 if k == steps else 2):
                q = self.ik.solve(q, soles, com, q0[2] + a * (pelvis_z - q0[2]), pelvis_rot, posture, hands=hands,
                                  hand_weight=100.0, hand_rot=[(HAND_FRAMES[0], rot), (HAND_FRAMES[1], rot)],
                                  hand_rot_weight=1.0 if lean else 3.0,
                                  pelvis_rot_weight=(10.0, 3.0 if lean else 1.0, 5.0), sole_weight=1000.0,
                                  pelvis_z_weight=1.0 if standing else 30.0, posture_weight=weights, com_weight=300.0,
                                  pelvis_z_max=z_cap, iterations=40 if k == steps else 20)
        res = max(float(np.linalg.norm(pp.hand_point(q, i) - targets[i])) for i in range(2))
        tilt = float(np.arccos(np.clip(self.ik.frame_pose(q, "pelvis")[1][2, 2], -1.0, 1.0)))
        return HoldPose(q, res, float(np.linalg.norm(self.ik.com(q)[:2] - com)), abs(float(q[2]) - pelvis_z), tilt)

    # -- clearance ----------------------------------------------------------------------------------
    def collision(self, q: np.ndarray, box: Box, center_w: np.ndarray, support: Block | None) -> str | None:
        """What part of the body, in pose q, comes into the support's top or the box (None: clear)."""
        ik = self.ik
        ik.pin.framesForwardKinematics(ik.model, ik.data, q)
        pos = {n: ik.data.oMf[f].translation for n, f in self._frames.items()}
        if support is not None and support.height_m > KNEE_HEIGHT_M:
            gap = support.distance_xy(q[:2])
            underside = support.height_m - TABLE_TOP_THICKNESS_M
            above_legs = underside - max(float(q[2]), STANDING_PELVIS_M) >= ABOVE_LEGS_M
            need = TRUNK_EDGE_CLEARANCE_M if above_legs else MIN_EDGE_CLEARANCE_M
            if gap < need:
                return f"the pelvis is {gap:.2f} m from '{support.name}' (stepping in needs >= {need:.2f} m)"
            for side in () if above_legs else ("left", "right"):
                knee_gap = support.distance_xy(pos[f"{side}_knee_link"][:2])
                if knee_gap < KNEE_EDGE_CLEARANCE_M:
                    return (f"the {side} knee is {knee_gap:.2f} m from under '{support.name}' (stepping in needs "
                            f">= {KNEE_EDGE_CLEARANCE_M:.2f} m)")
        half_box = box.size / 2
        c, s = math.cos(box.yaw_rad), math.sin(box.yaw_rad)
        for a, b, radius, meets_box in BODY_SEGMENTS:
            for u in np.linspace(0.0, 1.0, 6):
                p = pos[a] + u * (pos[b] - pos[a])
                if support is not None and support.distance_xy(p[:2]) < radius and \
                        support.height_m - TABLE_TOP_THICKNESS_M - radius < p[2] < support.height_m + radius:
                    return f"the {_part(a, b)} meets the top of '{support.name}'"
                if meets_box:
                    d = p[:2] - center_w[:2]
                    local = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])
                    out = np.maximum(np.abs(local) - half_box[:2], 0.0)
                    if np.linalg.norm(out) < radius and center_w[2] - half_box[2] - radius < p[2] < \
                            center_w[2] + half_box[2] + radius:
                        return f"the {_part(a, b)} meets the box"
        return None


# -- planner jobs (GoalContext.compute: inline, or in the planner process) ---------------------------
@lru_cache(maxsize=4)
def stance_planner(poses: PosePlanner) -> StancePlanner:
    """The StancePlanner over `poses` (one per PosePlanner: the loop's own, or the planner process's)."""
    return StancePlanner(poses)


def plan_stance(poses: PosePlanner, box: Box, center_w: np.ndarray, support: Block | None, headings: list[float],
                ground_z: float, lift_m: float | None, press_m: float, what: str,
                hand_dz_m: float | None = None) -> StancePlan:
    """StancePlanner.plan as a planner job: the stance, squat and lean to hold `box` at center_w."""
    return stance_planner(poses).plan(box, center_w, support, headings, ground_z=ground_z, lift_m=lift_m,
                                      press_m=press_m, what=what, hand_dz_m=hand_dz_m)


HoldStep = tuple[str, tuple[np.ndarray, np.ndarray], np.ndarray, float, int]
"""(name, the hands' two points, CoM shift (heading frame), pelvis height, bend: UPRIGHT/LEAN/STAND_LEAN/DEEP + k)."""


def grasp_hold_poses(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], heading: float, steps: list[HoldStep],
                     box_name: str, planned: str) -> list[np.ndarray]:
    """A pick's poses at the planned squat and lean, each from the one before (via, pre-grasp, contact,
    lift and, from a squat, the rise); ReachRefused when the hands get no closer than 3 cm to a grasp
    point from the stance the steps ended in (`planned`: the stance the search chose)."""
    hold = stance_planner(poses).hold
    out = []
    q = q0
    for name, targets, shift, pelvis_z, lean in steps:
        res = hold(q, soles, targets, heading, shift, pelvis_z, lean)
        if res.residual_m > 0.01 and q is not q0:  # a poor warm start (the pose before): again from the stance
            again = hold(q0, soles, targets, heading, shift, pelvis_z, lean)
            res = again if again.residual_m < res.residual_m else res
        if res.residual_m > 0.03 and name not in ("via", "rise"):
            raise StanceRefused(f"box '{box_name}': from the stance the steps ended in, the hands get only within "
                                f"{res.residual_m * 100:.1f} cm of the {name} points (planned: {planned})")
        q = res.q
        out.append(q)
    return out


def release_hold_poses(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], heading: float,
                       points: tuple[tuple[np.ndarray, np.ndarray], ...], shift: np.ndarray, pelvis_z: float,
                       lean: int, low: bool, planned: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                                     np.ndarray]:
    """A place's poses (above where the box goes, from a squat; set down; hands opened; hands out;
    standing): the box set down at the planned squat and lean; StanceRefused when the hands get no
    closer than 3 cm to where it goes."""
    above, down, opened, out = points
    hold = stance_planner(poses).hold
    q_above = hold(q0, soles, above, heading, shift, pelvis_z, lean).q if low else q0
    down_pose = hold(q_above, soles, down, heading, shift, pelvis_z, lean)
    if down_pose.residual_m > 0.03:  # a poor warm start (the arms as carried): again from the arms' default pose
        # (a 3.7 kg box carried raised, launch/sim_wbc_carry.yaml variant: 3.6 cm from the carried arms, put
        # down from the default ones; measured)
        fresh = q_above.copy()
        fresh[7 + len(g1.LEG_JOINTS):] = g1.DEFAULT_Q_RAD[len(g1.LEG_JOINTS):]
        again = hold(fresh, soles, down, heading, shift, pelvis_z, lean)
        down_pose = again if again.residual_m < down_pose.residual_m else down_pose
    if down_pose.residual_m > 0.03:
        raise StanceRefused(f"from the stance the carry ended in, the hands get only within "
                            f"{down_pose.residual_m * 100:.1f} cm of where the box goes (planned: {planned})")
    q_open = hold(down_pose.q, soles, opened, heading, np.zeros(2), pelvis_z, lean).q
    q_out = hold(q_open, soles, out, heading, np.zeros(2), pelvis_z, lean).q
    ground_z = min(p[2] for p, _ in soles)
    q_stand = poses.stand(q_out, soles, ground_z + poses.nominal_pelvis_m, g1.DEFAULT_Q_RAD)
    return q_above, down_pose.q, q_open, q_out, q_stand


CLEAR_MARGIN_M = 0.02
"""A hand (or a held box) moving past a support keeps this far from its outline, and a hand 1 cm
above its top (CLEAR_ABOVE_M) or below its underside less this."""
CLEAR_ABOVE_M = 0.01
HAND_TIP_M = 0.08
"""The rubber hand reaches this far beyond the hand point (the palm's middle) along the hand frame's x."""
DETOUR_SPACING_M = 0.05
"""A detour's hand points are solved this far apart (the keyframes blend in joint space between)."""
DETOUR_BACK_M = 0.06
"""The last way a detour tries draws the hands this far back (against the heading) before they rise:
hanging (the arms swung back) they are ~5 cm ahead of the pelvis and, raised palms in, their tips
HAND_TIP_M beyond, so near a high table's edge (the pelvis 0.15-0.18 m from it, TRUNK_EDGE_CLEARANCE_M)
the tips rose through its top on both other ways, and a hand hanging under an aslant edge rose into
it: "the hands find no way around" refused 9 of the 9 picks the trunk's rule let through on bench
objects seeds 9-16 (physics); with this way 7 got past it (6 picked, 1 set back by the lift check)."""
DETOUR_BACK_MAX_M = 0.2
DETOUR_SINK_M = 0.2
"""A detour's poses keep the pelvis within this of the hold's height: a way around a 0.90 m top whose
first poses the IK solved with the pelvis at 0.26 m (the hands drawn back below the edge) put the
reference pelvis on its way to the floor and the robot fell at the pick (`g1 bench objects` 153.19,
traced). Ways that sank 6-17 cm are common and were picked (10 of the 99 picks from a support planned on
seeds 140-157, plan only; 141.13 and 149.12 among them were placed in physics), so this only
catches an IK that lost its branch."""
PATH_SAMPLES = 24
BOX_SINK_M = 0.01
"""A held box's bottom counts as in a support's top this far below it."""
ELBOWS = ("left_elbow_link", "right_elbow_link")
WRISTS = ("left_wrist_pitch_link", "right_wrist_pitch_link")
WRIST_CLEAR_M = 0.05
"""The wrists keep this far outside a support's outline, or this far below its underside, where a hand
point keeps CLEAR_MARGIN_M: the wrist's links reach ~3 cm around its joint, and a blend that kept the
hands and elbows clear took a wrist joint 2.6 cm outside a 0.89 m top's edge, 1.2 cm under it: the
wrist met the underside rising and the robot fell at the pick (`g1 bench objects` 145.1, traced)."""


def _probes(poses: PosePlanner, q: np.ndarray, heading: float, box_probes: tuple[tuple[float, float], ...],
            tips: bool = True) -> tuple[list[tuple[np.ndarray, float]], list[np.ndarray]]:
    """The points that must stay clear of a support in pose q, each with its margin: (each hand point,
    its tip and the elbows (CLEAR_MARGIN_M), the wrists (WRIST_CLEAR_M); with a box held, the box's
    points (forward, down) from the middle between the hands)."""
    fwd = np.array([math.cos(heading), math.sin(heading), 0.0])
    frames = [poses.ik.frame_pose(q, HAND_FRAMES[i]) for i in range(2)]
    hands = [p for p, _ in frames]
    body = [(p, CLEAR_MARGIN_M) for p in (*hands, *(poses.ik.frame_pose(q, f)[0] for f in ELBOWS))]
    body += [(poses.ik.frame_pose(q, f)[0], WRIST_CLEAR_M) for f in WRISTS]
    if tips:
        body += [(p + HAND_TIP_M * r[:, 0], CLEAR_MARGIN_M) for p, r in frames]
    mid = (hands[0] + hands[1]) / 2
    return body, [mid + f * fwd - np.array([0.0, 0.0, d]) for f, d in box_probes]


def path_meets(poses: PosePlanner, q_a: np.ndarray, q_b: np.ndarray, heading: float, block: Block,
               box_probes: tuple[tuple[float, float], ...] = (), tips: bool = True) -> bool:
    """Whether the straight configuration-space move from q_a to q_b (the way keyframes blend) takes
    a hand, its tip or an elbow into `block`'s top (within CLEAR_MARGIN_M of its outline, between its
    underside less CLEAR_MARGIN_M and CLEAR_ABOVE_M above it), a wrist so within WRIST_CLEAR_M, or the
    held box's points (`box_probes`, see _probes) below its top (a box set down on it ends resting
    there). tips: the hands' tips too."""
    top, underside = block.height_m + CLEAR_ABOVE_M, block.height_m - TABLE_TOP_THICKNESS_M
    for s in np.linspace(0.0, 1.0, PATH_SAMPLES):
        q = q_a + s * (q_b - q_a)
        q[3:7] /= np.linalg.norm(q[3:7])
        body, box = _probes(poses, q, heading, box_probes, tips)
        for p, margin in body:
            if underside - margin < p[2] < top and block.distance_xy(p[:2]) < margin:
                return True
        for p in box:
            if underside - CLEAR_MARGIN_M < p[2] < block.height_m - BOX_SINK_M and block.distance_xy(p[:2]) < CLEAR_MARGIN_M:
                return True
    return False


def detour_poses(poses: PosePlanner, q_a: np.ndarray, q_b: np.ndarray, soles: list[Sole], heading: float,
                 shift: np.ndarray, pelvis_z: float, lean: int, block: Block, clear_z_m: float,
                 box_probes: tuple[tuple[float, float], ...] = (), tips: bool = True, strict: bool = False
                 ) -> list[np.ndarray]:
    """Poses to put between q_a and q_b so that the hands (and a held box) go around `block` instead
    of through it; [] where the straight move keeps clear (path_meets). The hands move at the higher of their
    two heights and clear_z_m: straight up, across, straight down, solved every DETOUR_SPACING_M from
    the pose before (one IK branch: independent solutions blend through other ones). Measured: a
    straight move from the arms hanging to above a box on a 0.95 m table swung a hand into the
    table's top from below, the arm caught and the robot fell stepping back (bench objects seed 12,
    trial 3). Two ways are tried, by their corners alone, then each solved every DETOUR_SPACING_M
    back from q_b (keeping its IK branch) and on from q_a, then a third so solved, the first whose every blend keeps clear kept, else (strict: StanceRefused, before the hands
    move) the one with the fewest that do not: across below, then straight up or down; straight up
    (or down) to the higher height, across, straight down; drawn back (`_draw_back`), then as the second."""
    if not path_meets(poses, q_a, q_b, heading, block, box_probes, tips):
        return []
    a = [poses.hand_point(q_a, i) for i in range(2)]
    b = [poses.hand_point(q_b, i) for i in range(2)]
    high = max(a[0][2], a[1][2], b[0][2], b[1][2], clear_z_m)
    fwd = np.array([math.cos(heading), math.sin(heading), 0.0])
    drawn = [p - _draw_back(block, p, fwd) * fwd for p in a]
    ways = ([a, [np.array([*p[:2], a[0][2]]) for p in b], b],  # across below, then up (or down)
            [a, [np.array([*p[:2], high]) for p in a], [np.array([*p[:2], high]) for p in b], b],
            # last: drawn back first, then up, across, down (the tips clear of a near edge)
            [a, drawn, [np.array([*p[:2], high]) for p in drawn], [np.array([*p[:2], high]) for p in b], b])
    best: tuple[int, list[np.ndarray]] | None = None
    # the corners alone first (fewest keyframes), then every DETOUR_SPACING_M, solved from q_b back
    # (keeping its IK branch) or from q_a on
    tries = [(math.inf, ways[0], False), (math.inf, ways[1], False),
             *((DETOUR_SPACING_M, way, back) for way in ways[:2] for back in (True, False)),
             *((DETOUR_SPACING_M, ways[2], back) for back in (True, False))]
    for spacing, corners, backward in tries:
        if backward:
            chain = _along(poses, q_b, corners[::-1], soles, heading, shift, pelvis_z, lean, spacing)[:-1][::-1]
        else:
            chain = _along(poses, q_a, corners, soles, heading, shift, pelvis_z, lean, spacing)[:-1]
        path = [q_a, *chain, q_b]
        bad = sum(path_meets(poses, u, v, heading, block, box_probes, tips) for u, v in pairwise(path))
        if max((pelvis_z - float(q[2]) for q in chain), default=0.0) > DETOUR_SINK_M:
            bad += len(path)  # a way the IK found only by dropping the pelvis: never kept
        if best is None or bad < best[0]:
            best = (bad, chain)
        if bad == 0:
            return chain
    assert best is not None
    if strict:  # a 5.6 kg box on a 0.84 m table: the way kept with a blend through the top caught a hand
        # under it and the robot fell at the lift (bench objects seed 12, trial 1)
        raise StanceRefused(f"the hands find no way around the top of '{block.name}' ({block.height_m:.2f} m): "
                            f"every way tried passes within {CLEAR_MARGIN_M * 100:.0f} cm of it (a wrist within "
                            f"{WRIST_CLEAR_M * 100:.0f} cm) or drops the pelvis more than {DETOUR_SINK_M * 100:.0f} cm")
    return best[1]


def _draw_back(block: Block, p: np.ndarray, fwd: np.ndarray) -> float:
    """How far back (against fwd) hand point p goes before it rises: DETOUR_BACK_M at least, more
    (up to DETOUR_BACK_MAX_M) until it and its tip, pointing ahead, are CLEAR_MARGIN_M clear of
    `block`'s outline."""
    d = DETOUR_BACK_M
    while d < DETOUR_BACK_MAX_M and min(block.distance_xy((p - d * fwd)[:2]),
                                        block.distance_xy((p + (HAND_TIP_M - d) * fwd)[:2])) < 2 * CLEAR_MARGIN_M:
        d += 0.02
    return d


def raised_pose(poses: PosePlanner, q0: np.ndarray, soles: list[Sole], heading: float, dz_m: float,
                shift: np.ndarray, pelvis_z: float) -> HoldPose:
    """The hold pose with both hands dz_m above where they are in q0 (a held box raised), upright."""
    targets = tuple(poses.hand_point(q0, i) + np.array([0.0, 0.0, dz_m]) for i in range(2))
    return stance_planner(poses).hold(q0, soles, (targets[0], targets[1]), heading, shift, pelvis_z, UPRIGHT)


def straight_poses(poses: PosePlanner, q_a: np.ndarray, q_b: np.ndarray, soles: list[Sole], heading: float,
                   shift: np.ndarray, pelvis_z: float, lean: int, block: Block | None = None) -> list[np.ndarray]:
    """Poses to put between q_a and q_b so that the hands go straight from where they are in q_a to
    where they are in q_b (every DETOUR_SPACING_M, each solved from the one before), not along the
    joint-space blend. Measured: from a stance off the box's line (SIDE_STEPS_M) the arm reaching across
    swung from its via pose to the pre-grasp pose through ~2.9 rad of its shoulder, its hand dipped
    under a 0.88 m table's top on the way and the robot fell (bench objects 133.1). block: only where the
    blend takes a hand into its top (`path_meets`; else []): from a stance on the box's line the blend's
    hand rose into a 0.85 m top's underside and the robot fell (bench objects 144.0, traced). The caller
    times these poses by joint speed: spread evenly over a second, a wrist turned at 24.8 rad/s (its
    limit 22) on 143.10."""
    if block is not None and not path_meets(poses, q_a, q_b, heading, block):
        return []
    a = [poses.hand_point(q_a, i) for i in range(2)]
    b = [poses.hand_point(q_b, i) for i in range(2)]
    return _along(poses, q_a, [a, b], soles, heading, shift, pelvis_z, lean)[:-1]


def _along(poses: PosePlanner, q: np.ndarray, corners: list[list[np.ndarray]], soles: list[Sole], heading: float,
           shift: np.ndarray, pelvis_z: float, lean: int, spacing: float = DETOUR_SPACING_M) -> list[np.ndarray]:
    """Poses with the hands every `spacing` along the polyline `corners` (pairs of hand points; at
    least at each corner), each solved from the one before."""
    hold = stance_planner(poses).hold
    out: list[np.ndarray] = []
    for p0, p1 in pairwise(corners):
        n = max(1, math.ceil(max(float(np.linalg.norm(p1[i] - p0[i])) for i in range(2)) / spacing))
        for j in range(1, n + 1):
            u = j / n
            targets = (p0[0] + u * (p1[0] - p0[0]), p0[1] + u * (p1[1] - p0[1]))
            q = hold(q, soles, targets, heading, shift, pelvis_z, lean).q
            out.append(q)
    return out


BENDS = {UPRIGHT: "upright", LEAN: "leaning", STAND_LEAN: "standing leaning",
         **{DEEP + k: f"deep squat (pelvis pitched {p:.2f}, waist {w:.2f} rad)" for k, (p, w) in enumerate(DEEP_BENDS)}}


def _part(a: str, b: str) -> str:
    side = "left " if a.startswith("left") else "right " if a.startswith("right") else ""
    names = {"hip_pitch_link": "thigh", "knee_link": "shin", "pelvis_contour_link": "trunk", "torso_link": "chest",
             "shoulder_pitch_link": "upper arm", "elbow_link": "forearm"}
    key = a.removeprefix("left_").removeprefix("right_")
    return side + names.get(key, key)


def pick_headings(box: Box, box_xy: np.ndarray, support: Block | None, robot_xy: np.ndarray) -> list[float]:
    """Headings (facing the box square on) to pick it from, best first (module docstring)."""
    normals = face_normals(box)
    if support is not None:
        edge = edge_normal(support, box_xy)
        ok = [n for n in normals if float(n @ edge) >= math.cos(EDGE_CONE_RAD) - 1e-9]
        ok.sort(key=lambda n: -float(n @ edge))
    else:
        toward = np.asarray(robot_xy, dtype=float) - box_xy
        toward = toward / max(float(np.linalg.norm(toward)), 1e-6)
        ok = sorted(normals, key=lambda n: -float(n @ toward))[:2]
    return [math.atan2(-n[1], -n[0]) for n in ok]


def place_heading(support: Block | None, xy: np.ndarray, robot_xy: np.ndarray) -> float:
    """Facing the support's edge nearest to the place, or (the floor) from where the robot is."""
    if support is not None:
        n = edge_normal(support, xy)
    else:
        n = np.asarray(robot_xy, dtype=float) - xy
        n = n / max(float(np.linalg.norm(n)), 1e-6)
    return math.atan2(-n[1], -n[0])


__all__ = ["DEEP", "LEAN", "STAND_LEAN", "UPRIGHT", "Candidate", "StancePlan", "StancePlanner", "StanceRefused", "box_com_shift", "detour_poses", "edge_normal",
           "face_normals", "grasp_hold_poses", "hand_height", "path_meets", "pick_headings", "place_heading", "plan_stance",
           "raised_pose", "release_hold_poses", "stance_planner", "straight_poses"]
