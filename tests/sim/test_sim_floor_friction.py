"""The floor grips as Coulomb friction does, in every scene the simulator builds, the bare floor included.

MuJoCo's defaults (pyramidal friction cones, impratio 1) bound |fx| + |fy| <= mu fn, so a contact
pushed diagonally slides at 0.71 mu, and their friction is soft: a loaded stance foot creeps. Only
scenes with objects had elliptic cones and impratio 100 (g1_control/sim/scene.py grip_physics); the
bare floor, where every walking benchmark and `g1 bench robust` run, kept the defaults, and the
model-based controller's low-friction draws fell on sliding stance feet (robust draw 25, foot friction
0.50: the stance foot slid at 0.1-0.3 m/s with |f_t| / f_z ~0.3 in MuJoCo's own contact forces, and
the robot fell at 3.53 s). Known answers first, on a block standing on four small spheres as the G1's
soles do, then the robot that fell.
"""

import mujoco
import numpy as np
import pytest

from g1_control.scene import SceneConfig
from g1_control.sim.mujoco_backend import MujocoBackend
from g1_control.sim.scene import grip_physics
from g1_control.tools import bench_robust

MU = 0.5
MASS_KG = 10.0


def _slide_mm(grip: bool, ratio: float, angle_rad: float = np.pi / 4, seconds: float = 1.0) -> float:
    """How far (mm) a MASS_KG block on four sole-like spheres (friction MU against the floor) slides in
    `seconds` under a horizontal force of `ratio` x MU x its weight at `angle_rad` from x."""
    spec = mujoco.MjSpec()
    spec.option.timestep = 0.002
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], friction=[MU, 0.005, 1e-4])
    body = spec.worldbody.add_body(name="block", pos=[0, 0, 0.1])
    body.add_freejoint()
    for x in (-0.08, 0.08):
        for y in (-0.03, 0.03):
            body.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.005, 0, 0], pos=[x, y, -0.05],
                          mass=MASS_KG / 4, friction=[MU, 0.005, 1e-4])
    if grip:
        grip_physics(spec)
    model = spec.compile()
    data = mujoco.MjData(model)
    for _ in range(250):  # settle on the floor
        mujoco.mj_step(model, data)
    start = data.qpos[:2].copy()
    force = ratio * MU * MASS_KG * 9.81 * np.array([np.cos(angle_rad), np.sin(angle_rad), 0.0])
    block = model.body("block").id
    for _ in range(round(seconds / model.opt.timestep)):
        data.xfrc_applied[block, :3] = force
        mujoco.mj_step(model, data)
    return float(1000 * np.linalg.norm(data.qpos[:2] - start))


def test_with_grip_physics_a_block_holds_below_mu_in_any_direction_and_slides_above():
    for angle in (0.0, np.pi / 4):
        assert _slide_mm(True, 0.9, angle) < 0.1  # measured 0.01-0.02 mm
        assert _slide_mm(True, 1.1, angle) > 100.0  # measured 246-248 mm: Coulomb, not glue


def test_mujoco_defaults_slide_a_block_pushed_diagonally_below_mu():
    """What the bare floor was: at 0.75 mu diagonally the pyramid's |fx| + |fy| <= mu fn gives way
    (measured 105 mm in 1 s); along an axis it only creeps (1.3 mm at 0.6 mu)."""
    assert _slide_mm(False, 0.75) > 50.0
    assert _slide_mm(False, 0.6, angle_rad=0.0) < 5.0


@pytest.mark.parametrize("scene", [SceneConfig(), None])
def test_the_bare_floor_is_built_with_grip_physics(scene):
    model = MujocoBackend(scene=scene).model
    assert model.opt.cone == mujoco.mjtCone.mjCONE_ELLIPTIC and model.opt.impratio == 100.0


def test_grip_physics_off_keeps_mujocos_defaults():
    model = MujocoBackend(scene=SceneConfig(grip_physics=False)).model
    assert model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL and model.opt.impratio == 1.0


def test_the_low_friction_draw_that_fell_on_sliding_feet_walks():
    """`g1 bench robust` draw 25 (foot friction 0.50, 6.6 ms latency), the model-based controller at
    0.6 m/s: on MuJoCo's default friction it fell at 3.53 s (a joint over-speed trip as the stance foot
    slid, then the pelvis at 0.38 m); on the Coulomb floor it walks (measured: 20 s at 0.640 m/s)."""
    friction, _ = bench_robust.draw_friction_latency(25)
    assert friction == pytest.approx(0.50, abs=0.005)
    row = bench_robust.forward_row("wbc", 25, walk_s=5.0)
    assert not row.fell and row.min_pelvis_m > 0.6, row.fall
    assert 0.5 < row.achieved[0] < 0.7
