import numpy as np

from g1_control import rotations as quat


def _random(n, seed=0):
    return quat.normalize(np.random.default_rng(seed).standard_normal((n, 4)))


def test_matrix_round_trip_and_multiply_matches_matrix_product():
    a, b = _random(10, 1), _random(10, 2)
    back = quat.from_matrix(quat.to_matrix(a))
    np.testing.assert_allclose(np.abs(np.sum(back * a, axis=1)), 1.0, atol=1e-12)
    np.testing.assert_allclose(quat.to_matrix(quat.multiply(a, b)), quat.to_matrix(a) @ quat.to_matrix(b), atol=1e-12)


def test_slerp_endpoints_midpoint_and_shorter_arc():
    a = np.array([1.0, 0.0, 0.0, 0.0])
    b = np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)])  # 1 rad about z
    np.testing.assert_allclose(quat.slerp(a, b, 0.0), a, atol=1e-12)
    np.testing.assert_allclose(quat.slerp(a, b, 1.0), b, atol=1e-12)
    np.testing.assert_allclose(quat.slerp(a, b, 0.5), [np.cos(0.25), 0, 0, np.sin(0.25)], atol=1e-12)
    # -b is the same rotation: slerp must not go the long way round
    np.testing.assert_allclose(np.abs(quat.slerp(a, -b, 0.5) @ [np.cos(0.25), 0, 0, np.sin(0.25)]), 1.0, atol=1e-12)


def test_rotvec_and_angular_velocity():
    q = np.array([np.cos(0.3), np.sin(0.3), 0.0, 0.0])
    np.testing.assert_allclose(quat.to_rotvec(q), [0.6, 0, 0], atol=1e-12)
    angles = np.linspace(0, 1, 11)
    seq = np.stack([np.cos(angles / 2), 0 * angles, 0 * angles, np.sin(angles / 2)], axis=1)
    np.testing.assert_allclose(quat.angular_velocity_w(seq, 10.0), np.tile([0, 0, 1.0], (11, 1)), atol=1e-9)


def test_per_tick_scalar_functions_equal_the_array_forms():
    qs = np.vstack([_random(500, 5), [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]])
    for q in qs:
        rot = quat.to_matrix(q)
        np.testing.assert_allclose(quat.quat_to_rot(q), rot, atol=1e-15)
        assert abs(quat.yaw_of(q) - quat.yaw_of_matrix(rot)) < 1e-12 or abs(abs(quat.yaw_of(q)) - np.pi) < 1e-9
        np.testing.assert_allclose(quat.projected_gravity(q), rot.T @ [0.0, 0.0, -1.0], atol=1e-15)
        tilt = np.arccos(np.clip(rot[2, 2], -1.0, 1.0))
        assert abs(quat.tilt_rad(q) - tilt) < 1e-7
        assert isinstance(quat.yaw_of(q), float) and isinstance(quat.tilt_rad(q), float)
    # Unnormalised and non-finite inputs: the tilt normalises; NaN in, NaN out; zero is NaN.
    assert abs(quat.tilt_rad(np.array([2.0, 0.0, 0.0, 0.0]))) < 1e-12
    assert np.isnan(quat.tilt_rad(np.array([np.nan, 0.0, 0.0, 1.0])))
    assert np.isnan(quat.tilt_rad(np.zeros(4)))
    np.testing.assert_allclose(quat.quat_to_rot([1, 0, 0, 0]), np.eye(3))  # lists and float32 arrays too
    np.testing.assert_allclose(quat.quat_to_rot(np.array([1, 0, 0, 0], dtype=np.float32)), np.eye(3))
