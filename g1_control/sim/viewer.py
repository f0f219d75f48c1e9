"""The MuJoCo viewer on a running simulation, with a text overlay (needs a display)."""

from __future__ import annotations


def open_viewer(model, data, *, track_body: str = "pelvis", distance_m: float = 3.0):
    """A passive viewer whose camera follows `track_body`."""
    import mujoco
    import mujoco.viewer

    view = mujoco.viewer.launch_passive(model, data, show_left_ui=False, show_right_ui=False)
    view.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    view.cam.trackbodyid = model.body(track_body).id
    view.cam.distance, view.cam.elevation = distance_m, -15.0
    return view


def update_viewer(view, labels: str, values: str) -> None:
    """Draw the overlay's two text columns and show the current frame."""
    import mujoco

    view.set_texts((mujoco.mjtFont.mjFONT_NORMAL, mujoco.mjtGridPos.mjGRID_TOPLEFT, labels, values))
    view.sync()
