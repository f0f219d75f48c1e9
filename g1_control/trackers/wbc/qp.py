"""The inverse-dynamics QP: joint accelerations, contact wrenches and torques for one tick.

Decision variables x = (ddq [nv], wrench_left [6], wrench_right [6]). The torques are the third
set of unknowns, but the actuated rows of the equation of motion fix them as an affine function of
the other two, tau = M_a ddq + h_a - J_a^T f, so they are substituted rather than carried as
variables: the QP stays at nv + 12 = 47 unknowns (a 29-variable, 29-equality larger problem
would give the same optimum at roughly twice the solve time). Constraints:

  floating-base dynamics   M_u ddq + h_u = J_u^T f                    (6 equalities)
  stance foot              J_i ddq + J_dot_i v = -k_v v_i              (6 equalities per foot)
  swing foot               f_i = 0                                     (same 6 rows, swapped)
  torque limits            -tau_max <= M_a ddq + h_a - J_a^T f <= tau_max   (29 inequalities)
  joint velocity limits    |dq + ddq dt| <= fraction * dq_max, one tick ahead (29 inequalities;
                           the safety layer damps the robot at dq_max: a fast recovery step
                           drove a knee there, measured)
  joint position limits    on the same rows: one tick ahead a joint moves towards its range's
                           edge (less a margin) no faster than it can still stop at a braking
                           deceleration, dq + ddq dt <= sqrt(2 a (q_max - margin - q)) (and the
                           mirror at q_min). Without them, once a knee reached its stop (`g1 bench
                           stairs` seed 2, trailing step up, 7.16 s) the QP went on asking it for
                           -2000 rad/s^2 into the stop at its -139 N m torque limit and planned the
                           rest of the body on accelerations MuJoCo's stop did not allow (hip
                           pitch: +700 planned, +30 measured; measured)
  per stance foot          friction pyramid, CoP in the sole, yaw torque, normal-force bounds
                           (contacts.py; 11 inequalities per foot, relaxed for a swing foot)

The problem keeps one shape whatever the contact state, so proxsuite's dense solver is
warm-started from the previous tick's primal/dual solution every time. The matrices persist between
ticks and only the entries that change are written (the python around the solver cost more than
the solver itself: ~0.17 ms of building against ~0.13 ms of proxsuite per tick, measured).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from g1_control.errors import WbcConfigError, WbcSolveError
from g1_control.robot import g1
from g1_control.robot.dynamics import WbcModel
from g1_control.trackers.wbc.contacts import (
    ROWS_PER_FOOT,
    FootGeometry,
    normal_force_bounds,
    wrench_constraint_rows,
)
from g1_control.trackers.wbc.tasks import AccelerationTask

_FREE = 1e20  # proxsuite treats bounds at or beyond this as absent


@dataclass(frozen=True)
class QpConfig:
    foot: FootGeometry = field(default_factory=FootGeometry)
    contact_damping_per_s: float = 20.0
    """A stance foot's acceleration is asked to cancel its residual velocity at this rate."""
    accel_regularisation: float = 1e-4
    force_regularisation: float = 1e-5
    moment_regularisation: float = 1e-2
    """Moments are regularised harder than forces: it keeps each foot's CoP near its centre."""
    effort_limit_nm: tuple[float, ...] = tuple(g1.EFFORT_LIMIT_NM)
    velocity_limit_fraction: float = 0.75
    """Joint speeds one tick ahead stay within this fraction of g1.VELOCITY_LIMIT_RADPS."""
    position_limits: bool = True
    """Bound the joints' positions (below) when solve() is given them; off, only their speeds."""
    position_limit_joints: tuple[int, ...] | None = tuple(j for j in range(29) if j not in (4, 5, 10, 11))
    """The joints (indices into g1.JOINT_NAMES) whose positions are bounded; None: every joint. The
    default leaves the ankles out: with the swing ankle's dorsiflexion bounded (it runs into its stop
    keeping a lifted foot flat) the QP lifted the whole body with the stance leg instead (stance ankle
    at its torque limit), and `g1 bench stairs` seeds 0-4 fell 15/15 with the step's top 0/5 (main
    13/15, 5/5); every joint but the ankles: 14/15, 5/5 (measured)."""
    position_limit_margin_rad: float = 0.05
    """Joint position bounds (with joint positions given to solve()): each joint stays this far inside
    g1.Q_MIN_RAD..Q_MAX_RAD."""
    position_limit_brake_radps2: float = 30.0
    """... moving towards that bound no faster than it can stop at this deceleration ..."""
    position_limit_zone_rad: float = 0.15
    """... once within this distance of it (farther away only the speed bound holds: a flat walk whose
    joints keep away from their stops solves the same problem, bit for bit, as without the bounds)."""
    position_limit_max_brake_radps2: float = 200.0
    """A joint faster than that towards its bound is asked to slow by at most this much (rad/s^2) in a
    tick, so the bound stays within what the torques can do."""
    eps_abs: float = 1e-5
    max_iter: int = 200
    contact_change_mu_in: float | None = None
    """Off (None): the solver's proximal parameters carry over from the last solve, and a solve that does
    not succeed goes to the tracker's relaxed retry. Set (1e-2 measured best): on a tick whose contact rows
    change (a foot lands or lifts, a load ramps in or out) the inequality proximal parameter is reset to it
    (the equality one to proxsuite's default, 1e-3) before the warm-started solve, and a warm start that
    still fails is solved again from a fresh solver before the relaxed retry.
    Why it exists: carried over, the parameters shrink to 1e-6..1e-8 on steady ticks, and on the changed
    problem proxsuite stops after 2-32 iterations with PRIMAL_INFEASIBLE though the same problem solves
    cold in 9-14: 20 of the 1500 ticks of `g1 bench wbc`'s walk, every touchdown and some ramp ticks, each
    then re-solved relaxed (full load, no contact damping). Set, that walk has no false exit, and its
    problems solve with half the p99 time (`g1 bench wbc` replays them both ways).
    Why it is off (stop 42): solving touchdowns as asked changes the walk. Lockstep it was as good or
    better (pushes 10/20 against 9/20, random timelines s10-49 0/40 falls, stairs a wash), but the 23-DoF
    G1 walked over DDS (tests/deploy/test_deploy_wbc_walk.py, 1.6 m forward) drifted 0.36-0.56 m sideways
    in 3 of 14 runs here, against at most 0.19 m in 9 runs without it. Stop 43 traced it (49 more runs): the
    drift is the gait's, a sideways stepping that saturates at max_width_m / min_width_m and never meets the
    stop's side-by-side rule; it comes off too (lockstep randomised robots: 2/30 off, 4/30 on) but more often
    over DDS with the reset (7/44 against 0/27, p ~ 0.03). The gait's stop rule is the thing to fix first."""


