"""Footsteps from a run's log: where the feet landed against where the plan put them, per style.

A touchdown is a foot coming down after a swing: its ankle rises more than `LIFT_M` above the height
that foot stands at (its lowest within `STAND_WINDOW_S`), then comes back within `LAND_M` of it. A step is where the landing
foot rests (`SETTLE_S` after its touchdown) relative to where the other foot stood at the touchdown, in
the pelvis's heading frame (x forward, y left): a step's length and width, whatever the robot's or the
plan's drift in the world. The same
rule runs on the measured configuration (ground truth in simulation: `base_pos_m`, `base_quat_wxyz`,
`q_rad`) and on the tracker's reference configuration (the plan after the IK: `ref_root_pos_m`,
`ref_root_quat_wxyz`, `q_ref_rad`); each measured step is paired with the plan's step of the same foot
nearest in time (within `MATCH_S`), and the pairs' differences give the RMS per style.

`g1 launch` reports it for runs in simulation whose tracker had a reference (launch/runner.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from g1_control.robot import g1

LIFT_M = 0.025
"""A foot is swinging once its ankle is this far above the height it stands at."""
LAND_M = 0.008
"""... and has landed once it is back within this of it."""
SETTLE_S = 0.05
"""A landed foot's position is read this long after its touchdown (it may still slide as it lands)."""
MATCH_S = 0.25
"""A measured step and a planned step of the same foot pair up when they land at most this far apart."""
STAND_WINDOW_S = 1.0
"""The height a foot stands at: the lowest its ankle comes within this long either side (flat ground)."""


@dataclass(frozen=True)
class Steps:
    """Touchdowns: time, which foot (0 left, 1 right), the step (landing foot minus the other foot,
    heading frame, m), and the operator's style index at the tick."""

    t_s: np.ndarray
    foot: np.ndarray
    step_h_m: np.ndarray
    style_id: np.ndarray


def ankle_positions(base_pos_m: np.ndarray, base_quat_wxyz: np.ndarray, q_rad: np.ndarray) -> np.ndarray:
    """(n, 2, 3): the left and right ankle-roll joints in the world, by forward kinematics (pinocchio)
    of each row's configuration (rows with a NaN come out NaN)."""
    import pinocchio as pin

    from g1_control.robot.description import pinocchio_model, pinocchio_q

    model = pinocchio_model()
    data = model.createData()
    joints = [model.getJointId(name.replace("_link", "_joint")) for name in g1.FOOT_BODIES]
    out = np.full((len(q_rad), 2, 3), np.nan)
    for k in range(len(q_rad)):
        if not (np.isfinite(base_pos_m[k]).all() and np.isfinite(base_quat_wxyz[k]).all() and np.isfinite(q_rad[k]).all()):
            continue
        quat = base_quat_wxyz[k] / np.linalg.norm(base_quat_wxyz[k])
        pin.forwardKinematics(model, data, pinocchio_q(base_pos_m[k], quat, q_rad[k]))
        for i, j in enumerate(joints):
            out[k, i] = data.oMi[j].translation
    return out


def standing_height(z: np.ndarray, window: int) -> np.ndarray:
    """Per row, the height the foot stands at around it: the lowest of its ankle's heights within
    `window` rows either side (a plan's ground level may wander by centimetres over a run)."""
    filled = np.where(np.isfinite(z), z, np.inf)
    n = len(z)
    out = np.empty(n)
    for k in range(n):
        out[k] = filled[max(0, k - window): k + window + 1].min()
    return out


def touchdowns(z: np.ndarray, window: int, lift_m: float = LIFT_M, land_m: float = LAND_M) -> np.ndarray:
    """Row indices where a foot whose ankle heights are `z` lands: the first row back within land_m
    of its standing height after having been more than lift_m above it."""
    if np.isfinite(z).sum() < 2:
        return np.zeros(0, dtype=int)
    ground = standing_height(z, window)
    out, swinging = [], False
    for k, h in enumerate(z):
        if not np.isfinite(h):
            swinging = False
            continue
        if not swinging and h > ground[k] + lift_m:
            swinging = True
        elif swinging and h < ground[k] + land_m:
            swinging = False
            out.append(k)
    return np.array(out, dtype=int)


def steps(t_s: np.ndarray, ankles: np.ndarray, yaw_rad: np.ndarray, style_id: np.ndarray) -> Steps:
    """Every touchdown of either foot as a step (module docstring)."""
    dt = float(np.median(np.diff(t_s))) if len(t_s) > 1 else 1.0
    window = max(1, round(STAND_WINDOW_S / dt))
    rows = [touchdowns(ankles[:, side, 2], window) for side in (0, 1)]
    k = np.concatenate(rows)
    foot = np.concatenate([np.full(len(r), side) for side, r in enumerate(rows)])
    order = np.argsort(k, kind="stable")
    k, foot = k[order], foot[order]
    rest = np.searchsorted(t_s, t_s[k] + SETTLE_S - 1e-9).clip(max=len(t_s) - 1)
    rel = ankles[rest, foot, :2] - ankles[k, 1 - foot, :2]
    c, s = np.cos(yaw_rad[k]), np.sin(yaw_rad[k])
    step_h = np.stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1]], axis=1)
    return Steps(t_s[k], foot, step_h, style_id[k])


