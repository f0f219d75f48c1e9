"""The browser view (viser): headless Chromium loads the page and the robot is in the screenshot."""

import shutil
import socket
import subprocess
import tempfile
import time

import numpy as np
import pytest

from g1_control.robot import description, g1

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
# Flags that work on a machine without a GPU or a network (software WebGL, no background calls home).
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-quic",
                  "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def _needs(what: str, ok: bool) -> None:
    if not ok:
        pytest.fail(f"{what} is not installed (scripts/setup.sh --test installs it as root)")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Browser:
    """Headless Chromium driven over the DevTools protocol: `look(url, done)` loads the page and takes
    screenshots, one about every second, until `done(picture)` holds or `deadline_s` of wall time
    passes, and returns the last one. Nothing rides on a virtual-time budget: on a loaded 2-core host a
    `--screenshot --virtual-time-budget` run took 10 to 53 s and now and then handed back a page whose
    software WebGL had not drawn yet; here a slow host only makes the wait longer (a page took up to
    ~110 s to draw and settle beside 2 busy processes and other jobs on 2 cores, a load of 9)."""

    def __init__(self, size=(800, 600)):
        import os

        self.size = size
        self._profile = tempfile.TemporaryDirectory(prefix="g1-chromium-", ignore_cleanup_errors=True)
        self._process = subprocess.Popen([CHROMIUM, *CHROMIUM_FLAGS, f"--user-data-dir={self._profile.name}",
                                          f"--window-size={size[0]},{size[1]}", "--remote-debugging-port=0",
                                          "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self._ids = 0
        self._socket = None
        try:
            # Chromium writes its port and browser endpoint there once it listens (port 0: any free one).
            active = os.path.join(self._profile.name, "DevToolsActivePort")
            end = time.monotonic() + 60.0
            while not (os.path.exists(active) and len(open(active).read().split()) >= 2):
                if self._process.poll() is not None or time.monotonic() > end:
                    raise RuntimeError(f"headless Chromium did not start its DevTools endpoint (exit code "
                                       f"{self._process.poll()})")
                time.sleep(0.1)
            port, path = open(active).read().split()[:2]
            from websockets.sync.client import connect

            self._socket = connect(f"ws://127.0.0.1:{port}{path}", max_size=None, proxy=None, open_timeout=60)
            page = next(t["targetId"] for t in self._call("Target.getTargets")["targetInfos"] if t["type"] == "page")
            self._session = self._call("Target.attachToTarget", targetId=page, flatten=True)["sessionId"]
        except BaseException:
            self.close()
            raise

    def _call(self, method: str, session: str | None = None, timeout_s: float = 60.0, **params) -> dict:
        import json

        self._ids += 1
        message = {"id": self._ids, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        self._socket.send(json.dumps(message))
        end = time.monotonic() + timeout_s
        while True:  # events and late answers to earlier calls are passed over
            answer = json.loads(self._socket.recv(timeout=max(0.0, end - time.monotonic())))
            if answer.get("id") == self._ids:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error'].get('message')}")
                return answer["result"]

    def look(self, url: str, done, settled: bool = False, deadline_s: float = 240.0) -> tuple[np.ndarray, bool]:
        """The last screenshot of `url` and whether `done` held on it (and, with `settled`, whether it
        was the same picture as the one before: the scene fades in over seconds under load, and a
        picture that stopped changing has finished)."""
        import base64

        import imageio.v2 as imageio

        self._call("Emulation.setDeviceMetricsOverride", self._session, width=self.size[0], height=self.size[1],
                   deviceScaleFactor=1, mobile=False)
        self._call("Page.navigate", self._session, url=url)
        end = time.monotonic() + deadline_s
        picture, before, error = None, None, None
        while True:
            try:
                png = self._call("Page.captureScreenshot", self._session, format="png")["data"]
                before, picture = picture, imageio.imread(base64.b64decode(png))[..., :3]
            except (RuntimeError, TimeoutError) as e:  # the page is swapping renderers, or the host is slow
                error = e
            held = picture is not None and bool(done(picture)) and (
                not settled or (before is not None and np.array_equal(before, picture)))
            if held or time.monotonic() > end:
                break
            time.sleep(1.0)
        if picture is None:
            pytest.fail(f"headless Chromium gave no screenshot of {url} within {deadline_s:.0f} s ({error})")
        return picture, held

    def close(self) -> None:
        if self._socket is not None:
            self._socket.close()
        self._process.kill()
        self._process.wait()
        self._profile.cleanup()


def robot_pixels(image: np.ndarray) -> int:
    """Pixels of the robot's colour (sim/web.py ROBOT_RGB, shaded), in the 3D canvas's middle."""
    h, w, _ = image.shape
    middle = image[h // 5: h, w // 5: 4 * w // 5].astype(int)
    r, g, b = middle[..., 0], middle[..., 1], middle[..., 2]
    return int(((b - r > 50) & (b - g > 30) & (b > 80)).sum())


MARKER_RGB = (60, 180, 70)
"""A green box the robot test puts where the camera looks once the robot is out of sight: a settled
picture with it has drawn its scene (which fades in, the marker with the robot), so a missing robot
there means out of sight, not not yet drawn."""


@pytest.mark.slow
def test_browser_shows_the_robot():
    _needs("chromium", CHROMIUM is not None)
    from g1_control.sim.web import WebView

    model = description.mujoco_spec().compile()
    view = WebView(model, port=_free_port(), title="test")
    try:
        browser = Browser()
        try:
            q = np.zeros(model.nq)
            q[2], q[3], q[7:] = 0.79, 1.0, g1.DEFAULT_Q_RAD
            view.show(q, "t 1.0 s\nsafety ok")
            image, _ = browser.look(view.url, lambda p: _drawn(p) and robot_pixels(p) > 3000)
            # The same page with the robot far out of sight: the count must drop to (nearly) nothing.
            view.show(q, "gone")
            view.server.scene.add_box("/marker", color=MARKER_RGB, dimensions=(2.0, 2.0, 2.0),
                                      position=(0.0, 0.0, -200.0))
            view.server.initial_camera.look_at = (0.0, 0.0, -200.0)  # look at the marker far below: no robot
            view.server.initial_camera.position = (0.0, 0.0, -190.0)
            empty, settled = browser.look(view.url, lambda p: box_pixels(p) > 500 and robot_pixels(p) < 100,
                                          settled=True)
        finally:
            browser.close()
    finally:
        view.close()
    assert _drawn(image), "the page never drew its 3D scene within the deadline (the canvas stayed blank)"
    assert robot_pixels(image) > 3000, f"robot not in the screenshot ({robot_pixels(image)} robot-coloured pixels)"
    assert box_pixels(empty) > 500, (f"the page looking away from the robot never drew its scene within the deadline "
                                     f"(the marker where it looks: {box_pixels(empty)} green pixels)")
    assert robot_pixels(empty) < 100, f"robot still in the screenshot looking away ({robot_pixels(empty)} pixels)"
    assert settled, "the page looking away from the robot never stopped changing (still fading in?) within the deadline"


def _scene_model():
    from g1_control.config import from_dict
    from g1_control.scene import SceneConfig
    from g1_control.sim.replay_scene import ReplayScene, replay_model

    scene = {"tables": [{"name": "table_a", "center_xy_m": [1.0, -0.8], "size_xy_m": [0.5, 0.8], "height_m": 0.7}],
             "boxes": [{"name": "box", "stands_on": "table_a", "xy_m": [1.0, -0.8], "size_m": [0.3, 0.3, 0.3]}]}
    from_dict(SceneConfig, scene, "scene")  # a valid scene
    import json

    return replay_model(ReplayScene(scene_json=json.dumps(scene)))


def test_web_view_draws_the_scene_and_moves_its_box():
    from g1_control.sim.web import WebView

    model = _scene_model()
    view = WebView(model, port=_free_port(), title="scene")
    try:
        box, table = model.body("box").id, model.body("table_a").id
        assert box in view.frames and table in view.frames, "the scene's bodies are not in the browser view"
        q = np.zeros(model.nq)
        q[2], q[3], q[7:36] = 0.79, 1.0, g1.DEFAULT_Q_RAD
        adr = model.jnt_qposadr[model.joint("box_free").id]
        q[adr:adr + 7] = [0.7, 0.2, 0.9, 1.0, 0.0, 0.0, 0.0]
        view.show(q, "box in the air")
        np.testing.assert_allclose(view.frames[box].position, [0.7, 0.2, 0.9])
        np.testing.assert_allclose(view.frames[table].position, [1.0, -0.8, 0.0])
    finally:
        view.close()


def box_pixels(image: np.ndarray) -> int:
    """Pixels of the boxes' green (sim/scene.py BOX_RGBA, shaded) in the 3D canvas's middle (not
    the page's green "connected" icon or axis gizmo). By hue, not saturation: software WebGL draws the
    box pale (180, 222, 179), and the floor and robot are grey or blue."""
    h, w, _ = image.shape
    middle = image[h // 5: h, w // 5: 4 * w // 5]
    r, g, b = (middle[..., k].astype(int) for k in range(3))
    return int(((g > 60) & (g > r + 25) & (g > b + 25)).sum())


def _drawn(image: np.ndarray) -> bool:
    """Whether the 3D canvas has drawn its scene: the floor and the robot cover much of the picture's
    middle (the page's text and icons alone do not)."""
    h, w, _ = image.shape
    middle = image[h // 5: h, w // 5: 4 * w // 5]
    return float((middle < 250).any(axis=2).mean()) > 0.05


def test_browser_shows_the_box():
    _needs("chromium", CHROMIUM is not None)
    from g1_control.sim.web import WebView

    model = _scene_model()
    view = WebView(model, port=_free_port(), title="scene")
    try:
        browser = Browser()
        try:
            q = np.zeros(model.nq)
            q[2], q[3], q[7:36] = 0.79, 1.0, g1.DEFAULT_Q_RAD
            adr = model.jnt_qposadr[model.joint("box_free").id]
            q[adr:adr + 7] = [0.6, 0.3, 0.9, 1.0, 0.0, 0.0, 0.0]
            view.show(q, "box beside the robot")
            image, _ = browser.look(view.url, lambda p: _drawn(p) and box_pixels(p) > 500)
            q[adr:adr + 3] = [60.0, 60.0, 0.15]  # recorded far away: gone from the picture
            view.show(q, "box gone")
            # Drawn here means the robot beside it in colour, in a settled picture: the scene fades in,
            # and while it is pale (seen for 10-25 s under load) the box would not count either.
            gone, settled = browser.look(view.url, lambda p: robot_pixels(p) > 3000 and box_pixels(p) < 50,
                                         settled=True)
        finally:
            browser.close()
    finally:
        view.close()
    assert _drawn(image), "the page never drew its 3D scene within the deadline (the canvas stayed blank)"
    assert box_pixels(image) > 500, f"box not in the screenshot ({box_pixels(image)} green pixels)"
    assert robot_pixels(gone) > 3000, ("the page with the box gone never drew its scene within the deadline "
                                       f"(the robot beside it: {robot_pixels(gone)} pixels)")
    assert box_pixels(gone) < 50, f"box still in the screenshot after it moved away ({box_pixels(gone)} green pixels)"
    assert settled, "the page with the box gone never stopped changing (still fading in?) within the deadline"
