"""Walking from a velocity command: footsteps, step timing, the capture-point (DCM) plan and swing
feet, per control tick, for the whole-body controller.

The linear inverted pendulum (capture_point.py): with the centre of pressure (CoP) held at a
stance foot u, the divergent component xi = c + c_dot / w evolves as xi(t) = u + (xi_0 - u) e^{w t}.
A step lasts T = double support + single support, from the stance foot's touchdown to the next
foot's. Call b = xi - u the DCM offset at touchdown; the next touchdown then sees
b' = b E - d with E = e^{w T} and d the step (next foot minus this one). Walking periodically with
steps d_1, d_2, d_1, ... (the lateral steps alternate out and in) needs, for the stance foot whose
next two steps are d_1 then d_2,

    b = (d_1 E + d_2) / (E^2 - 1)

(forward: d_1 = d_2 = vx T gives b = vx T / (E - 1)). The commanded velocity sets the steps, the
steps set the nominal offsets. Walking fast the steps come quicker (step_duration_for: the double
support shrinks as the steps near their limits), so a step covers less ground and the command's
speed limits (feasible) lie further out; slow walking keeps the configured timing.

Step location adjustment (Khadiv et al. 2016; Griffin et al. 2017): every tick the DCM measured
now is propagated to the coming touchdown under the CoP the controller asks for, and the swing
foot is sent to land at that predicted DCM less the nominal offset of the next stance. Whatever
the DCM's error (a push, model error), the next step absorbs it, and the steps after it are the
commanded ones again: the robot's speed follows the command within one step. Inside a foot, the
CoP tracks the nominal DCM, p = u + (1 + k)(xi - xi_nom), clipped to the sole (the rest is left to
the step). The landing point is frozen late in the swing so the foot can get there.

Recovery steps: a step whose DCM strays GaitConfig.recovery_dcm_error_m from its plan during the
swing, or whose landing stays beyond the step limits after its timing was adjusted (a push), is
marked (GaitTargets.recovery) until it lands; the tracker then holds the swing foot to its path
harder (WbcConfig.recovery_swing_weight), so the QP steps rather than swinging the leg back. One the
DCM's error made (GaitConfig.pushed_dcm_error_m: GaitTargets.pushed) may land wider
(recovery_max_width_m), and the tracker holds the CoM lower in it (WbcConfig.recovery_com_lower_m).
The CoM is held lower in the step after a pushed one too (GaitConfig.after_push_steps,
GaitTargets.after_push; on since stop 46), and, an option off by default, the swing foot lifted at
once when the DCM strays in a double support (GaitConfig.early_lift_dcm_error_m). The DCM's error
alone does not tell a push (turning and slowing down put it as far off its plan), so they act only after a push
told by what the pendulum cannot explain (GaitConfig.push_detect_m: the DCM running away from where
the pendulum under the asked CoP takes it; a command change moves the plan, not the DCM).

Swing feet: the horizontal path and the yaw are re-planned each tick as a minimum-jerk segment
from the reference's current position, velocity and acceleration to the (moving) landing point,
arriving a little before touchdown; the height is a smooth bump of `swing_height_m` with zero
velocity and acceleration at both ends.

Steps and platforms (terrain.py, the scene's map): a landing is snapped onto one tread and keeps
the level it chose for its step (once swinging, whatever the DCM asks); a foot on another level than
the stance foot lands on the stance foot's level (step-to: never two treads in one swing); the DCM's
plan moves with the snapped landing; a step onto another
level is not made sooner and swings long enough to cross (terrain_swing_speed_mps); the double
support before it lasts until the DCM is over the stance sole (terrain_max_wait_s); near a step the
CoP may go further sideways (terrain_cop_limit_y_m). The plan moved with the landing, and the landing
predicted from the CoP, form a loop whose CoP alternates tick to tick; on a terrain the CoP sent is
the mean of the last two ticks' (terrain_cop_two_tick_mean). A foot that finds no place on the
stance foot's level comes beside the stance foot, never onto it.

Starting from standing, a weight shift first brings the DCM onto the first stance foot's nominal
place; stopping, once the command is zero and the feet stand side by side, the DCM returns to
the middle between the feet. Nothing here reads simulator ground truth; positions are the
controller's odometry frame.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from g1_control.errors import WbcConfigError
from g1_control.rotations import wrap_angle
from g1_control.trackers.wbc import capture_point as cp
from g1_control.trackers.wbc.terrain import Terrain

LEFT, RIGHT = 0, 1
_SIDE = (1.0, -1.0)


@dataclass(frozen=True)
class GaitConfig:
    single_support_s: float = 0.28
    double_support_s: float = 0.07
    start_s: float = 0.5
    """Weight shift onto the first stance foot before the first lift-off."""
    stop_s: float = 0.6
    """DCM back to the middle of the feet after the last step."""
    step_width_m: float = 0.22
    """Sole centre to sole centre, side to side, walking straight."""
    min_width_m: float = 0.16
    max_width_m: float = 0.45
    max_forward_m: float = 0.42
    """Landing sole ahead of the stance sole, at most (heading frame of the step)."""
    max_backward_m: float = 0.32
    max_relative_yaw_rad: float = 0.7
    plan_turn: bool = True
    """The nominal DCM offsets follow the turn (nominal_dcm_offset's wz); off: planned as if straight."""
    swing_height_m: float = 0.07
    swing_rise: float = 0.4
    swing_fall: float = 0.4
    """Fractions of the single support the swing foot takes to rise to its apex and to come down."""
    swing_hold_s: float = 0.05
    """Fraction of the single support the swing foot rises before it moves across."""
    swing_arrive_early_s: float = 0.02
    """The horizontal swing ends this long before touchdown (the foot comes straight down)."""
    freeze_landing_after: float = 0.75
    """Fraction of the single support after which the landing point no longer moves."""
    cop_gain: float = 1.5
    """k in p = u + (1 + k)(xi - xi_nom): the DCM's error decays as exp(-k w t) while the CoP can."""
    double_support_cop_gain: float = 1.5
    cop_limit_x_m: float = 0.05
    cop_limit_y_m: float = 0.015
    """How far the CoP may leave the stance sole's centre (sole axes): inside the sole, with margin."""
    com_offset_x_m: float = 0.0
    """Where the CoM stands ahead of the soles' centre (heading frame), standing."""
    moving_speed: float = 0.02
    """A command whose |vx|, |vy| (m/s) or |wz| (rad/s) exceeds this makes the robot step."""
    max_accel: tuple[float, float, float] = (0.8, 0.8, 2.0)
    """The command the gait walks follows the operator's at most this fast (m/s^2, m/s^2, rad/s^2):
    a step's length cannot change much from the one before without a large DCM error."""
    timing_adjust_excess_m: float = 0.03
    """A landing point this far beyond the step limits makes the step land sooner (step timing)."""
    recovery_dcm_error_m: float = 0.2
    """A step during whose swing the DCM strays this far from its nominal plan (a push, say), or whose
    landing lies more than timing_adjust_excess_m beyond the step limits even after its timing was
    adjusted, is a recovery step (GaitTargets.recovery: the tracker holds its swing foot harder)."""
    min_swing_s: float = 0.15
    min_remaining_s: float = 0.08
    """A step made sooner still swings this long in all, and lands no sooner than this from now.
    Pushed (150 N for 0.2 s walking 0.5 m/s), the DCM runs away from the stance foot while the
    recovery step swings; landing sooner leaves it less far to catch. `g1 bench locomotion --only
    wbc/push`: 0.2 survived 2/20 (front_3, front_4), 0.17 3/20, 0.15 and 0.12 4/20 (front_1, front_3,
    front_4, right_4); at 10 stride phases (40 pushes) 0.2: 2/40, 0.15: 5/40; random timelines 0.2:
    6/10, 0.15: 7/10 (measured, one machine). Most pushes still end in a joint over-speed trip, but the
    trip is a symptom: with the safety layer's over-speed and joint-range trips switched off (diagnosis
    only) the same 7 of 20 survive and the other 13 fall (pelvis below 0.4 m or tilted) 0.6-2 s after
    the push. The first recovery step is torque-bound (pushed from behind: the swing hip pitch at its
    88 N m, the stance ankle at its limit, both knees straightening, the foot 6 cm up at the clock's
    touchdown) and lands with the DCM ~0.4 m off its plan, more than 0.42 m steps every 0.22 s can
    catch (0.42 / (e^{w 0.22} - 1) ~ 0.3 m). Tried, not kept (stop 34): touchdown detection from the
    soles' measured heights (an early landing ends the step, a late one keeps lowering the foot for up
    to 0.12 s) survived 5/20 (waiting for the late foot lengthens the single support while the DCM runs
    away); a minimum swing growing with the distance to go 1/20; a 0.02 s double support after a
    recovery step 9/20 but 8/20 at 120 N against 10/20 (measured)."""
    pushed_dcm_error_m: float = 0.25
    """A recovery step during whose swing the DCM strays this far from its plan is a pushed one
    (GaitTargets.pushed): it may land wider (recovery_max_width_m) and the tracker holds the CoM lower
    (WbcConfig.recovery_com_lower_m); a step that is a recovery step only because its landing lies
    beyond the step limits is not. The DCM strays 0.2 m walking 1.0 m/s and in the random timelines
    too: `g1 bench locomotion --only wbc/push`, forward_1.0's speed, wbc/random walked: 0.2: 11/20,
    0.841 m/s, 9/10 (random_s1 fell); 0.25: 9/20, 0.849 (bit-identical to without), 10/10; 0.3: 7/20.
    At 0.25, pushes this stop did not tune on (150 N at phases shifted by 0.1 stride; 120 N; walking
    0.3 m/s, two phase sets; 0.7 m/s), without -> with the lowering and the width: 8 -> 10, 8 -> 10,
    10 -> 8 and 8 -> 10, 2 -> 10 of 20 each. `g1 bench robust --only wbc`: 2 -> 3 falls of 10 (draw s2
    fell at 15.3 s, tilted; measured, one machine)."""
    recovery_max_width_m: float = 0.6
    """A pushed recovery step (GaitTargets.pushed) may land this far sideways from the stance foot (sole
    centre to sole centre; max_width_m otherwise): pushed sideways, the foot on the side the DCM runs to landed
    at the 0.45 m limit with the DCM 8 cm beyond it (measured). `g1 bench locomotion --only wbc/push`
    (swept with pushed_dcm_error_m 0.2) with WbcConfig.recovery_com_lower_m 0.08: 0.45 m 10/20, 0.6 m
    11/20 (alone, without the lowering: 8/20 against 7/20). Tried, not kept (stop 35): the landing and the touchdown time chosen together
    under a model of the swing foot's reach (2 m/s from where it is, touchdown up to 0.1 s later or as
    soon as min_swing_s allows, least DCM error left at touchdown) 2/20, only sooner 5/20, and with
    the lowering 4/20 (the later touchdowns found the foot already on the ground; the reach-limited
    landing asked the foot less than it could do); a step that would cross the stance foot made as
    soon as it may, with a 0.02-0.07 s double support after it: 7/20 (with the lowering 11/20, other
    cases); a CoP target up to 0.1 / 0.08 m off the sole in recovery steps (for the trunk's angular
    momentum) 6/20 (measured, one machine)."""
    after_push_steps: int = 1
    """In the steps after a pushed step (GaitTargets.after_push, this many, from the touchdown of the
    pushed step, double support included; 0: none) the tracker keeps the CoM lowered
    (WbcConfig.recovery_com_lower_m). Pushed from behind, the capture step caught the DCM, then the
    CoM rose 5 cm again while the trailing foot had 0.7 m to swing: its knee at its torque limit, the
    foot stayed behind and the robot rolled over the stance foot (measured). `g1 bench locomotion
    --only wbc/push`: 0: 9/20, 1: 12/20, 2: 11/20; with the pushed width (recovery_max_width_m) in
    the after-push step too: the same 12 (13 with early_lift_dcm_error_m), but front_3 then tripped
    (ankle over-speed) 3 s after its push (measured, one machine). Off (0) by default: the random
    velocity timelines have pushed steps without a push (the DCM 0.25-0.48 m off its plan turning or
    slowing down, as off as in the bench's pushes), and with 1 random_s1 and random_s6 of `--only
    wbc/random` fell (10/10 with 0) on stop 36's code. Since stop 37 it acts only after a told push
    (push_detect_m). On c91c490 with both options (1, 0.2): ungated, they fired in random_s1, s6 and s7
    (no fall there now); gated, in none of random_s0-9 and s11-18 (before push_detect_max_rate_mps) and
    s20-29 (with it; those runs bit-identical to the defaults'), and with it in none of s10 and s19 (uncapped, both were
    told pushes they did not have and s19 fell at 8.6 s); the bench's pushes 9 -> 12/20 (front_1,
    back_0, left_3, right_3 survive; front_3, a survivor without them, trips: a second push told 1.3 s
    after the first, while it staggers, lowers the step after it); unseen, 150 N at phases shifted by 0.1
    stride, 10 -> 11/20 (with and without the rate cap; measured, one machine). Off by default for front_3
    until stop 46. On (1) since, when the bare floor got Coulomb friction (g1_control/sim/scene.py
    grip_physics): there the grid is 9/20 with 0 and 12/20 with 1 (front_1, front_3 and right_3 survive;
    front_3 falls with 0), 150 N at phases shifted by 0.1 stride 9 -> 11/20; the random timelines
    10/10 either way, and `g1 bench locomotion --only wbc`'s walking rows within 2 % with it (measured,
    one machine; tests/trackers/wbc/test_wbc_recovery.py)."""
    early_lift_dcm_error_m: float = math.inf
    """In a step's double support, the DCM this far off its plan lifts the swing foot at once (its
    double support ends, the single support keeps its length, inf: never): pushed late in a swing, the
    swing foot landed where it was going and the other foot waited out the double support (0.11 s)
    while the DCM ran off. `g1 bench locomotion --only wbc/push` (with after_push_steps 1): inf 12/20,
    0.1 12/20, 0.15 and 0.2 13/20 (right_3 survives), alone (after_push_steps 0) 9/20, the same nine
    (measured, one machine). Never sooner than fast_double_support_s into the double support (the
    load needs moving onto the other foot). Off (inf) by default: on the Coulomb floor of stop 46 it
    saves no push of the grid (12/20 with 0.2 and without, 11 and 11 shifted by 0.1 stride; measured)."""
    push_detect_m: float = 0.1
    """A push is told from a command change (or from the DCM drifting off its plan turning hard) by what
    the pendulum cannot explain: each walking tick the measured DCM is compared with where the last one
    would have run under the CoP the gait asked (xi' = p + (xi - p) e^{w dt}); the differences, summed
    with a push_detect_tau_s memory, staying this far (m) from zero for push_detect_hold_s tell a push (a
    command change moves the plan, not the DCM). after_push_steps and early_lift_dcm_error_m act only
    within push_memory_s of a told push; 0: on the DCM's error alone (as before stop 37); inf: never.
    Measured on c91c490 (tau 0.2 s, held 80 ms; GaitTargets.push_drift_m): the bench's 20 pushes (150 N
    for 0.2 s walking 0.5 m/s) reach levels held 80 ms of 0.107-0.19 m, told 0.12-0.36 s after the push starts and before the first
    step the options touch; the 10 random velocity timelines of `g1 bench locomotion` (30 s each, their
    pushed steps turning and slowing down included) at most 0.091 m, and walking before the pushes
    0.048 m. Unmodelled motion of the robot's own counts too: staggering after a push, front_3 was told a
    second push 1.3 s after the first."""
    push_detect_tau_s: float = 0.2
    push_detect_hold_s: float = 0.08
    push_detect_max_rate_mps: float = 2.0
    """Each tick's departure from the pendulum counts at most this fast: a push moves the DCM by about
    F / (m w) per second (150 N on the robot's 35 kg: ~1.1 m/s); faster jumps came and went within
    0.06 s (the estimate's, walking 0.6-0.7 m/s: unseen random_s10 and s19 told pushes without one and
    s19 fell with the options; at 2 m/s neither does, every bench push is still told)."""
    push_memory_s: float = 1.0
    speed_feedback_gain: float = 0.3
    """Per stride, this fraction of the error between the command and the stride's speed (from the
    feet's measured touchdowns) is added to the speed the steps are planned for: the pendulum model
    is not the robot, and without it the robot walks ~20 % slow (measured)."""
    max_speed_correction_mps: float = 0.4
    corrected_speed_margin: float = 0.95
    """The command with the speed correction added walks at most this fraction of the speeds the
    step limits allow at the walked command's cadence, walking fast (from `speed_margin` slowly, with
    the cadence share): at 1.0 m/s the robot walks ~73 % of the plan (measured), and with
    `speed_margin` (0.85) the correction saturated at 0.82 m/s achieved; 0.95: 0.89, and 1.1 m/s
    still walked (0.84); 1.0: 0.90, but 1.05 m/s fell; 0.95 at every speed: random timelines fell
    more often (measured)."""
    speed_margin: float = 0.85
    fast_single_support_s: float = 0.28
    fast_double_support_s: float = 0.03
    fast_max_width_m: float = 0.52
    """... and, walking fast sideways, the widest stance grows from `max_width_m` towards this (with the
    sideways step's own cadence share): within 0.45 m the quicker steps walked 0.31 m/s for 0.4
    (measured); slow walking keeps 0.45 (a wider limit at every speed made the random timelines fall
    more often, measured)."""
    """Walking fast, the steps come quicker (cadence rising with speed): the single support shrinks
    from `single_support_s` towards this as the steps' reach (the nominal step's share of its limits at
    the slow cadence, `step_reach`) grows from `cadence_reach_from` to `cadence_reach_full`, and the
    double support towards `fast_double_support_s`. Shorter steps leave the step adjustment room
    that long steps near their limits do not (at 1.0 m/s on 0.35 s steps the robot walked 0.86 m/s
    or fell, measured); a shorter double support shortens the step without speeding up the swing
    (a shorter single support did: knee and ankle over-speeds at 0.9 m/s, measured)."""
    cadence_reach_from: float = 0.7
    cadence_reach_full: float = 0.9
    """The gait walks at most this fraction of the speeds its step limits allow (the rest is left
    for the step adjustment that balance needs)."""
    stop_tolerance_m: float = 0.05
    """Stopping needs the feet side by side within this (else it steps once more)."""
    terrain_clearance_m: float = 0.07
    """Over a step (the terrain under the swing's path not one level), the swing foot's apex clears
    the highest point under its path by this much."""
    terrain_hold: float = 0.4
    """... and the foot rises this fraction of the single support before it moves across (its toe
    would catch the riser), and comes down only once across."""
    terrain_max_wait_s: float = 0.4
    """Near a step, the double support lasts at most this much longer while the DCM is short of the
    stance sole's centre (VelocityGait._dcm_short_of_stance)."""
    terrain_lift_dcm_margin_m: float = 0.03
    """... the other foot lifts once the DCM is no more than this behind the stance sole's centre: the
    trailing leg swinging up and forward then carries it on (lifted with the DCM at the centre, the
    DCM ran past the CoP's front limit in the trailing swing up, measured: `g1 bench stairs` seed 0)."""
    terrain_cop_two_tick_mean: bool = True
    """On a terrain, the CoP sent to the whole-body QP is the mean of this tick's and the last tick's
    within one contact phase: a notch at the tick rate's Nyquist frequency. Why: where the terrain
    moved a landing, the DCM's plan moves with it (the snap shift) and that landing is predicted from
    this tick's CoP, a loop of gain up to (1 + cop_gain) with a tick's delay. Its CoP alternated
    between the sole's ends every tick (+-5 cm; MuJoCo's measured CoP alternated with it) on every
    step onto a tread (stop 48, `g1 bench stairs`' CoP jumps). Every way of removing the loop tried
    fell far more often (a plan from its own landing, a low-passed shift, no shift, a dead zone, the
    CoP at the sole's centre: stop 48's note), so the loop is kept and only what the QP gets is
    averaged over its 2-cycle. `g1 bench stairs --seed S --trials 10` (three courses), across / top
    reached / falls, without -> with: S = 100, 200, 300, 400 (120 trials) 43/83/77 -> 46/81/74;
    unseen S = 500, 600 (60 trials) 22/41/38 -> 26/41/34; CoP jumps per course of ten 1800-3600 ->
    21-41. Flat ground is untouched (bit-identical)."""
    terrain_cop_limit_y_m: float = 0.03
    """Near a step, the CoP may leave the stance sole's centre this far sideways (cop_limit_y_m on flat
    ground): the longer single supports there let a sideways DCM error grow past what 1.5 cm caught
    (`g1 bench stairs --only step` seeds 0-4: 1 of 5 up and down without a fall, 0 with 1.5 cm)."""
    terrain_level_reach_m: float = 0.45
    """How far along the heading a landing may move to stay on the level it must keep (a foot below the
    stance foot's level comes onto that level; a swing keeps its foothold's level)."""
    terrain_side_follow_reach_m: float = 0.0
    """A step whose landing snapped onto a tread keeps that tread (and the side of its edge) for the
    rest of its swing. With this > 0, when the landing the DCM asks no longer snaps there, the foothold
    still follows it sideways (across the heading), moved along the heading by at most this to stay
    whole on that level (VelocityGait._kept_foothold); 0 (default): the foothold is kept as it was,
    sideways too. Why it exists: walking obliquely onto stairs (`g1 bench stairs --only stairs` seed
    100, 16.7 deg), the first step up snapped onto tread 1 with its sideways place frozen from 5.88 s
    for the rest of the 0.78 s single support while the DCM's landing moved 9 cm further out (world y
    -0.177 kept, -0.265 asked, relative to the stance sole); the foot landed with the DCM 8.6 cm outside
    it, the next single support started with the DCM beyond the sole's CoP range and it ran out to
    0.87 m (pelvis tilt trip at 7.20 s). With 0.1 that step lands with the DCM on the sole's centre line.
    Off because the outcomes did not improve overall (measured, stop 40, `g1 bench stairs --trials 5`
    across/top/falls per course, base -> 0.1): seeds 100-104 stairs 0/1/5 -> 0/2/5, platform 0/3/5 ->
    0/3/5, step 3/5/2 -> 3/5/2; 400-404 stairs 0/1/5 -> 0/2/5, platform 1/2/4 -> 0/2/5, step 4/5/1
    -> 3/5/2; 200-204 stairs 0/0/5 -> 0/1/5, platform 2/3/3 -> 1/3/4, step 3/5/2 -> 1/5/4; 300-304
    stairs 0/0/5 -> 0/0/5. The stairs' top is reached more often (2 -> 5 of 20), the platform and the
    step are crossed less (13 -> 8 of 30): the wider steps it makes leave the rear foot rolling on its
    edge in the next double support. Following only onto a higher level gave the same platform and
    step figures on 200-204."""
    terrain_swing_speed_mps: float = 1.5
    terrain_max_single_support_s: float = 0.8
    """A step onto another level swings longer when its foot has far to go: its horizontal crossing
    averages at most terrain_swing_speed_mps, its single support at most terrain_max_single_support_s.
    A shorter cap (the DCM runs sideways off the stance sole in the 0.7-0.8 s single supports of a
    step up) measured worse, `g1 bench stairs --trials 5` across/top/falls per course, seeds 100-104
    then 400-404, 0.8: stairs 0/1/5 0/1/5, platform 0/3/5 1/2/4, step 3/5/2 4/5/1; 0.65: stairs
    0/0/5 0/0/5, platform 2/2/3 1/1/4, step 4/5/1 3/5/2; 0.7: stairs 0/0/5 0/1/5, platform 1/2/4
    1/1/4, step 3/5/2 4/5/1; 0.6 (seeds 100-104): stairs 0/0/5, platform 0/2/5, step 0/5/5."""
    terrain_plan_long_steps: bool = True
    """A step onto another level gets its longer single support (terrain_swing_speed_mps) as soon as its
    foothold is known, in the double support before it, not only at its lift-off: the DCM's plan in
    that double support is then the long step's (the DCM beside the stance sole's centre at lift-off,
    e^{w T} times closer than for a short step). Lengthened only at lift-off, the step started with the
    DCM where a 0.42 s step wants it, 3-7 cm inside the stance sole, beyond the 3 cm the CoP may go
    sideways (terrain_cop_limit_y_m), and in the 0.8 s single support it ran 0.4-0.9 m sideways
    (`g1 bench stairs --only stairs` seeds 0 and 1, the step from the first tread to the second;
    the DCM from the tracker's estimate, the fall from ground truth). With WbcConfig.terrain_hold_pelvis_up,
    `g1 bench stairs --trials 10` across / top reached / falls of 30 trials, seeds 400-409: off 3/22/27,
    on 11/21/19 (measured, one machine)."""
    terrain_landing_speed_mps: float = 2.0
    """On steps (a terrain that is not flat), a swing's landing point moves at most this fast (m/s; 0:
    unlimited) as it is re-planned. In a long step up (0.8 s single support) the landing is the DCM
    predicted e^{w t_r} ~ 12-20 times further out, and the trailing foot's landing jumped between the
    step's backward and forward limits (0.04 m behind and 0.42 m ahead of the stance foot, tick to
    tick: `g1 bench stairs --only platform` seed 100, 6.52-6.66 s); the swing, re-planned to it each
    tick, whipped the leg and a joint passed its speed limit (35 of the 90 trials of seeds 100-309
    ended in a joint speed trip). `g1 bench stairs --trials 10` across / top reached / falls of 30
    trials, 0 -> 2.0: seeds 100 9/23/21 -> 13/21/17, 200 10/23/20 -> 13/21/17, 300 6/21/24 -> 5/21/25;
    1.0 on 100-200: 24/37/36, 3.0 on 100-300: 25/65/65 (base 25/67/65); 2.0 only in steps onto another
    level, 100-200: 20/41/40. Not looked at before the choice: 400 11/21/19 -> 12/20/18, 500 6/21/24 ->
    11/20/19, 600 10/21/20 -> 11/21/19. Over seeds 100-509 by course: the platform crossed 13 -> 25 of
    50, the step 29 -> 29, the stairs' landing reached 10 -> 4 (every stairs draw falls either way);
    joint speed trips 35 -> 27 of 90 on 100-309 (measured, stop 48; flat ground is not affected).
    The limited landing is not snapped again: until it has caught up it may lie where no sole fits
    (across a riser), and the landing freezes late in the swing wherever it then is."""
    terrain_rise: float = 0.4
    """Over a step, the fraction of the single support the swing foot takes to rise to its apex."""
    terrain_single_support_s: float = 0.42
    """Near a step (as for terrain_speed_mps), every step's single support lasts this long: the swing
    foot goes up, across, then down. The DCM plan is the periodic one of these longer steps (one
    longer step alone made the DCM run sideways past the stance foot, measured)."""
    step_change_m: float = 0.03
    touchdown_height_m: float = math.inf
    """A step onto another level (a step up or down on the scene's terrain) makes its swing foot the
    stance foot only once its sole (leg odometry, which anchors the stance feet at the map's height) is
    this close to the terrain under it (Terrain.under_sole), not at the clock's touchdown while still in
    the air: until then the step goes on, its reference lowering at touchdown_descent_mps below the
    landing, for at most touchdown_max_wait_s (inf: the clock's touchdown). Steps on one level, and
    flat ground, keep the clock's touchdown (on the approach to a step, 20 ms waits on the floor moved
    which foot went up first, measured).
    On the clock, 8 of 262 touchdowns in `g1 bench stairs --seed 100 --trials 5` came with the foot
    2-13 cm above the ground under it (ground truth, mostly stepping down): a foot loaded on nothing.
    Off (inf) by default: with 0.02 the touchdowns more than 2 cm up went 15 of 527 -> 5 of 501 (max
    13 -> 4 cm) on seeds 100-104 and 400-404, but the outcomes did not improve: across 8 -> 7, top reached
    17 -> 16, falls 22 -> 23 of 30 (measured, stop 37)."""
    touchdown_max_wait_s: float = 0.15
    touchdown_descent_mps: float = 0.3
    terrain_speed_mps: float = 0.15
    """Walking towards a step (a level change within `terrain_look_ahead_m` of the feet, along the
    motion), the gait walks at most this fast: a step up or down from a slow DCM (at 0.3 m/s the
    body ran ahead of the long step up, measured)."""
    terrain_look_ahead_m: float = 0.6
    min_advance_m: float = 0.1
    """A foothold snapped back to this little ahead of the stance foot is moved forward instead
    (onto the tread): walking slowly at a riser, the feet otherwise shuffle in front of it."""
    """A landing this much above or below the stance sole is a step up or down."""

    def __post_init__(self) -> None:
        for name in ("single_support_s", "double_support_s", "start_s", "stop_s", "step_width_m", "swing_height_m"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise WbcConfigError(f"GaitConfig.{name} must be a finite number > 0; got {value}")
        if not 0 < self.min_width_m <= self.step_width_m <= self.max_width_m:
            raise WbcConfigError(f"GaitConfig needs 0 < min_width_m <= step_width_m <= max_width_m; got "
                                 f"{self.min_width_m}, {self.step_width_m}, {self.max_width_m}")
        if not 0 <= self.freeze_landing_after <= 1:
            raise WbcConfigError(f"GaitConfig.freeze_landing_after must be in [0, 1]; got {self.freeze_landing_after}")
        if not (0 < self.fast_single_support_s <= self.single_support_s
                and 0 < self.fast_double_support_s <= self.double_support_s):
            raise WbcConfigError(f"GaitConfig needs 0 < fast_single_support_s <= single_support_s and 0 < "
                                 f"fast_double_support_s <= double_support_s; got {self.fast_single_support_s}, "
                                 f"{self.single_support_s}, {self.fast_double_support_s}, {self.double_support_s}")
        if not (np.isfinite(self.recovery_max_width_m) and self.recovery_max_width_m > 0):
            raise WbcConfigError(f"GaitConfig.recovery_max_width_m must be a finite number > 0; got "
                                 f"{self.recovery_max_width_m}")
        if not (isinstance(self.after_push_steps, int) and self.after_push_steps >= 0):
            raise WbcConfigError(f"GaitConfig.after_push_steps must be an integer >= 0; got {self.after_push_steps!r}")
        if not self.early_lift_dcm_error_m > 0:  # inf: never
            raise WbcConfigError(f"GaitConfig.early_lift_dcm_error_m must be > 0 (inf: never); got "
                                 f"{self.early_lift_dcm_error_m}")
        if not (np.isfinite(self.terrain_landing_speed_mps) and self.terrain_landing_speed_mps >= 0):
            raise WbcConfigError(f"GaitConfig.terrain_landing_speed_mps must be a finite number >= 0 (0: unlimited); "
                                 f"got {self.terrain_landing_speed_mps}")
        if not self.push_detect_m >= 0:  # inf: never a push
            raise WbcConfigError(f"GaitConfig.push_detect_m must be >= 0 (0: no check, inf: never); got "
                                 f"{self.push_detect_m}")
        for name in ("push_detect_tau_s", "push_detect_hold_s", "push_memory_s", "push_detect_max_rate_mps"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0) or (name in ("push_detect_tau_s", "push_detect_max_rate_mps") and value == 0):
                raise WbcConfigError(f"GaitConfig.{name} must be a finite number "
                                     f"{'> 0' if name in ('push_detect_tau_s', 'push_detect_max_rate_mps') else '>= 0'}; got {value}")
        if not self.max_width_m <= self.fast_max_width_m:
            raise WbcConfigError(f"GaitConfig needs max_width_m <= fast_max_width_m; got {self.max_width_m}, "
                                 f"{self.fast_max_width_m}")
        if not 0 <= self.cadence_reach_from < self.cadence_reach_full:
            raise WbcConfigError(f"GaitConfig needs 0 <= cadence_reach_from < cadence_reach_full; got "
                                 f"{self.cadence_reach_from}, {self.cadence_reach_full}")
        if not self.touchdown_height_m > 0:  # inf: on the clock
            raise WbcConfigError(f"GaitConfig.touchdown_height_m must be > 0 (inf: on the clock); got "
                                 f"{self.touchdown_height_m}")
        for name in ("touchdown_max_wait_s", "touchdown_descent_mps", "terrain_side_follow_reach_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise WbcConfigError(f"GaitConfig.{name} must be a finite number >= 0; got {value}")
        if not 0 <= self.swing_arrive_early_s < self.fast_single_support_s:
            raise WbcConfigError(f"GaitConfig.swing_arrive_early_s must be in [0, fast_single_support_s); got "
                                 f"{self.swing_arrive_early_s}")

    @property
    def step_s(self) -> float:
        return self.single_support_s + self.double_support_s


@dataclass
class GaitTargets:
    """What the gait asks of the whole-body controller this tick (odometry frame, world axes)."""

    contacts: np.ndarray = field(default_factory=lambda: np.ones(2, dtype=bool))
    cop_xy_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    heading_rad: float = 0.0
    yaw_rate_radps: float = 0.0
    swing_foot: int = -1
    """-1 in double support."""
    swing_pos_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    swing_vel_mps: np.ndarray = field(default_factory=lambda: np.zeros(3))
    swing_acc_mps2: np.ndarray = field(default_factory=lambda: np.zeros(3))
    swing_yaw_rad: float = 0.0
    swing_yaw_rate_radps: float = 0.0
    landing_m: np.ndarray = field(default_factory=lambda: np.zeros(3))
    """Where the swing foot (or, in double support, the next one) is to land."""
    swing_progress: float = 0.0
    """Fraction of this step's swing done (0 in double support)."""
    mode: str = "stand"
    recovery: bool = False
    """The step under way is a recovery step (GaitConfig.recovery_dcm_error_m): a push, say."""
    pushed: bool = False
    """... with the DCM GaitConfig.pushed_dcm_error_m off its plan: walking fast, steps near their limits
    are recovery steps without a push."""
    after_push: bool = False
    """The step under way (double support included) follows a pushed one (GaitConfig.after_push_steps):
    the tracker keeps the CoM lowered."""
    dcm_error_m: float = 0.0
    """How far the DCM is from its nominal plan this tick (walking; 0 otherwise)."""
    push_drift_m: float = 0.0
    """How far the DCM has run beyond what the pendulum explains (GaitConfig.push_detect_m; walking)."""
    push_seen: bool = False
    """A push was told (GaitConfig.push_detect_m) within GaitConfig.push_memory_s."""


def nominal_dcm_offset(cfg: GaitConfig, stance: int, v_h: np.ndarray, omega: float, wz: float = 0.0) -> np.ndarray:
    """DCM offset b (heading frame) at the touchdown of foot `stance`, walking periodically at the
    heading-frame velocity v_h = (vx, vy) (module docstring) and turning at wz (rad/s): the heading
    turns by wz T each step, so the next step's offset is in a frame turned by that much and the
    steps follow the arc (the centre's chord turned by half the step's turn, the feet beside the
    turned centre line); without the turn the DCM drifted out of the curve (measured, issue 23)."""
    T = cfg.step_s
    E = math.exp(omega * T)
    d1, d2 = nominal_step(cfg, 1 - stance, v_h), nominal_step(cfg, stance, v_h)
    turn = wz * T
    if turn == 0.0:
        return (d1 * E + d2) / (E * E - 1.0)
    R, half = _rot2(turn), _rot2(0.5 * turn)
    chord = np.array([v_h[0] * T, v_h[1] * T])
    eye = np.eye(2)
    # a step landing foot f: its straight displacement plus the arc's terms (R(turn/2) - I) chord
    # and (R(turn) - I) o_f, o_f the landing foot's offset from the centre line (half the width)
    d1 = d1 + (half - eye) @ chord + (R - eye) @ np.array([0.0, 0.5 * _SIDE[1 - stance] * cfg.step_width_m])
    d2 = d2 + (half - eye) @ chord + (R - eye) @ np.array([0.0, 0.5 * _SIDE[stance] * cfg.step_width_m])
    # periodic: d1 = E b_s - R b_o, d2 = E b_o - R b_s  ->  (E^2 I - R^2) b_s = E d1 + R d2
    return np.asarray(np.linalg.solve(E * E * eye - R @ R, E * d1 + R @ d2))


def nominal_step(cfg: GaitConfig, foot: int, v_h: np.ndarray) -> np.ndarray:
    """Heading-frame displacement of a step that lands `foot` beside the other: forward vx T;
    sideways the foot on the side of the motion steps out by the width plus 2 |vy| T and the other
    closes to the width, so the mean is vy T."""
    T = cfg.step_s
    side = _SIDE[foot]
    out = side * v_h[1] > 0
    width = cfg.step_width_m + (2.0 * abs(v_h[1]) * T if out else 0.0)
    return np.array([v_h[0] * T, side * width])


def step_reach(cfg: GaitConfig, v_h: np.ndarray) -> float:
    """How much of the step limits walking at v_h = (vx, vy) takes at the slow cadence
    (`single_support_s`, `double_support_s`): the forward step's share of its limit plus the sideways
    step out's share of the room beyond the step width."""
    T = cfg.step_s
    forward = abs(float(v_h[0])) * T / (cfg.max_forward_m if v_h[0] >= 0 else cfg.max_backward_m)
    return forward + 2.0 * abs(float(v_h[1])) * T / (cfg.max_width_m - cfg.step_width_m)


def cadence_share(cfg: GaitConfig, v_h: np.ndarray) -> float:
    """0 walking slowly, rising to 1 as the step reach (step_reach) grows from
    `cadence_reach_from` to `cadence_reach_full` (GaitConfig.fast_single_support_s)."""
    span = cfg.cadence_reach_full - cfg.cadence_reach_from
    return min(max((step_reach(cfg, v_h) - cfg.cadence_reach_from) / span, 0.0), 1.0)


def support_times_for(cfg: GaitConfig, v_h: np.ndarray) -> tuple[float, float]:
    """(single, double) support of steps walking at v_h: `single_support_s` and `double_support_s`
    slowly, shrinking towards the fast ones as the step reach grows."""
    a = cadence_share(cfg, v_h)
    return (cfg.single_support_s + a * (cfg.fast_single_support_s - cfg.single_support_s),
            cfg.double_support_s + a * (cfg.fast_double_support_s - cfg.double_support_s))


def max_width_for(cfg: GaitConfig, v_h: np.ndarray) -> float:
    """The widest stance (sideways step limit) of steps walking at v_h: `max_width_m` slowly, growing
    towards `fast_max_width_m` with the cadence of the sideways part alone (cadence_share)."""
    sideways = np.array([0.0, float(v_h[1])])
    return cfg.max_width_m + cadence_share(cfg, sideways) * (cfg.fast_max_width_m - cfg.max_width_m)


def step_duration_for(cfg: GaitConfig, v_h: np.ndarray) -> float:
    """Touchdown to touchdown of steps walking steadily at v_h (flat ground): a stride is two."""
    return sum(support_times_for(cfg, v_h))


def step_load(cfg: GaitConfig, command_h: np.ndarray, margin: float, cadence_of: np.ndarray | None = None) -> float:
    """The share of the step limits (`margin` of them) walking command_h = (vx, vy, wz) takes: the
    forward step over its limit, the sideways step out over the room beyond the step width (up to
    the width limit, max_width_for), the turn (per slow step) over the relative yaw limit, summed.
    The steps have the cadence and width limit of `cadence_of` (vx, vy), None: of the command itself."""
    pace = command_h[:2] if cadence_of is None else cadence_of[:2]
    T = step_duration_for(cfg, pace)
    vx, vy, wz = (float(x) for x in command_h[:3])
    forward = cfg.max_forward_m if vx >= 0 else cfg.max_backward_m
    return (abs(vx) * T / (margin * forward)
            + 2.0 * abs(vy) * T / (margin * (max_width_for(cfg, pace) - cfg.step_width_m))
            + abs(wz) * cfg.step_s / (margin * cfg.max_relative_yaw_rad))


def _axis_limits(cfg: GaitConfig, margin: float, cadence_of: np.ndarray | None) -> tuple[float, float, float, float]:
    """The largest forward, backward, sideways speed and turn rate each alone within step_load <= 1
    (with the cadence each speed has, when cadence_of is None: the load grows with the speed, bisected)."""
    if cadence_of is not None:
        return _axis_limits_at_cadence(cfg, margin, cadence_of)
    out = [_axis_limit_bisected(cfg, margin, cadence_of, axis, sign) for axis, sign in _AXES]
    return out[0], out[1], out[2], out[3]


_AXES = ((0, 1.0), (0, -1.0), (1, 1.0), (2, 1.0))
"""(axis, sign) of _axis_limits' four limits: forward, backward, sideways, turn."""


def _largest_within(load: Callable[[float], float]) -> float:
    """The largest speed in [0, 10) whose load is <= 1 (60 bisection steps; load grows with speed)."""
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if load(mid) <= 1.0 else (lo, mid)
    return lo


def _axis_limit_bisected(cfg: GaitConfig, margin: float, cadence_of: np.ndarray | None, axis: int,
                         sign: float) -> float:
    def load(speed: float) -> float:
        v = np.zeros(3)
        v[axis] = sign * speed
        return step_load(cfg, v, margin, cadence_of)

    return _largest_within(load)


def _axis_limits_at_cadence(cfg: GaitConfig, margin: float,
                            cadence_of: np.ndarray) -> tuple[float, float, float, float]:
    """_axis_limits at a given cadence, bit for bit: the same bisection, with step_load's terms for a
    one-axis command written out (the step duration and width limit are the cadence's, computed once;
    the other axes' terms are zeros, which leave the sum unchanged). step_load itself costs ~5 us a
    call and the bisection makes 240: ~1.5 ms inside a controller tick at every touchdown while the
    walked command changes, measured."""
    pace = cadence_of[:2]
    T = step_duration_for(cfg, pace)
    room = max_width_for(cfg, pace) - cfg.step_width_m
    denominators = (margin * cfg.max_forward_m, margin * cfg.max_backward_m, margin * room,
                    margin * cfg.max_relative_yaw_rad)
    if not (math.isfinite(T) and all(math.isfinite(d) and d != 0.0 for d in denominators)):
        # a zero term could be 0/0 here: the generic path gives what step_load gives
        return tuple(_axis_limit_bisected(cfg, margin, cadence_of, axis, sign)  # type: ignore[return-value]
                     for axis, sign in _AXES)
    loads = (lambda s: s * T / denominators[0], lambda s: s * T / denominators[1],
             lambda s: 2.0 * s * T / denominators[2], lambda s: s * cfg.step_s / denominators[3])
    out = [_largest_within(load) for load in loads]
    return out[0], out[1], out[2], out[3]


def _rot2(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s], [s, c]])


def yaw_rotation(yaw: float) -> np.ndarray:
    """3 x 3 rotation about world z."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _smooth(a: float, duration_s: float) -> tuple[float, float, float]:
    """Quintic smoothstep of a (clipped to [0, 1]) with its time derivatives for a ramp lasting duration_s."""
    if a <= 0.0:
        return 0.0, 0.0, 0.0
    if a >= 1.0:
        return 1.0, 0.0, 0.0
    s = a * a * a * (10 - 15 * a + 6 * a * a)
    ds = 30 * a * a * (1 - a) ** 2 / duration_s
    dds = 60 * a * (1 - a) * (1 - 2 * a) / duration_s**2
    return s, ds, dds


def _min_jerk(x0: float, v0: float, a0: float, x1: float, T: float, t: float) -> tuple[float, float, float]:
    """Position, velocity, acceleration at t of the quintic from (x0, v0, a0) to (x1, 0, 0) over T."""
    if T <= 1e-6:
        return x1, 0.0, 0.0
    t = min(max(t, 0.0), T)
    T2, T3 = T * T, T * T * T
    h = x1 - x0
    c3 = (20 * h - 12 * v0 * T - 3 * a0 * T2) / (2 * T3)
    c4 = (-30 * h + 16 * v0 * T + 3 * a0 * T2) / (2 * T3 * T)
    c5 = (12 * h - 6 * v0 * T - a0 * T2) / (2 * T3 * T2)
    x = x0 + v0 * t + 0.5 * a0 * t * t + c3 * t**3 + c4 * t**4 + c5 * t**5
    v = v0 + a0 * t + 3 * c3 * t * t + 4 * c4 * t**3 + 5 * c5 * t**4
    a = a0 + 6 * c3 * t + 12 * c4 * t * t + 20 * c5 * t**3
    return x, v, a


class VelocityGait:
    """The gait's state machine: stand -> start (weight shift) -> walk (steps) -> stop -> stand."""

    def __init__(self, config: GaitConfig | None = None, terrain: Terrain | None = None):
        """terrain: heights of what the feet stand on (terrain.py); None: flat ground."""
        self.config = config or GaitConfig()
        self.terrain = terrain or Terrain()
        self._terrain_cfg: GaitConfig | None = None
        self._limits = _axis_limits(self.config, self.config.speed_margin, None)
        """feasible()'s per-axis limits (forward, backward, sideways, turning) at the cadence of each speed."""
        self._limits_memo: dict[tuple, tuple[float, float, float, float]] = {}
        self.targets = GaitTargets()
        self.reset()

    def reset(self) -> None:
        self.mode = "stand"
        self._t0 = 0.0
        """Start of the current phase: the weight shift, the stop, or the stance foot's touchdown."""
        self._last_t: float | None = None
        self.stance = LEFT
        self.heading = 0.0
        self._swing_from = np.zeros(3)
        self._swing_yaw_from = 0.0
        self._landing = np.zeros(3)
        self._landing_yaw = 0.0
        self._path_top = 0.0
        self._snap_shift = np.zeros(2)
        """How far (xy) the terrain moved this step's landing from where the DCM would put it."""
        self._last_phase: tuple[float, bool] = (math.nan, False)
        """(_t0, swinging) of the last walking tick: within the same phase, that tick's landing is still in
        targets.landing_m (terrain_landing_speed_mps limits the move from it) and its CoP in _p_last
        (terrain_cop_two_tick_mean)."""
        self._snap_shift_at = math.nan
        """The _t0 of the step _snap_shift belongs to (nan: none)."""
        self._snap_dir = 0
        """That step's landing moved forward (1) or back (-1) onto a level, once it was (0: not yet)."""
        self._foothold = np.zeros(2)
        self._foothold_ground = 0.0
        """The foothold (xy, height of its level) _on_terrain chose last."""
        self._level_change = False
        """That foothold is on another level than the stance foot or the swing foot."""
        self.active = self.config
        """The configuration of the step under way: near a step, the one with longer single support."""
        """The highest point under the swing's path, relative to the stance sole (terrain)."""
        self._ref = np.zeros((4, 3))
        """Swing reference (x, y, yaw) rows: position, velocity, acceleration; row 3 unused."""
        self._dcm_from = np.zeros(2)
        self.step_T = self.config.step_s
        """This step's duration (touchdown to touchdown): shortened when balance needs a step sooner."""
        self._lifted_at = math.nan
        """The _t0 of the step whose swing has started (nan: none)."""
        self._late_at = math.nan
        self._late_from = math.nan
        """The _t0 of the step whose touchdown waits for contact (GaitConfig.touchdown_height_m; nan: none)
        and when the wait began."""
        self._recovery_at = math.nan
        """The _t0 of the step that is a recovery step (GaitConfig.recovery_dcm_error_m; nan: none)."""
        self._pushed_at = math.nan
        """... and a pushed one (GaitConfig.pushed_dcm_error_m)."""
        self._after_push_at = math.nan
        """The _t0 of a step after a pushed one (GaitConfig.after_push_steps; nan: none) ..."""
        self._after_push_left = 0
        self._dcm_error_at = math.nan
        self._p_last = np.zeros(2)
        """The CoP this gait computed last tick."""
        self._drift = np.zeros(2)
        """The DCM's runs beyond the pendulum's prediction, summed with push_detect_tau_s's memory (m)."""
        self._drift_xi: np.ndarray | None = None
        """The DCM at the last walking tick (None: the last tick did not walk)."""
        self._drift_over_since = math.nan
        self._push_seen_t = -math.inf
        """When a push was last told (GaitConfig.push_detect_m)."""
        """The _t0 of the step GaitTargets.dcm_error_m was last measured in (nan: none)."""
        """... and how many such steps are left, that one included."""
        self.command_h = np.zeros(3)
        """The command being walked: the operator's, rate limited (GaitConfig.max_accel)."""
        self.speed_correction_h = np.zeros(2)
        """Added to the walked command's (vx, vy) when planning steps (GaitConfig.speed_feedback_gain)."""
        self._td_pos = np.full((2, 2), np.nan)
        self._td_t = np.full(2, np.nan)
        self.steps = 0
        self.touchdowns: list[tuple[float, int, np.ndarray]] = []
        """(time, foot, planned landing point) of every step taken, for tests and figures."""

    # -- the schedule (from time and command only) ---------------------------------------------------
    def schedule(self, t_s: float, command_h: np.ndarray, soles_m: np.ndarray, sole_yaws: np.ndarray,
                 dcm_xy: np.ndarray) -> np.ndarray:
        """Advance the state machine to t_s; returns the contact schedule (left, right) for this tick.
        command_h: (vx, vy, wz) heading frame; soles_m (2, 3), sole_yaws (2,): measured feet; dcm_xy:
        the measured DCM (only read when a phase starts)."""
        cfg = self.config
        dt = 0.0 if self._last_t is None else t_s - self._last_t
        self._last_t = t_s
        moving = self._walks(command_h)
        walked = self.command_h
        if self.mode == "walk":
            step = np.asarray(cfg.max_accel) * dt
            walked += np.minimum(np.maximum(self._terrain_limited(self.feasible(command_h), soles_m) - walked, -step), step)
        else:
            walked[:] = 0.0
        command_h = walked
        if self.mode == "stand":
            self.heading = float(math.atan2(np.sin(sole_yaws).sum(), np.cos(sole_yaws).sum()))
            if moving:
                self.mode, self._t0 = "start", t_s
                self.speed_correction_h[:] = 0.0
                self._td_t[:] = np.nan
                self._dcm_from = np.array(dcm_xy, dtype=float)
                # the first swing foot leads on the side of the motion (turning counts as its side)
                lead = LEFT if (command_h[1] > 0.02 or (abs(command_h[1]) <= 0.02 and command_h[2] > 0)) else RIGHT
                self.stance = 1 - lead
        else:
            self.heading += float(command_h[2]) * dt
        if self.mode == "start" and t_s - self._t0 >= cfg.start_s:
            # straight into single support: the stance foot's touchdown is dated a double support ago
            self.mode, self._t0 = "walk", t_s - cfg.double_support_s
            self.active = self._timing_for(soles_m)
            self.step_T = self.active.step_s
            self._lift(soles_m, sole_yaws)
        if self.mode == "walk":
            if t_s - self._t0 >= self.step_T and self._awaits_contact(t_s, soles_m, sole_yaws):
                pass  # the swing foot is still above the terrain: the step goes on (update() keeps lowering it)
            elif t_s - self._t0 >= self.step_T:
                # touchdown of the swing foot: it becomes the stance foot
                if self._late_at == self._t0:
                    self.step_T = t_s - self._t0  # it came late: the next step starts now
                self.touchdowns.append((t_s, 1 - self.stance, self._landing.copy()))
                self._correct_speed(t_s, 1 - self.stance, soles_m[1 - self.stance, :2])
                self.steps += 1
                pushed, after = self._pushed_at == self._t0, self._after_push_at == self._t0
                pushed = pushed and self._push_recent(t_s)
                self.stance = 1 - self.stance
                self._t0 += self.step_T
                if pushed or after:
                    self._after_push_left = cfg.after_push_steps if pushed else self._after_push_left - 1
                    if self._after_push_left > 0:
                        self._after_push_at = self._t0
                self.active = self._timing_for(soles_m)
                self.step_T = self.active.step_s
                if not moving and self._side_by_side(soles_m, sole_yaws):
                    self.mode, self._t0 = "stop", t_s
                    self._dcm_from = np.array(dcm_xy, dtype=float)
            elif (not self._swinging and self._dcm_error_at == self._t0 and not self._in_swing(t_s)
                  and t_s - self._t0 >= cfg.fast_double_support_s
                  and self.targets.dcm_error_m > cfg.early_lift_dcm_error_m and self._push_recent(t_s)):
                # pushed in the double support: the swing foot lifts now
                t_in = t_s - self._t0
                self.step_T -= self.active.double_support_s - t_in
                self.active = dataclasses.replace(self.active, double_support_s=t_in,
                                                  fast_double_support_s=min(t_in, self.active.fast_double_support_s))
                self._lift(soles_m, sole_yaws)
            elif self._in_swing(t_s) and not self._swinging:
                if self._dcm_short_of_stance(command_h, soles_m, dcm_xy) and (
                        self.active.double_support_s < cfg.double_support_s + cfg.terrain_max_wait_s):
                    # the double support lasts until the DCM is over the stance foot (below)
                    self.active = dataclasses.replace(self.active,
                                                      double_support_s=self.active.double_support_s + dt)
                    self.step_T += dt
                else:
                    self._lift(soles_m, sole_yaws)
        if self.mode == "stop" and t_s - self._t0 >= cfg.stop_s:
            self.mode = "stand"
        contacts = self.targets.contacts
        contacts[:] = True
        if self.mode == "walk" and self._in_swing(t_s):
            contacts[1 - self.stance] = False
        self.targets.mode = self.mode
        return contacts

    def feasible(self, command_h: np.ndarray, margin: float | None = None,
                 cadence_of: np.ndarray | None = None) -> np.ndarray:
        """`command_h` within what the step limits allow (`margin` of them, GaitConfig.speed_margin by
        default), each axis and together (the three axes' fractions of their limits, step_load, add up
        to at most one); the steps have the cadence and width limit of `cadence_of`'s (vx, vy), or (None)
        of the command itself: walking fast, quicker steps reach further per second."""
        cfg = self.config
        m = cfg.speed_margin if margin is None else margin
        limits = self._limits if margin is None and cadence_of is None else self._limits_for(m, cadence_of)
        out = np.array(command_h, dtype=float)
        out[0] = min(max(out[0], -limits[1]), limits[0])
        out[1] = min(max(out[1], -limits[2]), limits[2])
        out[2] = min(max(out[2], -limits[3]), limits[3])
        # combined axes share the step's reach: walking fast while turning hard stretched the swing
        # leg straight to its landing point (a knee overspeed at touchdown, measured)
        load = step_load(cfg, out, m, cadence_of)
        if load > 1.0:
            scaled = out / load
            if step_load(cfg, scaled, m, cadence_of) > 1.0 + 1e-9:
                # slower, the steps come slower and reach less far per second: scale down further
                lo, hi = 0.0, 1.0 / load
                for _ in range(40):
                    mid = 0.5 * (lo + hi)
                    lo, hi = (mid, hi) if step_load(cfg, mid * out, m, cadence_of) <= 1.0 else (lo, mid)
                scaled = lo * out
            out = scaled
        return out

    def _limits_for(self, margin: float, cadence_of: np.ndarray | None) -> tuple[float, float, float, float]:
        """_axis_limits, remembered per (margin, cadence_of): bisecting them costs ~2 ms of CPU, and the
        speed correction asks at every touchdown, inside the controller's tick, mostly for the same command."""
        key = (margin, None if cadence_of is None else tuple(float(v) for v in cadence_of))
        limits = self._limits_memo.get(key)
        if limits is None:
            if len(self._limits_memo) >= 64:
                self._limits_memo.clear()
            limits = self._limits_memo[key] = _axis_limits(self.config, margin, cadence_of)
        return limits

    def _turn(self, command_h: np.ndarray) -> float:
        """The turn rate the nominal DCM offsets plan for (0 with GaitConfig.plan_turn off)."""
        return float(command_h[2]) if self.config.plan_turn else 0.0

    def _timing_for(self, soles_m: np.ndarray) -> GaitConfig:
        """The step timing for the coming step: longer single support near a step; shorter walking
        fast (GaitConfig.fast_single_support_s)."""
        cfg = self.config
        if not self.terrain.flat:
            direction = self.heading + math.atan2(self.command_h[1], self.command_h[0])
            if self.terrain.level_change_ahead(soles_m[:, :2].mean(axis=0), direction, cfg.terrain_look_ahead_m):
                if self._terrain_cfg is None:
                    self._terrain_cfg = dataclasses.replace(cfg, single_support_s=cfg.terrain_single_support_s,
                                                            cop_limit_y_m=cfg.terrain_cop_limit_y_m)
                return self._terrain_cfg
        single, double = support_times_for(cfg, self.command_h[:2])
        if single == cfg.single_support_s and double == cfg.double_support_s:
            return cfg
        return dataclasses.replace(cfg, single_support_s=single, double_support_s=double,
                                   max_width_m=max_width_for(cfg, self.command_h[:2]))

    def _terrain_limited(self, command_h: np.ndarray, soles_m: np.ndarray) -> np.ndarray:
        """`command_h` slowed to GaitConfig.terrain_speed_mps while a step is ahead of the feet."""
        cfg = self.config
        speed = float(np.hypot(command_h[0], command_h[1]))
        if self.terrain.flat or speed <= cfg.terrain_speed_mps:
            return command_h
        direction = self.heading + math.atan2(command_h[1], command_h[0])
        mid = (soles_m[0, :2] + soles_m[1, :2]) / 2
        if not self.terrain.level_change_ahead(mid, direction, cfg.terrain_look_ahead_m):
            return command_h
        out = command_h.copy()
        out[:2] *= cfg.terrain_speed_mps / speed
        return out

    def _walks(self, command_h: np.ndarray) -> bool:
        """The command walked still moves the robot (any axis above GaitConfig.moving_speed): the speed
        correction applies. Stopping (the command walked down to zero), it does not: from a combined walk
        (random timeline s8 of `g1 bench locomotion`) the correction wound up to -0.28 m/s against the
        capture steps' own motion while the command was zero, kept the robot stepping and threw it
        (an ankle over-speed trip 1.4 s after the stop)."""
        return any(abs(c) > self.config.moving_speed for c in command_h.tolist())

    def _correct_speed(self, t_s: float, foot: int, landed_xy: np.ndarray) -> None:
        """A foot has landed: compare the stride since its last touchdown with the command walked."""
        cfg = self.config
        if not self._walks(self.command_h):
            self.speed_correction_h[:] = 0.0  # stopping: nothing to correct (a kept one walked the robot on)
        elif np.isfinite(self._td_t[foot]):
            dt = t_s - self._td_t[foot]
            v_w = (landed_xy - self._td_pos[foot]) / dt
            v_h = _rot2(self.heading - 0.5 * dt * float(self.command_h[2])).T @ v_w
            c = self.speed_correction_h
            c += cfg.speed_feedback_gain * (self.command_h[:2] - v_h)
            np.clip(c, -cfg.max_speed_correction_mps, cfg.max_speed_correction_mps, out=c)
            # no wind-up: the corrected command stays within the step limits
            # at the cadence the walked command has (the correction does not quicken the steps)
            corrected = np.array([*(self.command_h[:2] + c), 0.0])
            share = cadence_share(cfg, self.command_h[:2])
            margin = cfg.speed_margin + share * (cfg.corrected_speed_margin - cfg.speed_margin)
            c[:] = self.feasible(corrected, margin, self.command_h)[:2] - self.command_h[:2]
        self._td_pos[foot] = landed_xy
        self._td_t[foot] = t_s

    def _landing_for(self, t_r: float, p: np.ndarray, u: np.ndarray, f: int, dcm_xy: np.ndarray, omega: float,
                     command_h: np.ndarray) -> tuple[float, np.ndarray, float]:
        """(heading at touchdown, unclipped landing relative to the stance sole in that heading
        frame, how far (m) it lies beyond the step limits) for a touchdown t_r from now."""
        cfg = self.active
        heading_td = self.heading + float(command_h[2]) * t_r
        xi_td = p + (dcm_xy - p) * math.exp(omega * t_r)
        b_next = _rot2(heading_td) @ nominal_dcm_offset(cfg, f, command_h[:2], omega, self._turn(command_h))
        rel = _rot2(heading_td).T @ (xi_td - b_next - u[:2])
        side_out = _SIDE[f] * rel[1]
        excess = max(rel[0] - cfg.max_forward_m, -cfg.max_backward_m - rel[0], side_out - cfg.max_width_m, 0.0)
        return heading_td, rel, float(excess)

    def _on_terrain(self, u: np.ndarray, swing_sole: np.ndarray, heading_td: float) -> None:
        """The landing point snapped onto one tread (terrain.py), its height from the terrain relative
        to the stance sole's (odometry's height drifts; the map's steps do not), and the highest point
        under the swing's path."""
        terrain = self.terrain
        ground_s = terrain.height(u[:2])  # where it stands (with the margin, a toe near a riser reads the tread above)
        want = self._landing[:2]
        forward = np.array([math.cos(heading_td), math.sin(heading_td)])
        if self._snap_shift_at == self._t0 and self._snap_dir != 0:
            # the step keeps the side of the edge and the level it chose, else the foothold it chose
            # (re-choosing as the DCM moved, the landing jumped from before a riser onto its tread late
            # in the swing; snapped within max_shift_m alone, it once straddled the riser, measured)
            reach = max(self.active.max_forward_m - float((want - u[:2]) @ forward), 0.0) if self._snap_dir > 0 else None
            xy, ground_l = terrain.snap(want, self._landing_yaw, heading_td, forward_only=self._snap_dir > 0,
                                        backward_only=self._snap_dir < 0, max_shift_m=reach)
            if (abs(ground_l - self._foothold_ground) > terrain.config.level_tolerance_m
                    or not terrain.is_level(xy, self._landing_yaw)):
                xy, ground_l = self._kept_foothold(want, heading_td)
        else:
            xy, ground_l = terrain.snap(want, self._landing_yaw, heading_td)
            advance = float((xy - u[:2]) @ forward)
            if advance < self.config.min_advance_m and advance < float((want - u[:2]) @ forward):
                # moved back to little ahead of the stance foot: onto the tread instead, as far as the
                # step limit allows (a riser's tread lies a sole and a riser gap ahead; within
                # max_shift_m alone the feet shuffled at the riser while the DCM ran ahead, measured)
                reach = max(self.active.max_forward_m - float((want - u[:2]) @ forward), 0.0)
                ahead, ground_a = terrain.snap(want, self._landing_yaw, heading_td, forward_only=True,
                                               max_shift_m=reach)
                if terrain.is_level(ahead, self._landing_yaw):
                    xy, ground_l = ahead, ground_a
        tol = terrain.config.level_tolerance_m
        ground_f = terrain.height(swing_sole[:2])
        ground_o = terrain.height((self._swing_from if self._swinging else swing_sole)[:2])  # where it lifted from
        if abs(ground_o - ground_s) > tol and abs(ground_l - ground_s) > tol:
            # a foot below (or above) the stance foot's level comes onto that level, beside it: never
            # past it onto the next tread (the trailing foot swung from the first tread onto the top,
            # 0.3 m up and 0.8 m on, measured)
            xy, ground_l = self._on_level(want, heading_td, ground_s, u[:2])
        elif self._swinging and self._snap_shift_at == self._t0 and abs(ground_l - self._foothold_ground) > tol:
            # a swing keeps the level its foothold had (its timing and apex were chosen for it at
            # lift-off): a same-level step whose landing moved onto the next tread mid-swing came down
            # on that tread's edge (measured)
            xy, ground_l = self._on_level(want, heading_td, self._foothold_ground, u[:2])
        shift = float((xy - want) @ forward)
        if self._snap_shift_at != self._t0 or self._snap_dir == 0:
            self._snap_dir = 1 if shift > 1e-9 else -1 if shift < -1e-9 else 0
        self._snap_shift = xy - want
        self._snap_shift_at = self._t0
        self._foothold, self._foothold_ground = xy.copy(), ground_l
        self._level_change = max(abs(ground_l - ground_s), abs(ground_l - ground_f)) > self.config.step_change_m
        self._landing[:2] = xy
        self._landing[2] = u[2] + ground_l - ground_s
        start = self._swing_from[:2] if self._swinging else self._landing[:2]
        self._path_top = terrain.max_height_along(start, xy, self._landing_yaw) - ground_s

    def _kept_foothold(self, want: np.ndarray, heading_td: float) -> tuple[np.ndarray, float]:
        """The foothold a step keeps when its landing no longer snaps onto the side and level it chose:
        the last foothold, moved sideways (across the heading) to where the DCM now asks the foot to
        land, if a sole there, moved along the heading within terrain_side_follow_reach_m, still lies on
        the foothold's level; else the last foothold as it was."""
        reach = self.config.terrain_side_follow_reach_m
        if reach <= 0.0:
            return self._foothold.copy(), self._foothold_ground
        across = np.array([-math.sin(heading_td), math.cos(heading_td)])
        moved = self._foothold + float((want - self._foothold) @ across) * across
        xy, ground = self.terrain.snap(moved, self._landing_yaw, heading_td, max_shift_m=reach,
                                       level_m=self._foothold_ground)
        if self.terrain.fits(xy, self._landing_yaw, self._foothold_ground):
            return xy, ground
        return self._foothold.copy(), self._foothold_ground

    def _on_level(self, want: np.ndarray, heading_td: float, level_m: float,
                  stance_xy: np.ndarray) -> tuple[np.ndarray, float]:
        """The foothold nearest `want` along the heading (within terrain_level_reach_m) whose whole sole
        lies on the level `level_m` (Terrain.snap). When there is none: this step's own foothold, once it
        has one; before that, beside the stance sole on want's side (step_width_m, else min_width_m
        across the heading) on that level, else the nearest foothold on any level (Terrain.snap), else
        `want` as it is. Never the last step's foothold, which is where the stance foot stands: a trailing
        foot whose landing lay off the stairs' side was sent onto the stance sole (`g1 bench stairs` seed
        100 at 8.59 s, measured)."""
        terrain = self.terrain
        yaw = self._landing_yaw
        xy, ground = terrain.snap(want, yaw, heading_td, max_shift_m=self.config.terrain_level_reach_m, level_m=level_m)
        if terrain.fits(xy, yaw, level_m):
            return xy, ground
        if self._snap_shift_at == self._t0:
            return self._foothold.copy(), self._foothold_ground
        across = np.array([-math.sin(heading_td), math.cos(heading_td)])
        side = 1.0 if float((want - stance_xy) @ across) >= 0.0 else -1.0
        for width in (self.config.step_width_m, self.config.min_width_m):
            beside = stance_xy + side * width * across
            if terrain.fits(beside, yaw, level_m):
                return beside, terrain.sole_height(beside, yaw)
        return terrain.snap(want, yaw, heading_td)  # want itself when no place in reach fits

    def _dcm_short_of_stance(self, command_h: np.ndarray, soles_m: np.ndarray, dcm_xy: np.ndarray) -> bool:
        """Near a step, whether the DCM lies behind the stance sole's centre along the motion (by more than
        GaitConfig.terrain_lift_dcm_margin_m): lifting
        the other foot then, the DCM runs back off the sole's heel (after a long step up onto a tread
        the trailing foot lifted with the DCM 0.13 m short of the front sole and the robot fell back,
        measured)."""
        if self.terrain.flat or float(np.hypot(command_h[0], command_h[1])) <= self.config.moving_speed:
            return False
        direction = self.heading + math.atan2(command_h[1], command_h[0])
        along = np.array([math.cos(direction), math.sin(direction)])
        return float((dcm_xy - soles_m[self.stance, :2]) @ along) < -self.config.terrain_lift_dcm_margin_m

    def _awaits_contact(self, t_s: float, soles_m: np.ndarray, sole_yaws: np.ndarray) -> bool:
        """At or after the clock's touchdown of a step onto another level: whether the swing foot is still
        above the terrain (GaitConfig.touchdown_height_m), within touchdown_max_wait_s of the clock's touchdown."""
        cfg = self.config
        if self.terrain.flat or not math.isfinite(cfg.touchdown_height_m) or not self._swinging:
            return False
        f = 1 - self.stance
        lifted_from = self.terrain.under_sole(self._swing_from[:2], self._swing_yaw_from)
        if abs(self._foothold_ground - lifted_from) <= cfg.step_change_m:
            return False  # a step on one level lands on the clock, as on flat ground
        if self._late_at != self._t0:
            self._late_at, self._late_from = self._t0, t_s
        if t_s - self._late_from >= cfg.touchdown_max_wait_s:
            return False
        above = float(soles_m[f, 2]) - self.terrain.under_sole(soles_m[f, :2], float(sole_yaws[f]))
        return above > cfg.touchdown_height_m

    def _push_recent(self, t_s: float) -> bool:
        """Whether a push was told within GaitConfig.push_memory_s (always, with push_detect_m 0)."""
        cfg = self.config
        return cfg.push_detect_m == 0 or t_s - self._push_seen_t <= cfg.push_memory_s

    def _track_drift(self, t_s: float, dt_s: float, dcm_xy: np.ndarray, omega: float) -> None:
        """GaitConfig.push_detect_m: the DCM against the pendulum's prediction from the last walking tick
        under the CoP asked then (self.targets.cop_xy_m, before this tick's)."""
        cfg, out = self.config, self.targets
        walking = self.mode == "walk"
        if walking and self._drift_xi is not None and dt_s > 0:
            p = out.cop_xy_m
            predicted = p + (self._drift_xi - p) * math.exp(omega * dt_s)
            self._drift *= math.exp(-dt_s / cfg.push_detect_tau_s)
            departure = dcm_xy - predicted
            size, most = float(np.hypot(*departure)), cfg.push_detect_max_rate_mps * dt_s
            self._drift += departure if size <= most else departure * (most / size)
        else:
            self._drift *= math.exp(-dt_s / cfg.push_detect_tau_s) if dt_s > 0 else 1.0
        self._drift_xi = np.array(dcm_xy, dtype=float) if walking else None
        out.push_drift_m = float(np.hypot(*self._drift))
        if out.push_drift_m > cfg.push_detect_m:
            if math.isnan(self._drift_over_since):
                self._drift_over_since = t_s
            if t_s - self._drift_over_since >= cfg.push_detect_hold_s - 1e-9:
                self._push_seen_t = t_s
        else:
            self._drift_over_since = math.nan
        out.push_seen = self._push_recent(t_s)

    def _in_swing(self, t_s: float) -> bool:
        return t_s - self._t0 >= self.active.double_support_s

    @property
    def _swinging(self) -> bool:
        return bool(self._lifted_at == self._t0)

    def _lift(self, soles_m: np.ndarray, sole_yaws: np.ndarray) -> None:
        swing = 1 - self.stance
        self._swing_from = soles_m[swing].copy()
        self._swing_yaw_from = float(sole_yaws[swing])
        self._ref[:] = 0.0
        self._ref[0] = (soles_m[swing, 0], soles_m[swing, 1], sole_yaws[swing])
        self._lifted_at = self._t0
        self._lengthen_for_level(soles_m)

    def _lengthen_for_level(self, soles_m: np.ndarray) -> None:
        """A step onto another level swings long enough to cross at terrain_swing_speed_mps on
        average (the trailing foot's 0.6 m at 0.42 s threw the body, measured); never shorter than it
        was made already."""
        if not (self._snap_shift_at == self._t0 and self._level_change):
            return
        cfg = self.config
        across = float(np.hypot(*(self._landing[:2] - soles_m[1 - self.stance, :2])))
        window = 1.0 - cfg.terrain_hold - 0.6 * cfg.swing_fall
        single = min(max(self.active.single_support_s, across / (cfg.terrain_swing_speed_mps * window)),
                     cfg.terrain_max_single_support_s)
        if single > self.active.single_support_s:
            self.step_T += single - self.active.single_support_s
            self.active = dataclasses.replace(self.active, single_support_s=single)

    def _side_by_side(self, soles_m: np.ndarray, sole_yaws: np.ndarray) -> bool:
        cfg = self.config
        s = self.stance
        rel = _rot2(-float(sole_yaws[s])) @ (soles_m[1 - s, :2] - soles_m[s, :2])
        return (abs(rel[0]) < cfg.stop_tolerance_m and abs(abs(rel[1]) - cfg.step_width_m) < cfg.stop_tolerance_m
                and abs(float(wrap_angle(sole_yaws[0] - sole_yaws[1]))) < 0.15)

    # -- the targets (from the measured DCM) ------------------------------------------------------------
    def update(self, t_s: float, dt_s: float, soles_m: np.ndarray, sole_yaws: np.ndarray,
               dcm_xy: np.ndarray, omega: float) -> GaitTargets:
        """The CoP, heading and swing-foot targets for this tick (call schedule() first; the
        command walked is schedule()'s, rate limited)."""
        cfg, out = self.active, self.targets
        self._track_drift(t_s, dt_s, dcm_xy, omega)
        command_h = self.command_h.copy()
        if self._walks(command_h):
            command_h[:2] += self.speed_correction_h
        out.heading_rad = self.heading
        out.yaw_rate_radps = 0.0 if self.mode == "stand" else float(command_h[2])
        out.swing_foot = -1
        out.swing_progress = 0.0
        out.recovery = out.pushed = out.after_push = False
        out.dcm_error_m = 0.0
        mid = (soles_m[0, :2] + soles_m[1, :2]) / 2
        centre = mid + _rot2(self.heading) @ np.array([cfg.com_offset_x_m, 0.0])
        if self.mode in ("stand", "start", "stop"):
            if self.mode == "stand":
                goal, a = centre, 1.0
                dur = 1.0
            elif self.mode == "start":
                s = self.stance
                b = nominal_dcm_offset(cfg, s, command_h[:2], omega, self._turn(command_h))
                goal = soles_m[s, :2] + _rot2(self.heading) @ b * math.exp(omega * cfg.double_support_s)
                dur = cfg.start_s
                a = (t_s - self._t0) / dur
            else:
                goal, dur = centre, cfg.stop_s
                a = (t_s - self._t0) / dur
            # DCM reference moving smoothly from where it was to the goal; CoP tracks it
            a = min(max(a, 0.0), 1.0)
            sm = a * a * a * (10 - 15 * a + 6 * a * a)
            dsm = 30 * a * a * (1 - a) ** 2 / dur if a < 1.0 else 0.0
            xi_ref = self._dcm_from + sm * (goal - self._dcm_from) if self.mode != "stand" else goal
            xi_ref_dot = dsm * (goal - self._dcm_from) if self.mode != "stand" else np.zeros(2)
            out.cop_xy_m[:] = xi_ref - xi_ref_dot / omega + (1.0 + cfg.cop_gain) * (dcm_xy - xi_ref)
            if self.mode == "start":
                out.landing_m[:] = soles_m[1 - self.stance]
            return out
        # walking
        same_phase = self._last_phase == (self._t0, self._swinging)
        self._last_phase = (self._t0, self._swinging)
        s, f = self.stance, 1 - self.stance
        Tds = cfg.double_support_s
        t_in = t_s - self._t0
        t_r = max(self.step_T - t_in, 0.0)
        u = soles_m[s]
        b_now = _rot2(self.heading - float(command_h[2]) * t_in) @ nominal_dcm_offset(cfg, s, command_h[:2], omega,
                                                                                      self._turn(command_h))
        xi_nom = u[:2] + b_now * math.exp(omega * t_in)
        if self._snap_shift_at == self._t0:
            # the landing the terrain moved (onto a tread) moves the DCM's plan with it: the DCM at
            # touchdown is to lie that much further, so its plan now is that much e^{-w t_r} further
            xi_nom = xi_nom + self._snap_shift * math.exp(-omega * t_r)
        out.dcm_error_m = float(np.hypot(*(dcm_xy - xi_nom)))
        self._dcm_error_at = self._t0
        if self._swinging and t_in >= Tds and out.dcm_error_m > cfg.recovery_dcm_error_m:
            self._recovery_at = self._t0
            if out.dcm_error_m > cfg.pushed_dcm_error_m:
                self._pushed_at = self._t0
        if t_in < Tds or not self._swinging:
            # double support: the CoP anywhere between the feet, to take out the DCM's error
            # before the other foot lifts (its offset then grows by e^{w T_ss} until touchdown)
            p = u[:2] + (1.0 + cfg.double_support_cop_gain) * (dcm_xy - xi_nom)
            box = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * (cfg.cop_limit_x_m, cfg.cop_limit_y_m)
            corners = np.vstack([soles_m[i, :2] + box @ _rot2(float(sole_yaws[i])).T for i in range(2)])
            p = cp.project_into_polygon(p, cp.convex_hull(corners))
        else:
            delta = (1.0 + cfg.cop_gain) * (dcm_xy - xi_nom)
            rs = _rot2(float(sole_yaws[s]))
            d_local = rs.T @ delta
            d_local[0] = min(max(d_local[0], -cfg.cop_limit_x_m), cfg.cop_limit_x_m)
            d_local[1] = min(max(d_local[1], -cfg.cop_limit_y_m), cfg.cop_limit_y_m)
            p = u[:2] + rs @ d_local
        if self.config.terrain_cop_two_tick_mean and not self.terrain.flat and same_phase:
            # the CoP sent is the mean of this tick's and the last one's, within one contact phase
            # (GaitConfig.terrain_cop_two_tick_mean); the landing below is predicted from this tick's own
            out.cop_xy_m[:] = 0.5 * (p + self._p_last)
        else:
            out.cop_xy_m[:] = p
        self._p_last[:] = p
        # where the swing foot lands: the DCM predicted at touchdown less the next stance's offset
        tau = (t_in - Tds) / cfg.single_support_s
        if tau < cfg.freeze_landing_after or not self._swinging:
            heading_td, rel, excess = self._landing_for(t_r, p, u, f, dcm_xy, omega, command_h)
            # a step onto another level keeps its timing: sooner, its swing had no time to go up,
            # across and down (it crossed 0.43 m in 0.05 s and caught the edge, measured)
            level_change = self._snap_shift_at == self._t0 and self._level_change
            if excess > cfg.timing_adjust_excess_m and self._swinging and not level_change:
                # step timing: the step cannot reach far enough in time; land sooner, when the
                # DCM has not yet run as far (the earliest that leaves the swing its minimum)
                t_sw = t_in - Tds
                for frac in (0.8, 0.6, 0.45, 0.3):
                    t_try = max(t_r * frac, cfg.min_swing_s - t_sw, cfg.min_remaining_s)
                    if t_try >= t_r - 1e-3:
                        break
                    heading_td, rel, excess = self._landing_for(t_try, p, u, f, dcm_xy, omega, command_h)
                    self.step_T = t_in + t_try
                    if excess <= cfg.timing_adjust_excess_m:
                        break
            if excess > cfg.timing_adjust_excess_m and self._swinging:
                self._recovery_at = self._t0  # latched: the rest of the step is a recovery step
            side = _SIDE[f]
            widest = cfg.max_width_m
            if self._pushed_at == self._t0 and self._swinging:
                widest = max(widest, cfg.recovery_max_width_m)
            rel[0] = min(max(rel[0], -cfg.max_backward_m), cfg.max_forward_m)
            rel[1] = side * min(max(side * rel[1], cfg.min_width_m), widest)
            self._landing[:2] = u[:2] + _rot2(heading_td) @ rel
            self._landing[2] = u[2]
            yaw_s = float(sole_yaws[s])
            dyaw = float(wrap_angle(heading_td - yaw_s))
            lim = cfg.max_relative_yaw_rad
            self._landing_yaw = yaw_s + min(max(dyaw, -lim), lim)
            if not self.terrain.flat:
                self._on_terrain(u, soles_m[f], heading_td)
                if not self._swinging and self.config.terrain_plan_long_steps:
                    self._lengthen_for_level(soles_m)
                speed = self.config.terrain_landing_speed_mps
                if speed > 0 and self._swinging and same_phase:
                    # the landing moves at most so fast from the last tick's (GaitConfig.terrain_landing_speed_mps)
                    move = self._landing[:2] - out.landing_m[:2]
                    dist = float(np.hypot(*move))
                    if dist > speed * dt_s:
                        self._landing[:2] = out.landing_m[:2] + move * (speed * dt_s / dist)
        out.landing_m[:] = self._landing
        out.after_push = bool(self._after_push_at == self._t0)
        if not self._swinging:
            return out
        out.recovery = bool(self._recovery_at == self._t0)
        out.pushed = bool(self._pushed_at == self._t0)
        # the swing foot: horizontal and yaw by re-planned minimum jerk once the foot is off the
        # ground, height up early, across, down late (a foot moving forward low trips on its toe)
        out.swing_foot = f
        Tss = cfg.single_support_s
        Tsw = self.step_T - Tds  # this step's swing (shorter when its timing was adjusted)
        t_sw = t_in - Tds
        ref = self._ref
        z0, z1 = self._swing_from[2], self._landing[2]
        stepping = not self.terrain.flat and (self._path_top > max(z0, z1) - u[2] + cfg.step_change_m
                                              or abs(z1 - z0) > cfg.step_change_m)
        hold = cfg.terrain_hold if stepping else cfg.swing_hold_s
        out.swing_progress = min(max(t_sw / max(Tsw, 1e-6), 0.0), 1.0)
        if t_sw >= hold * Tss:
            goals = (self._landing[0], self._landing[1],
                     self._swing_yaw_from + float(wrap_angle(self._landing_yaw - self._swing_yaw_from)))
            arrive = cfg.swing_arrive_early_s + (min(cfg.swing_fall * Tss, 0.5 * Tsw) * 0.6 if stepping else 0.0)
            h = max(Tsw - arrive - t_sw, 0.0)
            for k in range(3):
                x, v, acc = _min_jerk(ref[0, k], ref[1, k], ref[2, k], goals[k], h + dt_s, dt_s)
                ref[0, k], ref[1, k], ref[2, k] = x, v, acc
        apex = max(z0, z1) + cfg.swing_height_m
        if stepping:
            apex = max(apex, u[2] + self._path_top + cfg.terrain_clearance_m)
        rise = cfg.terrain_rise if stepping else cfg.swing_rise
        up = _smooth(t_sw / (rise * Tss), rise * Tss)
        fall = min(cfg.swing_fall * Tss, 0.5 * Tsw)
        down = _smooth((t_sw - (Tsw - fall)) / fall, fall)
        out.swing_pos_m[:] = (ref[0, 0], ref[0, 1], z0 + up[0] * (apex - z0) + down[0] * (z1 - apex))
        out.swing_vel_mps[:] = (ref[1, 0], ref[1, 1], up[1] * (apex - z0) + down[1] * (z1 - apex))
        out.swing_acc_mps2[:] = (ref[2, 0], ref[2, 1], up[2] * (apex - z0) + down[2] * (z1 - apex))
        out.swing_yaw_rad, out.swing_yaw_rate_radps = float(ref[0, 2]), float(ref[1, 2])
        if t_in > self.step_T and self._late_at == self._t0:
            # past the clock's touchdown, the foot not yet down (schedule()): on down below the landing
            out.swing_pos_m[2] -= self.config.touchdown_descent_mps * (t_in - self.step_T)
            out.swing_vel_mps[2] = -self.config.touchdown_descent_mps
            out.swing_acc_mps2[2] = 0.0
        return out


__all__ = ["GaitConfig", "GaitTargets", "VelocityGait", "cadence_share", "max_width_for", "nominal_dcm_offset", "nominal_step",
           "step_duration_for", "step_load", "step_reach", "support_times_for", "yaw_rotation"]
