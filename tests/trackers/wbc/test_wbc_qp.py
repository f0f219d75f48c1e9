"""The inverse-dynamics QP at a standing state: its solution obeys the physics it encodes."""

import numpy as np
import pytest

from g1_control.errors import WbcConfigError, WbcSolveError
from g1_control.robot import description, g1
from g1_control.robot.dynamics import WbcModel
from g1_control.trackers.wbc.contacts import FootGeometry, cop_of
from g1_control.trackers.wbc.qp import InverseDynamicsQP, QpConfig
from g1_control.trackers.wbc.tasks import AccelerationTask, TaskGains, posture_task


@pytest.fixture(scope="module")
def model():
    m = WbcModel()
    q = description.pinocchio_q(np.array([0.0, 0.0, 0.756]), np.array([1.0, 0, 0, 0]), g1.DEFAULT_Q_RAD)
    m.update(q, np.zeros(m.nv))
    return m


def posture(model, q_ref=None):
    return posture_task(model.nv, g1.DEFAULT_Q_RAD, np.zeros(29),
                        g1.DEFAULT_Q_RAD if q_ref is None else q_ref, np.zeros(29), TaskGains(100, 20, 1))


def com_task(model, a_des):
    return AccelerationTask("com", model.com_jac, np.asarray(a_des) - model.com_drift, np.full(3, 100.0))


def check_dynamics(model, sol):
    """M ddq + h = S^T tau + J_c^T f, all 35 rows."""
    lhs = model.mass_matrix @ sol.ddq + model.bias
    rhs = np.concatenate([np.zeros(6), sol.tau_nm]) + model.contact_jac_local.T @ sol.wrenches.ravel()
    np.testing.assert_allclose(lhs, rhs, atol=1e-3)


def test_double_support_carries_the_weight_within_every_limit(model):
    qp = InverseDynamicsQP(model.nv)
    sol = qp.solve(model, [posture(model)], np.array([True, True]), np.ones(2))
    check_dynamics(model, sol)
    assert sol.wrenches[:, 2].sum() == pytest.approx(model.mass_kg * 9.81, rel=1e-3)
    assert np.all(np.abs(sol.tau_nm) <= g1.EFFORT_LIMIT_NM + 1e-6)
    # stance feet do not accelerate
    acc = model.contact_jac_local @ sol.ddq + model.contact_drift_local
    np.testing.assert_allclose(acc, 0.0, atol=1e-4)


def test_single_support_puts_no_force_on_the_swing_foot_and_keeps_the_cop_in_the_sole(model):
    qp = InverseDynamicsQP(model.nv)
    # ask the CoM to move toward the right foot as single support would
    sol = qp.solve(model, [posture(model), com_task(model, [0.0, -1.0, 0.0])], np.array([False, True]), np.ones(2))
    check_dynamics(model, sol)
    np.testing.assert_allclose(sol.wrenches[0], 0.0, atol=1e-6)
    foot = FootGeometry()
    px, py = cop_of(sol.wrenches[1])
    assert 0.8 * foot.x_min_m - 1e-4 <= px <= 0.8 * foot.x_max_m + 1e-4
    assert 0.8 * foot.y_min_m - 1e-4 <= py <= 0.8 * foot.y_max_m + 1e-4
    fx, fy, fz = sol.wrenches[1, :3]
    assert abs(fx) <= foot.friction * fz + 1e-6 and abs(fy) <= foot.friction * fz + 1e-6


def test_torque_limits_bind(model):
    # a knee limit below what standing needs: the QP must respect it, not the task
    limits = g1.EFFORT_LIMIT_NM.copy()
    limits[[3, 9]] = 5.0
    qp = InverseDynamicsQP(model.nv, QpConfig(effort_limit_nm=tuple(limits)))
    sol = qp.solve(model, [posture(model)], np.array([True, True]), np.ones(2))
    assert np.all(np.abs(sol.tau_nm[[3, 9]]) <= 5.0 + 1e-4)
    check_dynamics(model, sol)


