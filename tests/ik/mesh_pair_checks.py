"""Helpers shared by the collision-limit tests."""

import numpy as np
import pinocchio as pin

from g1_control.ik.configuration import Configuration
from g1_control.robot import g1


def random_configurations(seed: int, count: int):
    """`count` Configurations with joints drawn uniformly within their limits (root fixed)."""
    rng = np.random.default_rng(seed)
    conf = Configuration()
    for _ in range(count):
        q = conf.q.copy()
        q[7:] = rng.uniform(g1.Q_MIN_RAD, g1.Q_MAX_RAD)
        conf.update(q)
        yield conf


def exact_distance_jacobian(limit, conf: Configuration, pairs: np.ndarray, eps: float = 1e-5) -> np.ndarray:
    """Central finite differences of limit.exact's distances of `pairs` over the tangent space
    (GJK and EPA tightened first so that the differences resolve)."""
    for request in limit.geometry_data.distanceRequests:
        request.gjk_tolerance = request.epa_tolerance = 1e-10
    q0 = conf.q.copy()
    out = np.zeros((len(pairs), conf.nv))
    for i in range(conf.nv):
        step = np.zeros(conf.nv)
        step[i] = eps
        conf.update(pin.integrate(conf.model, q0, step))
        plus = limit.exact(conf, pairs)[0]
        conf.update(pin.integrate(conf.model, q0, -step))
        out[:, i] = (plus - limit.exact(conf, pairs)[0]) / (2 * eps)
    conf.update(q0)
    return out
