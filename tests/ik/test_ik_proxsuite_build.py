"""proxsuite is loaded in its portable build (g1_control/ik/solver.py:import_proxsuite): the same QP
solved by fresh solvers, with the heap shifted between them, gives bit-identical answers. (The AVX2 and
AVX-512 builds the package picks by itself gave two different answers to this problem, about 1 in 4,
and made lockstep runs with the whole-body controller differ from process to process.)"""

from __future__ import annotations

import numpy as np

from g1_control.ik.solver import import_proxsuite


def _problem(n: int = 47, n_eq: int = 18, n_in: int = 51):
    """A QP of the whole-body controller's size (47 variables, 18 equalities, 51 inequalities)."""
    rng = np.random.default_rng(7)
    m = rng.standard_normal((n, n))
    return (m.T @ m + 1e-3 * np.eye(n), rng.standard_normal(n), rng.standard_normal((n_eq, n)),
            rng.standard_normal(n_eq), rng.standard_normal((n_in, n)), -np.abs(rng.standard_normal(n_in)),
            np.abs(rng.standard_normal(n_in)))


def test_the_same_qp_gets_the_same_answer_wherever_the_solver_lies_in_memory():
    proxsuite = import_proxsuite()
    assert getattr(proxsuite, "build", None) == "portable"
    import proxsuite as imported_later

    assert imported_later is proxsuite, "an `import proxsuite` elsewhere gets the same build"
    H, g, A, b, C, l, u = _problem()
    answers = set()
    rng = np.random.default_rng(3)
    shifts: list[bytearray] = []
    for _ in range(300):
        # Move the solver around the heap: keep some blocks of odd sizes, free others.
        shifts.append(bytearray(int(rng.integers(24, 4000))))
        if rng.random() < 0.4:
            shifts.pop(int(rng.integers(len(shifts))))
        qp = proxsuite.proxqp.dense.QP(H.shape[0], A.shape[0], C.shape[0])
        qp.settings.eps_abs = 1e-5
        qp.settings.eps_rel = 0.0
        qp.settings.verbose = False
        qp.init(H, g, A, b, C, l, u)
        qp.solve()
        assert "SOLVED" in str(qp.results.info.status)
        answers.add(qp.results.x.tobytes())
    assert len(answers) == 1, f"{len(answers)} different answers to one QP"