def test_warm_started_solve_gives_the_cold_solution(model):
    shifted = g1.DEFAULT_Q_RAD + 0.05
    warm = InverseDynamicsQP(model.nv)
    warm.solve(model, [posture(model)], np.array([True, True]), np.ones(2))
    warm_sol = warm.solve(model, [posture(model, shifted), com_task(model, [0.2, 0, 0])], np.array([True, True]), np.ones(2))
    cold_sol = InverseDynamicsQP(model.nv).solve(model, [posture(model, shifted), com_task(model, [0.2, 0, 0])],
                                                 np.array([True, True]), np.ones(2))
    np.testing.assert_allclose(warm_sol.tau_nm, cold_sol.tau_nm, atol=1e-2)


def test_load_ramp_limits_a_new_contact(model):
    qp = InverseDynamicsQP(model.nv)
    sol = qp.solve(model, [posture(model)], np.array([True, True]), np.array([1.0, 0.1]))
    assert sol.wrenches[1, 2] <= 0.1 * FootGeometry().fz_max_n + 1e-3
    assert sol.wrenches[0, 2] > 0.5 * model.mass_kg * 9.81


def test_infeasible_problem_raises_a_named_error(model):
    # no torque and a foot just touching down (its normal force capped near zero): nothing can
    # hold the robot while the stance foot must not accelerate
    qp = InverseDynamicsQP(model.nv, QpConfig(effort_limit_nm=(0.0,) * 29, max_iter=100))
    with pytest.raises(WbcSolveError, match="QP not solved"):
        qp.solve(model, [posture(model)], np.array([True, False]), np.zeros(2))


def _problem(qp):
    return tuple(m.copy() for m in (qp.H, qp.g, qp.A, qp.b, qp.C, qp.l, qp.u))


def test_a_joint_space_task_enters_the_hessian_as_its_jacobian_product_would(model):
    task = posture(model, g1.DEFAULT_Q_RAD + 0.1)
    task.weight = np.linspace(0.5, 3.0, 29)
    general = AccelerationTask("posture", task.jac, task.target, task.weight)  # multiplied out
    qp_diag, qp_full = InverseDynamicsQP(model.nv), InverseDynamicsQP(model.nv)
    stance = np.array([True, True])
    qp_diag.solve(model, [com_task(model, [0.1, 0, 0]), task], stance, np.ones(2))
    qp_full.solve(model, [com_task(model, [0.1, 0, 0]), general], stance, np.ones(2))
    for a, b in zip(_problem(qp_diag), _problem(qp_full)):
        np.testing.assert_array_equal(a, b)


def test_constraints_written_incrementally_equal_a_fresh_problem_whatever_the_contact_history(model):
    """The QP rewrites only the rows that change between ticks: after any sequence of contact states
    and speed bounds its matrices are those a new QP writes for the last one."""
    kept = InverseDynamicsQP(model.nv)
    dq = np.full(29, 0.5)
    steps = [((True, True), dq, 0.004), ((False, True), dq, 0.004), ((False, True), None, 0.0),
             ((True, False), dq, 0.005), ((True, True), dq, 0.004), ((True, False), None, 0.0)]
    for contacts, speeds, dt in steps:
        args = ([posture(model)], np.array(contacts), np.array([0.5, 1.0]))
        kept.solve(model, *args, joint_velocity_radps=speeds, dt_s=dt)
        fresh = InverseDynamicsQP(model.nv)
        fresh.solve(model, *args, joint_velocity_radps=speeds, dt_s=dt)
        for a, b in zip(_problem(kept), _problem(fresh)):
            np.testing.assert_array_equal(a, b)


def test_resolve_keeps_the_last_cost_and_takes_new_contact_settings(model):
    tasks = [posture(model), com_task(model, [0.0, -0.5, 0.0])]
    stance = np.array([True, True])
    retried = InverseDynamicsQP(model.nv)
    retried.solve(model, tasks, stance, np.array([0.2, 1.0]))
    again = retried.resolve(model, stance, np.ones(2), contact_damping_per_s=0.0)
    direct = InverseDynamicsQP(model.nv)
    once = direct.solve(model, tasks, stance, np.ones(2), contact_damping_per_s=0.0)
    for a, b in zip(_problem(retried), _problem(direct)):
        np.testing.assert_array_equal(a, b)
    check_dynamics(model, again)
    check_dynamics(model, once)