@dataclass
class IdSolution:
    ddq: np.ndarray
    wrenches: np.ndarray
    """(2, 6) per foot (left, right): force N and moment N m at the sole, sole axes."""
    tau_nm: np.ndarray
    iterations: int
    solve_time_s: float
    status: str


class InverseDynamicsQP:
    def __init__(self, nv: int, config: QpConfig | None = None):
        from g1_control.ik.solver import import_proxsuite

        self._proxsuite = import_proxsuite()
        self.config = config or QpConfig()
        self.nv = nv
        self.n = nv + 12
        self.n_eq = 6 + 12
        self.n_in = 2 * (nv - 6) + 2 * ROWS_PER_FOOT
        self.effort_limit = np.asarray(self.config.effort_limit_nm, dtype=float)
        self.velocity_limit = self.config.velocity_limit_fraction * np.asarray(g1.VELOCITY_LIMIT_RADPS, dtype=float)
        margin = self.config.position_limit_margin_rad
        self.position_min = np.asarray(g1.Q_MIN_RAD, dtype=float) + margin
        self.position_max = np.asarray(g1.Q_MAX_RAD, dtype=float) - margin
        if not np.all(self.position_min < self.position_max):
            raise WbcConfigError(f"QpConfig.position_limit_margin_rad {margin} leaves a joint no range")
        mu = self.config.contact_change_mu_in
        if mu is not None and not (np.isfinite(mu) and 0 < mu <= 1):
            raise WbcConfigError(f"QpConfig.contact_change_mu_in must be None or a number in (0, 1]; got {mu}")
        for name in ("position_limit_brake_radps2", "position_limit_max_brake_radps2", "position_limit_zone_rad"):
            value = getattr(self.config, name)
            if not (np.isfinite(value) and value > 0):
                raise WbcConfigError(f"QpConfig.{name} must be a finite number > 0; got {value}")
        self._pos_lo = np.zeros(nv - 6)
        self._pos_hi = np.zeros(nv - 6)
        joints = self.config.position_limit_joints
        self._pos_free = np.zeros(nv - 6, dtype=bool)
        if joints is not None:
            bad = [j for j in joints if not 0 <= j < nv - 6]
            if bad:
                raise WbcConfigError(f"QpConfig.position_limit_joints {bad} are not joint indices 0..{nv - 7}")
            self._pos_free[:] = True
            self._pos_free[list(joints)] = False
        self._vel_rows = slice(nv - 6 + 2 * ROWS_PER_FOOT, 2 * (nv - 6) + 2 * ROWS_PER_FOOT)
        self._vel_diag = (np.arange(self._vel_rows.start, self._vel_rows.stop), np.arange(6, nv))
        self._foot_rows = wrench_constraint_rows(self.config.foot)
        self._diag = np.diag_indices(self.n)
        self._diag_q = np.diag_indices(nv)
        self._eye6 = np.eye(6)
        self.H = np.zeros((self.n, self.n))
        self.g = np.zeros(self.n)
        self.A = np.zeros((self.n_eq, self.n))
        self.b = np.zeros(self.n_eq)
        self.C = np.zeros((self.n_in, self.n))
        self.l = np.zeros(self.n_in)
        self.u = np.zeros(self.n_in)
        self._Hq = self.H[:nv, :nv]
        self._gq = self.g[:nv]
        self._foot_slices = tuple((slice(6 + 6 * i, 12 + 6 * i), slice(nv + 6 * i, nv + 6 * i + 6),
                                   slice(nv - 6 + ROWS_PER_FOOT * i, nv - 6 + ROWS_PER_FOOT * (i + 1))) for i in range(2))
        """Per foot (left, right): its equality rows in A, its wrench's columns, its rows in C."""
        for _, cols, rows in self._foot_slices:
            self.C[rows, cols] = self._foot_rows[0]
        self._vel_dt: float | None = None
        """The time step on the joint-speed rows' diagonal in C (None: the rows are zero)."""
        self._eq_stance: list[bool | None] = [None, None]
        """What each foot's equality rows in A now hold: a stance (True) or swing (False) foot's."""
        c = self.config
        self._reg = np.concatenate([np.full(nv, c.accel_regularisation),
                                    np.tile([c.force_regularisation] * 3 + [c.moment_regularisation] * 3, 2)])
        self._qp: Any = None
        """The proxsuite dense QP (untyped), warm-started between solves; None before the first."""
        self._feet_rows = slice(nv - 6, nv - 6 + 2 * ROWS_PER_FOOT)
        self._feet_bounds = np.full((2, 2 * ROWS_PER_FOOT), np.nan)
        """The feet's rows of l and u at the last solve (a change resets the proximal parameters)."""
        self.solves = 0
        self.contact_resets = 0
        """Solves whose proximal parameters were reset for changed contact rows (contact_change_mu_in)."""
        self.cold_retries = 0
        """Warm-started solves that did not solve and were solved again from a fresh solver (contact_change_mu_in set)."""
        self.warm_exits = 0
        """Warm-started solves that did not solve (retried cold, or else raised to the tracker's relaxed retry)."""

    def reset(self) -> None:
        """Forget the warm start (the next solve starts cold)."""
        self._qp = None

    def _new_solver(self):
        dense = self._proxsuite.proxqp.dense
        qp = dense.QP(self.n, self.n_eq, self.n_in)
        qp.settings.eps_abs = self.config.eps_abs
        qp.settings.eps_rel = 0.0
        qp.settings.max_iter = self.config.max_iter
        qp.settings.verbose = False
        qp.init(self.H, self.g, self.A, self.b, self.C, self.l, self.u)
        return qp

    def solve(self, model: WbcModel, tasks: list[AccelerationTask], stance: np.ndarray,
              load_fraction: np.ndarray, contact_damping_per_s: float | None = None,
              joint_velocity_radps: np.ndarray | None = None, dt_s: float = 0.0,
              joint_position_rad: np.ndarray | None = None) -> IdSolution:
        """Solve for the state last passed to model.update(). stance: (2,) bool; load_fraction:
        (2,) 0..1, each stance foot's share of the full normal-force allowance (contact ramps);
        contact_damping_per_s overrides the configured value for this solve; joint_velocity_radps
        and dt_s (> 0): bound the joint speeds one tick of dt_s ahead (else unbounded); with
        joint_position_rad as well, bound them also by the joints' position margins (QpConfig)."""
        self._set_cost(tasks)
        self._set_constraints(model, stance, load_fraction, contact_damping_per_s, joint_velocity_radps, dt_s,
                              joint_position_rad)
        return self._solve(model, stance)

    def resolve(self, model: WbcModel, stance: np.ndarray, load_fraction: np.ndarray,
                contact_damping_per_s: float | None = None, joint_velocity_radps: np.ndarray | None = None,
                dt_s: float = 0.0, joint_position_rad: np.ndarray | None = None) -> IdSolution:
        """solve() again with the last solve()'s tasks (its cost is kept, not rebuilt) and these
        contact, speed and position settings: a retry after a failed solve, at the same state."""
        self._set_constraints(model, stance, load_fraction, contact_damping_per_s, joint_velocity_radps, dt_s,
                              joint_position_rad)
        return self._solve(model, stance)

    def _set_cost(self, tasks: list[AccelerationTask]) -> None:
        H, g, nv = self.H, self.g, self.nv
        H[:] = 0.0
        g[:] = 0.0
        Hq, gq = self._Hq, self._gq
        for task in tasks:
            if task.joint_space:
                # jac is the identity on the last len(target) columns: J^T W J is W on that diagonal
                # block, exactly what the product's sums (of one term and zeros) give, at a tenth of the cost
                k = nv - len(task.target)
                Hq[self._diag_q[0][k:], self._diag_q[1][k:]] += task.weight
                gq[k:] -= task.weight * task.target
                continue
            wj = task.jac * task.weight[:, None]
            Hq += task.jac.T @ wj
            gq -= wj.T @ task.target
        H[self._diag] += self._reg

    def _set_constraints(self, model: WbcModel, stance: np.ndarray, load_fraction: np.ndarray,
                         contact_damping_per_s: float | None, joint_velocity_radps: np.ndarray | None,
                         dt_s: float, joint_position_rad: np.ndarray | None = None) -> None:
        """Writes only what changes from tick to tick: the feet's wrench rows in C are constant
        (__init__), a swing foot's equality rows are constant while it swings."""
        nv = self.nv
        M, h, Jc = model.mass_matrix, model.bias, model.contact_jac_local
        A, b, C, l, u = self.A, self.b, self.C, self.l, self.u
        # floating-base dynamics
        A[:6, :nv] = M[:6]
        A[:6, nv:] = -Jc[:, :6].T
        b[:6] = -h[:6]
        # torque limits
        C[:nv - 6, :nv] = M[6:]
        C[:nv - 6, nv:] = -Jc[:, 6:].T
        l[:nv - 6] = -self.effort_limit - h[6:]
        u[:nv - 6] = self.effort_limit - h[6:]
        vr = self._vel_rows
        if joint_velocity_radps is not None and dt_s > 0:
            if self._vel_dt != dt_s:
                C[self._vel_diag] = dt_s
                self._vel_dt = dt_s
            # a joint already past its bound need only not speed up further (ddq = 0 stays feasible)
            np.minimum(-self.velocity_limit - joint_velocity_radps, 0.0, out=l[vr])
            np.maximum(self.velocity_limit - joint_velocity_radps, 0.0, out=u[vr])
            if joint_position_rad is not None and self.config.position_limits:
                self._position_bounds(joint_position_rad, joint_velocity_radps, dt_s)
                # only where tighter than the speed bound: elsewhere the rows are exactly as without
                np.maximum(l[vr], self._pos_lo, out=l[vr])
                np.minimum(u[vr], self._pos_hi, out=u[vr])
        else:
            if self._vel_dt is not None:
                C[vr] = 0.0
                self._vel_dt = None
            l[vr], u[vr] = -_FREE, _FREE
        _, fl, fu = self._foot_rows
        kv = self.config.contact_damping_per_s if contact_damping_per_s is None else contact_damping_per_s
        for i in range(2):
            eq, cols, rows = self._foot_slices[i]
            if stance[i]:
                A[eq, :nv] = Jc[6 * i:6 * i + 6]
                if self._eq_stance[i] is not True:
                    A[eq, nv:] = 0.0
                    self._eq_stance[i] = True
                b[eq] = -model.contact_drift_local[6 * i:6 * i + 6] - kv * model.contact_vel_local[6 * i:6 * i + 6]
                l[rows], u[rows] = fl, fu
                fz_min, fz_max = normal_force_bounds(self.config.foot, load_fraction[i])
                l[rows.stop - 1], u[rows.stop - 1] = fz_min, fz_max
            else:
                if self._eq_stance[i] is not False:
                    A[eq] = 0.0
                    A[eq, cols] = self._eye6
                    self._eq_stance[i] = False
                b[eq] = 0.0
                l[rows], u[rows] = -_FREE, _FREE

    def _position_bounds(self, q: np.ndarray, dq: np.ndarray, dt_s: float) -> None:
        """Fills _pos_lo/_pos_hi: the bounds on dt ddq (the speed change in a tick) that the
        position margins set: the speed one tick ahead towards a bound at most sqrt(2 a d), d the
        distance left to it (zero at or past it); a joint faster than that slows by at most
        position_limit_max_brake_radps2 in the tick (the bound stays within reach of the torques).
        Beyond position_limit_zone_rad from a bound, none (+-_FREE)."""
        c = self.config
        a, cap = c.position_limit_brake_radps2, c.position_limit_max_brake_radps2 * dt_s
        d_max = np.maximum(self.position_max - q, 0.0)
        d_min = np.maximum(q - self.position_min, 0.0)
        np.maximum(np.sqrt(2.0 * a * d_max) - dq, -cap, out=self._pos_hi)
        np.minimum(-np.sqrt(2.0 * a * d_min) - dq, cap, out=self._pos_lo)
        zone = c.position_limit_zone_rad
        self._pos_hi[(d_max > zone) | self._pos_free] = _FREE
        self._pos_lo[(d_min > zone) | self._pos_free] = -_FREE

    def _solve_cold(self) -> None:
        self._qp = self._new_solver()
        self._qp.solve()
        # Only now: proxsuite 0.8 segfaults when asked to warm-start before any result exists.
        self._qp.settings.initial_guess = self._proxsuite.proxqp.InitialGuess.WARM_START_WITH_PREVIOUS_RESULT

    def _solved(self) -> bool:
        return "SOLVED" in self._qp.results.info.status.name and bool(np.isfinite(self._qp.results.x).all())

    def solve_problem(self) -> tuple[bool, int, float]:
        """Solve the problem now in H, g, A, b, C, l, u as a tick does (warm-started; with
        contact_change_mu_in, the proximal parameters reset when the feet's rows changed and a failed warm
        start retried cold): (solved, iterations, seconds). `g1 bench wbc` replays a walk's problems
        through it."""
        H, g, A, b, C, l, u = self.H, self.g, self.A, self.b, self.C, self.l, self.u
        t0 = time.perf_counter()
        mu = self.config.contact_change_mu_in
        changed = False
        if mu is not None:  # off (the default), nothing below is looked at in the hot loop
            feet = self._feet_rows
            changed = not (np.array_equal(self._feet_bounds[0], l[feet]) and np.array_equal(self._feet_bounds[1], u[feet]))
            self._feet_bounds[0], self._feet_bounds[1] = l[feet], u[feet]
        iterations = 0
        if self._qp is None:
            self._solve_cold()
            solved = self._solved()
        else:
            if changed:
                self._qp.update(H, g, A, b, C, l, u, mu_in=mu, mu_eq=self._qp.settings.default_mu_eq)
                self.contact_resets += 1
            else:
                self._qp.update(H, g, A, b, C, l, u)
            self._qp.solve()
            solved = self._solved()
            if not solved:
                self.warm_exits += 1
                if mu is not None:
                    # a warm start's exit (PRIMAL_INFEASIBLE on a feasible problem, seen from shrunk proximal
                    # parameters) is not the problem's: the same problem once more from a fresh solver
                    iterations = int(self._qp.results.info.iter)
                    self.cold_retries += 1
                    self._solve_cold()
                    solved = self._solved()
        elapsed = time.perf_counter() - t0
        self.solves += 1
        iterations += int(self._qp.results.info.iter)
        return solved, iterations, elapsed

    def _solve(self, model: WbcModel, stance: np.ndarray) -> IdSolution:
        nv = self.nv
        M, h, Jc = model.mass_matrix, model.bias, model.contact_jac_local
        solved, iterations, elapsed = self.solve_problem()
        status = self._qp.results.info.status.name
        x = self._qp.results.x
        if not solved:
            self._qp = None  # do not warm-start from a failed solve
            raise WbcSolveError(f"inverse-dynamics QP not solved: status {status} after {iterations} iterations "
                                f"(stance {stance.tolist()})")
        ddq = x[:nv].copy()
        wrenches = x[nv:].reshape(2, 6).copy()
        tau = M[6:] @ ddq + h[6:] - Jc[:, 6:].T @ x[nv:]
        return IdSolution(ddq, wrenches, tau, iterations, elapsed, status)