def _yaw(quat_wxyz: np.ndarray) -> np.ndarray:
    w, x, y, z = quat_wxyz.T
    return np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def measured_and_planned_steps(log: dict[str, np.ndarray]) -> tuple[Steps, Steps] | None:
    """(measured, planned) steps of a run's log; None when it has no ground truth or no reference."""
    fields = ("base_pos_m", "base_quat_wxyz", "q_rad", "q_ref_rad", "ref_root_pos_m", "ref_root_quat_wxyz")
    if any(f not in log for f in fields) or not len(log["t_s"]):
        return None
    truth = np.isfinite(log["base_pos_m"][:, 0])
    ref = np.isfinite(log["ref_root_pos_m"][:, 0]) & np.isfinite(log["q_ref_rad"][:, 0])
    if truth.sum() < 2 or ref.sum() < 2:
        return None
    t, style = log["t_s"], log["style_id"]
    measured = ankle_positions(log["base_pos_m"], log["base_quat_wxyz"], log["q_rad"])
    planned = ankle_positions(log["ref_root_pos_m"], log["ref_root_quat_wxyz"], log["q_ref_rad"])
    return (steps(t, measured, _yaw(log["base_quat_wxyz"]), style),
            steps(t, planned, _yaw(log["ref_root_quat_wxyz"]), style))


def pair(measured: Steps, planned: Steps, match_s: float = MATCH_S) -> tuple[np.ndarray, np.ndarray]:
    """(i, j): measured step i paired with planned step j, the same foot, landing nearest in time and at
    most match_s apart (each planned step pairs at most once: the nearest measured step wins it)."""
    best: dict[int, tuple[float, int]] = {}
    for i in range(len(measured.t_s)):
        same = np.nonzero(planned.foot == measured.foot[i])[0]
        if not len(same):
            continue
        gap = np.abs(planned.t_s[same] - measured.t_s[i])
        j = int(same[np.argmin(gap)])
        d = float(gap.min())
        if d <= match_s and (j not in best or d < best[j][0]):
            best[j] = (d, i)
    js = sorted(best, key=lambda j: best[j][1])
    return np.array([best[j][1] for j in js], dtype=int), np.array(js, dtype=int)


def footsteps_by_style(log: dict[str, np.ndarray], match_s: float = MATCH_S) -> dict[str, dict]:
    """Per operator style (the measured step's tick decides): measured and planned step counts, pairs,
    the pairs' RMS difference (x, y, and as a distance, m), and the mean step of each (m, heading
    frame; y is taken on the left foot's side, so left and right steps average to the width)."""
    got = measured_and_planned_steps(log)
    if got is None:
        return {}
    return compare_by_style(*got, [str(n) for n in log.get("style_names", [])], match_s)


def compare_by_style(measured: Steps, planned: Steps, names: list[str],
                     match_s: float = MATCH_S) -> dict[str, dict]:
    """footsteps_by_style's figures from the two step lists (style_id indexes `names`)."""
    i, j = pair(measured, planned, match_s)
    out: dict[str, dict] = {}

    def mean_step(s: Steps, rows: np.ndarray) -> list[float]:
        if not rows.any():
            return [float("nan"), float("nan")]
        sign = np.where(s.foot[rows] == 0, 1.0, -1.0)
        return [float(s.step_h_m[rows, 0].mean()), float((sign * s.step_h_m[rows, 1]).mean())]

    for sid, name in enumerate(names):
        m_rows, p_rows = measured.style_id == sid, planned.style_id == sid
        if not m_rows.any() and not p_rows.any():
            continue
        paired = measured.style_id[i] == sid
        d = measured.step_h_m[i[paired]] - planned.step_h_m[j[paired]]
        entry = {"steps": int(m_rows.sum()), "plan_steps": int(p_rows.sum()), "paired": int(paired.sum()),
                 "mean_step_m": mean_step(measured, m_rows), "plan_mean_step_m": mean_step(planned, p_rows)}
        if len(d):
            entry |= {"rms_x_m": float(np.sqrt(np.mean(d[:, 0] ** 2))), "rms_y_m": float(np.sqrt(np.mean(d[:, 1] ** 2))),
                      "rms_m": float(np.sqrt(np.mean((d**2).sum(axis=1))))}
        out[name] = entry
    return out