def _knee_driven_straight(model, config):
    """The left knee 0.02 rad inside its position margin, straightening at 2 rad/s, its posture task
    pulling it far past its stop: the QP's knee speed change in one tick (dt ddq)."""
    q = g1.DEFAULT_Q_RAD.copy()
    q[3] = g1.Q_MIN_RAD[3] + QpConfig().position_limit_margin_rad + 0.02
    dq = np.zeros(29)
    dq[3] = -2.0
    q_ref = g1.DEFAULT_Q_RAD.copy()
    q_ref[3] = -1.5
    task = posture_task(model.nv, q, dq, q_ref, np.zeros(29), TaskGains(400, 40, 100))
    dt = 0.004
    sol = InverseDynamicsQP(model.nv, config).solve(model, [task], np.array([False, True]), np.ones(2),
                                                     joint_velocity_radps=dq, dt_s=dt, joint_position_rad=q)
    return q, dq, dt, sol.ddq[6 + 3] * dt


def test_position_limits_brake_a_joint_before_its_stop(model):
    c = QpConfig()
    q, dq, dt, change = _knee_driven_straight(model, c)
    distance = q[3] - (g1.Q_MIN_RAD[3] + c.position_limit_margin_rad)
    speed_allowed = np.sqrt(2 * c.position_limit_brake_radps2 * distance)  # 1.1 rad/s at most towards the stop
    # it cannot slow from 2 to 1.1 rad/s in one tick within the deceleration cap: it slows by the cap
    assert dq[3] + change == pytest.approx(min(-speed_allowed, dq[3] + c.position_limit_max_brake_radps2 * dt), abs=1e-5)
    # without position limits the task drives it on into the stop
    _, _, _, unbounded = _knee_driven_straight(model, QpConfig(position_limits=False))
    assert unbounded < 0.0


def test_position_limits_leave_the_problem_unchanged_away_from_the_stops(model):
    """Where no joint is near its position margin the QP's matrices are bit for bit those without
    positions (a change that acts only near the stops leaves flat walking's runs bit-identical)."""
    dq = np.full(29, 0.5)
    args = ([posture(model)], np.array([True, True]), np.ones(2))
    with_q, without = InverseDynamicsQP(model.nv), InverseDynamicsQP(model.nv)
    with_q.solve(model, *args, joint_velocity_radps=dq, dt_s=0.004, joint_position_rad=g1.DEFAULT_Q_RAD)
    without.solve(model, *args, joint_velocity_radps=dq, dt_s=0.004)
    for a, b in zip(_problem(with_q), _problem(without)):
        np.testing.assert_array_equal(a, b)


def test_position_limit_settings_are_checked(model):
    with pytest.raises(WbcConfigError, match="position_limit_margin_rad"):
        InverseDynamicsQP(model.nv, QpConfig(position_limit_margin_rad=0.3))
    with pytest.raises(WbcConfigError, match="position_limit_brake_radps2"):
        InverseDynamicsQP(model.nv, QpConfig(position_limit_brake_radps2=0.0))
    for bad in (0.0, -1e-3, 2.0, float("nan")):
        with pytest.raises(WbcConfigError, match="contact_change_mu_in"):
            InverseDynamicsQP(model.nv, QpConfig(contact_change_mu_in=bad))


def test_only_the_chosen_joints_are_position_bounded(model):
    # the knee left out: the task drives it on into its stop as without position limits
    c = QpConfig(position_limit_joints=tuple(j for j in range(29) if j != 3))
    _, _, _, change = _knee_driven_straight(model, c)
    assert change < 0.0
    with pytest.raises(WbcConfigError, match="position_limit_joints"):
        InverseDynamicsQP(model.nv, QpConfig(position_limit_joints=(3, 29)))
