"""One differential-IK step: gather the tasks' costs and the limits' constraints into a dense QP
over the tangent step dq (nv = 35) and solve it.

    minimize 1/2 dq^T H dq + c^T dq   s.t.  lb <= dq <= ub,  l <= A dq <= u,  A_eq dq = b

Backends: "daqp" (dual active set; default, about 6x faster than proxqp on this problem size,
measured in `g1 bench ik`) and "proxqp" (proxsuite's dense solver). Both are registry packages.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from g1_control.ik.configuration import Configuration
from g1_control.ik.exceptions import IKError, NoSolutionFound
from g1_control.ik.limits.base import INF, BoxBounds, Limit, RowConstraint
from g1_control.ik.tasks.base import Task
from g1_control.ik.tasks.frame_task import FrameTask, stack_frame_tasks

BACKENDS = ("daqp", "proxqp")


def import_proxsuite():
    """proxsuite with its portable (SSE2) build of the solver rather than the AVX2/AVX-512 build its
    package picks on this CPU: those builds give answers that differ in the last bits depending on
    where their work buffers happen to lie in memory (measured: the same dense QP, solved 200 times
    in one process, gave two different x under AVX-512 and under AVX2, one under the portable build,
    which costs ~5 % more per solve), and a lockstep run must be bit-identical from run to run.

    The package's own __init__ (which loads the fastest build) is bypassed; `import proxsuite`
    elsewhere then gets this module. If proxsuite was imported before, that module is returned
    as it is (two builds cannot live in one process)."""
    import importlib
    import importlib.util
    import sys
    import types

    loaded = sys.modules.get("proxsuite")
    if loaded is not None:
        return loaded
    spec = importlib.util.find_spec("proxsuite")
    if spec is None or spec.submodule_search_locations is None:
        raise ImportError("proxsuite is not installed (pip install proxsuite)")
    package = types.ModuleType("proxsuite", "proxsuite, its portable build (g1_control.ik.solver.import_proxsuite)")
    package.__path__ = list(spec.submodule_search_locations)
    package.__spec__ = spec
    sys.modules["proxsuite"] = package
    try:
        core = importlib.import_module("proxsuite.proxsuite_pywrap")
    except ImportError:
        del sys.modules["proxsuite"]
        import proxsuite

        return proxsuite
    package.__dict__.update({k: v for k, v in vars(core).items() if not k.startswith("__")})
    package.build = "portable"  # type: ignore[attr-defined]
    return package


class QPSolver:
    """Reusable solver for one model size; keeps its work arrays between calls."""

    def __init__(self, nv: int = 35, backend: str = "daqp", tolerance: float = 1e-7) -> None:
        if backend not in BACKENDS:
            raise IKError(f"unknown QP backend '{backend}'; known: {', '.join(BACKENDS)}")
        self.nv, self.backend, self.tolerance = nv, backend, tolerance
        self.hessian = np.zeros((nv, nv))
        self.linear = np.zeros(nv)
        self.lower = np.zeros(nv)
        self.upper = np.zeros(nv)
        self.last_iterations = 0
        self._senses: dict[tuple[int, int], np.ndarray] = {}
        if backend == "daqp":
            import daqp

            self._daqp = daqp
        else:
            self._proxsuite = import_proxsuite()

    def build(self, configuration: Configuration, tasks: Sequence[Task], limits: Sequence[Limit],
              dt_s: float) -> tuple[list[RowConstraint], list[RowConstraint]]:
        """Fill H, c and the box; return (inequality rows, equality rows)."""
        self.hessian.fill(0.0)
        self.linear.fill(0.0)
        jacs, errs, weights = [], [], []
        frame_tasks = [t for t in tasks if type(t) is FrameTask and t.lm_damping == 0.0]
        if frame_tasks:
            jac_rows, err, w2 = stack_frame_tasks(configuration, frame_tasks)
            jacs.append(jac_rows)
            errs.append(err)
            weights.append(w2)
        for task in tasks:
            if type(task) is FrameTask and task.lm_damping == 0.0:
                continue
            if task.stackable and task.lm_damping == 0.0:
                # Gathered and multiplied once below: one (m, nv) product instead of one per task.
                err, jac_rows = task.compute_error_and_jacobian(configuration)
                jacs.append(jac_rows)
                errs.append(task.gain * err)
                w2 = task._w2
                weights.append(w2 if w2.shape == err.shape else np.broadcast_to(w2, err.shape))
            else:
                task.add_objective(configuration, self.hessian, self.linear)
        if jacs:
            jac = np.concatenate(jacs)
            jw = jac.T * np.concatenate(weights)
            self.hessian += jw @ jac
            self.linear += jw @ np.concatenate(errs)
        self.lower.fill(-INF)
        self.upper.fill(INF)
        rows, eqs = [], []
        for limit in limits:
            cons = limit.compute(configuration, dt_s)
            if cons is None:
                continue
            if isinstance(cons, BoxBounds):
                np.maximum(self.lower, cons.lower, out=self.lower)
                np.minimum(self.upper, cons.upper, out=self.upper)
            elif cons.equality:
                eqs.append(cons)
            else:
                rows.append(cons)
        # Two boxes that do not overlap (only when q already broke one of them): keep the lower
        # bound, which moves the joint back toward its allowed range.
        np.maximum(self.upper, self.lower, out=self.upper)
        return rows, eqs

    def solve(self, configuration: Configuration, tasks: Sequence[Task], limits: Sequence[Limit],
              dt_s: float) -> np.ndarray:
        """The step dq (nv,) minimising the tasks' costs within the limits."""
        rows, eqs = self.build(configuration, tasks, limits, dt_s)
        if self.backend == "daqp":
            return self._solve_daqp(rows, eqs)
        return self._solve_proxqp(rows, eqs)

    def _solve_daqp(self, rows: list[RowConstraint], eqs: list[RowConstraint]) -> np.ndarray:
        cons = eqs + rows
        if cons:
            a = np.concatenate([c.matrix for c in cons])
            bu = np.concatenate([self.upper] + [c.upper for c in cons])
            bl = np.concatenate([self.lower] + [c.lower for c in cons])
        else:
            a = np.zeros((0, self.nv))
            bu, bl = self.upper.copy(), self.lower.copy()
        n_eq = sum([c.matrix.shape[0] for c in eqs])
        sense = self._senses.get((bu.shape[0], n_eq))
        if sense is None:  # daqp's row kinds: 0 inequality, 5 equality (read-only: reused every tick)
            sense = np.zeros(bu.shape[0], dtype=np.int32)
            sense[self.nv:self.nv + n_eq] = 5
            self._senses[(bu.shape[0], n_eq)] = sense
        x, _, exitflag, info = self._daqp.solve(self.hessian, self.linear, a, bu, bl, sense,
                                                primal_tol=self.tolerance)
        self.last_iterations = int(info.get("iterations", 0)) if isinstance(info, dict) else 0
        self.last_exitflag = int(exitflag)
        if exitflag < 1:
            raise NoSolutionFound(f"daqp found no IK step (exit flag {exitflag}: "
                                  f"{'infeasible constraints' if exitflag == -1 else 'solver failure'})")
        return np.asarray(x)

    def _solve_proxqp(self, rows: list[RowConstraint], eqs: list[RowConstraint]) -> np.ndarray:
        proxqp = self._proxsuite.proxqp
        a = np.vstack([c.matrix for c in eqs]) if eqs else None
        b = np.concatenate([c.lower for c in eqs]) if eqs else None
        c_mat = np.vstack([c.matrix for c in rows]) if rows else None
        l_vec = np.concatenate([c.lower for c in rows]) if rows else None
        u_vec = np.concatenate([c.upper for c in rows]) if rows else None
        n_eq = 0 if a is None else a.shape[0]
        n_in = 0 if c_mat is None else c_mat.shape[0]
        qp = proxqp.dense.QP(self.nv, n_eq, n_in, True)
        qp.settings.eps_abs = self.tolerance
        qp.settings.verbose = False
        qp.init(self.hessian, self.linear, a, b, c_mat, l_vec, u_vec,
                np.maximum(self.lower, -1e20), np.minimum(self.upper, 1e20))
        qp.solve()
        self.last_iterations = int(qp.results.info.iter)
        if qp.results.info.status != proxqp.QPSolverOutput.PROXQP_SOLVED:
            raise NoSolutionFound(f"proxqp found no IK step (status {qp.results.info.status})")
        return np.asarray(qp.results.x)
