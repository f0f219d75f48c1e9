"""A 3D view of the G1 in the browser (viser), live or replayed: `--web` on g1 launch, g1 replay, g1 view.

The robot's visual meshes (the MuJoCo model's group-1 mesh geoms) and the scene's boxes and
meshes (tables, platforms, boxes, a clip's shapes: every box or mesh geom outside the robot, in
its own colour) are sent once; each update moves one frame per body to the pose MuJoCo's forward
kinematics gives for a full configuration (base position, base quaternion w x y z, 29 joints, then
the free bodies of the scene: its boxes). A text panel shows the overlay (command,
achieved velocity, safety state). viser serves its own page and client, so nothing is fetched
from the network; install it with `pip install 'g1-control[web]'` (scripts/setup.sh does).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from g1_control.errors import G1ControlError
from g1_control.robot import g1

ROBOT_RGB = (70, 110, 200)
"""One colour for the whole robot (a screenshot test looks for it)."""
VISUAL_GROUP = 1


def import_viser():
    try:
        import viser
    except ImportError:
        raise G1ControlError("the browser view needs viser: pip install 'g1-control[web]' (or pip install viser)") from None
    return viser


class WebView:
    """A viser server showing one G1. `show(qpos, text)` moves it; `url` is where to look."""

    def __init__(self, model, *, port: int = 8080, host: str = "127.0.0.1", title: str = "g1-control"):
        import mujoco

        viser = import_viser()
        self.model = model
        self.data = mujoco.MjData(model)
        self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.server.gui.configure_theme(control_layout="floating", dark_mode=False)
        self.server.scene.set_up_direction("+z")
        self.server.scene.add_grid("/ground", width=20.0, height=20.0, cell_size=0.5, position=(0.0, 0.0, 0.0))
        self.title = self.server.gui.add_markdown(f"**{title}**")
        self.text = self.server.gui.add_markdown("")
        self.frames: dict[int, Any] = {}  # body id -> viser frame handle
        robot_root = model.body(g1.BASE_BODY).id
        for g in range(model.ngeom):
            body = int(model.geom_bodyid[g])
            on_robot = int(model.body_rootid[body]) == robot_root
            kind = mujoco.mjtGeom(int(model.geom_type[g]))
            if on_robot and (kind != mujoco.mjtGeom.mjGEOM_MESH or model.geom_group[g] != VISUAL_GROUP):
                continue
            if not on_robot and kind not in (mujoco.mjtGeom.mjGEOM_MESH, mujoco.mjtGeom.mjGEOM_BOX):
                continue  # the floor (the grid stands for it)
            if body not in self.frames:
                self.frames[body] = self.server.scene.add_frame(f"/robot/b{body}", show_axes=False)
            color = ROBOT_RGB if on_robot else tuple(round(255 * float(c)) for c in model.geom_rgba[g][:3])
            where = {"position": tuple(model.geom_pos[g]), "wxyz": tuple(model.geom_quat[g])}
            if kind == mujoco.mjtGeom.mjGEOM_BOX:
                self.server.scene.add_box(f"/robot/b{body}/g{g}", color=color,
                                          dimensions=tuple(2.0 * model.geom_size[g]), **where)
                continue
            mesh = int(model.geom_dataid[g])
            va, vn = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            fa, fn = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
            self.server.scene.add_mesh_simple(
                f"/robot/b{body}/g{g}", vertices=np.asarray(model.mesh_vert[va:va + vn], dtype=np.float32),
                faces=np.asarray(model.mesh_face[fa:fa + fn], dtype=np.uint32), color=color, **where)

    @property
    def url(self) -> str:
        return f"http://{self.server.get_host()}:{self.server.get_port()}"

    def show(self, qpos: np.ndarray, text: str = "") -> None:
        """Pose the robot at `qpos` (MuJoCo order: base xyz, base quat wxyz, joints)."""
        import mujoco

        self.data.qpos[:] = qpos
        mujoco.mj_kinematics(self.model, self.data)
        with self.server.atomic():
            for body, frame in self.frames.items():
                frame.position = tuple(self.data.xpos[body])
                frame.wxyz = tuple(self.data.xquat[body])
            if text:
                self.text.content = "```\n" + text + "\n```"
        # The camera follows the pelvis: new pages start looking at it from the front left, open
        # pages keep the user's viewing angle and distance and only turn towards the robot.
        base = tuple(float(x) for x in self.data.qpos[:3])
        self.server.initial_camera.look_at = base
        self.server.initial_camera.position = (base[0] + 2.0, base[1] + 1.6, base[2] + 0.5)
        for client in self.server.get_clients().values():
            client.camera.look_at = base

    def close(self) -> None:
        self.server.stop()
