"""`modc view` in a real browser: headless Chromium (Debian's `chromium` package) loads the page
from the in-process server, a screenshot shows the arm, dragging a joint slider moves it, and
every request the page makes stays on this machine. Driven over the DevTools protocol with the
`websockets` client viser already brings (no selenium, no driver). Skipped where no Chromium is
installed (CI: apt-get install chromium)."""
from __future__ import annotations

import base64
import contextlib
import io
import itertools
import json
import shutil
import subprocess
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from modc.view.page import Page, Source
from modc.view.server import run, start

ROOT = Path(__file__).resolve().parent.parent
FARM = ROOT / "examples" / "farm.mod"
BROWSER = next((p for p in (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")) if p), None)
pytestmark = pytest.mark.skipif(BROWSER is None, reason="no Chromium installed (Debian: apt-get install chromium)")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
         "--no-first-run", "--enable-unsafe-swiftshader", "--use-angle=swiftshader", "--window-size=1200,800",
         "--remote-debugging-port=0"]


SLIDERS = "document.querySelectorAll('.mantine-Slider-root').length"


class DevTools:
    """The few DevTools-protocol calls the test needs, over one page's websocket."""

    def __init__(self, ws_url: str):
        from websockets.sync.client import connect

        self.ws = connect(ws_url, max_size=64 * 2**20)
        self.ids = itertools.count(1)
        self.events: list[dict] = []

    def call(self, method: str, **params):
        n = next(self.ids)
        self.ws.send(json.dumps({"id": n, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=60))
            if msg.get("id") == n:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self.events.append(msg)

    def js(self, expression: str):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        return r.get("result", {}).get("value")

    def screenshot(self, save: Path | None = None) -> np.ndarray:
        """The page as RGB pixels (also written to `save` as PNG, to look at)."""
        from PIL import Image

        data = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        if save is not None:
            save.write_bytes(data)
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)

    def drag(self, x0: float, y: float, x1: float) -> None:
        self.call("Input.dispatchMouseEvent", type="mousePressed", x=x0, y=y, button="left", clickCount=1)
        for k in range(1, 11):
            self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x0 + (x1 - x0) * k / 10, y=y, button="left")
        self.call("Input.dispatchMouseEvent", type="mouseReleased", x=x1, y=y, button="left", clickCount=1)


def _wait(cond, timeout: float, what: str, every: float = 0.2):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = cond()
        if v:
            return v
        time.sleep(every)
    raise AssertionError(f"timed out waiting for {what}")


@contextlib.contextmanager
def running(page):
    """The page's server with its update loop (as `modc view` runs it); stopped after."""
    server, view = start(page, port=0)
    stop = threading.Event()
    loop = threading.Thread(target=run, args=(view, stop), daemon=True)
    loop.start()
    try:
        yield server, view
    finally:
        stop.set()
        loop.join(timeout=10)


@contextlib.contextmanager
def chromium():
    """Headless Chromium with a fresh profile, driven over DevTools; stopped and removed after."""
    profile = tempfile.mkdtemp(prefix="modc-view-chromium-")
    proc = subprocess.Popen([BROWSER, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        port_file = Path(profile) / "DevToolsActivePort"
        _wait(lambda: port_file.is_file() and port_file.read_text().strip(), 60, "Chromium's DevTools port")
        port = port_file.read_text().split()[0]
        import urllib.request

        targets = json.loads(urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10).read())
        page = next(t for t in targets if t["type"] == "page")
        tools = DevTools(page["webSocketDebuggerUrl"])
        yield tools
        tools.ws.close()
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
        shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture
def browser():
    with chromium() as tools:
        yield tools


# The browser's own notices (e.g. "software WebGL") would count as picture pixels: hidden.
HIDE_NOTICES = """document.head.insertAdjacentHTML('beforeend',
    '<style>[class*="Notification"] { display: none !important; }</style>')"""


def scene_part(img: np.ndarray) -> np.ndarray:
    """The 3D view, left of the control panel."""
    return img[:, : img.shape[1] * 2 // 3]


def changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(scene_part(a) - scene_part(b)).sum(axis=2) > 60


def test_page_shows_the_arm_and_a_slider_moves_it(browser, tmp_path):
    page = Page([Source(FARM)])
    server, view = start(page, port=0)
    url = view.url
    try:
        browser.call("Network.enable")
        browser.call("Page.enable")
        browser.call("Page.navigate", url=url)
        _wait(lambda: server.get_clients(), 60, "the page to connect to the server")
        _wait(lambda: browser.js(SLIDERS) == 3, 60, "3 joint sliders")
        browser.js(HIDE_NOTICES)
        time.sleep(2.0)  # meshes arrive and the first frames render
        before = browser.screenshot(tmp_path / "before.png")
        # the arm is what disappears when its links are hidden; it has the URDF's colours
        for link in view._links.values():
            link.visible = False
        time.sleep(1.5)
        arm = changed(before, browser.screenshot(tmp_path / "hidden.png"))
        for link in view._links.values():
            link.visible = True
        assert arm.sum() > 1500, f"the arm is hardly in the picture ({arm.sum()} pixels)"
        r, g, b = (scene_part(before)[..., k][arm] for k in range(3))
        light = ((r > g + 40) & (g > b + 30)).sum()  # the light (L) modules' orange
        heavy = ((b > r + 40) & (b > g + 10)).sum()  # the heavy (H1) module's blue
        assert light > 100 and heavy > 30, (light, heavy)

        # drag joint_1's slider from its thumb to near the right end of its track
        box = browser.js("""(() => { const s = document.querySelectorAll('.mantine-Slider-root')[0];
            const t = s.querySelector('.mantine-Slider-thumb').getBoundingClientRect();
            const r = s.getBoundingClientRect();
            return [t.x + t.width / 2, t.y + t.height / 2, r.x + r.width * 0.9]; })()""")
        q0 = page.q
        browser.drag(box[0], box[1], box[2])
        _wait(lambda: page.q[0] > q0[0] + 0.5, 20, "joint_1 to follow the slider")
        time.sleep(1.5)
        after = browser.screenshot(tmp_path / "after.png")
        assert page.q[1:] == q0[1:]
        moved = changed(after, before).sum()
        assert moved > 500, f"the picture hardly changed ({moved} pixels)"

        # everything the page loaded came from this process
        urls = {e["params"]["request"]["url"] for e in browser.events if e.get("method") == "Network.requestWillBeSent"}
        origin = f"127.0.0.1:{server.get_port()}"
        local = (f"http://{origin}/", f"ws://{origin}", "data:", "blob:")
        assert urls and all(u.startswith(local) for u in urls), sorted(u for u in urls if not u.startswith(local))
    finally:
        server.stop()


WATCH = """window.modcSeen = {};
setInterval(() => {  // every 20 ms: when each change has reached the page
    const seen = window.modcSeen;
    if (!seen.error && document.body.textContent.includes('error[')) seen.error = Date.now();
    if (!seen.arm && document.querySelectorAll('.mantine-Slider-root').length === 4) seen.arm = Date.now();
}, 20);"""


def test_saving_the_file_updates_the_page_within_a_second(browser, tmp_path):


    f = tmp_path / "farm.mod"
    text = FARM.read_text(encoding="utf-8")
    f.write_text(text, encoding="utf-8")
    page = Page([Source(f)])
    sliders = SLIDERS
    body = "document.body.innerText"
    with running(page) as (server, view):
        browser.call("Page.navigate", url=view.url)
        _wait(lambda: browser.js(sliders) == 3, 60, "3 joint sliders")

        # Two figures per save: when the server has sent the change (what modc controls; must be
        # under a second) and when the page shows it, noted by the page itself (browser clock = this
        # machine's) so the DevTools round trip is not counted. The second depends on the browser
        # having CPU for software WebGL, so it is printed, and only required to come at all.
        browser.js(WATCH)
        t0 = time.time()
        f.write_text(text.replace("chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)",
                                  "chain H1 - L4(pivot=-90deg, port=45deg - L3(link=180mm)"), encoding="utf-8")
        _wait(lambda: "error[" in (view._diagnostics or ""), 5, "the server to send the diagnostics", every=0.005)
        sent_error = time.time() - t0
        shown_error = _wait(lambda: browser.js("window.modcSeen.error"), 60, "the diagnostics in the page") / 1000 - t0
        assert "showing the last good arm" in browser.js(body) and browser.js(sliders) == 3
        (tmp_path / "error.png").write_bytes(base64.b64decode(browser.call("Page.captureScreenshot")["data"]))

        fixed = text.replace("L3(link=180mm)", "L3(link=180mm) - L1").replace("(0, 0, 0) deg", "(0, 0, 0, 0) deg")
        generation = view._generation
        t0 = time.time()
        f.write_text(fixed.replace("(90, -45, -90) deg", "(90, -45, -90, 0) deg"), encoding="utf-8")
        _wait(lambda: view._generation != generation, 5, "the server to send the new arm", every=0.005)
        sent_arm = time.time() - t0
        shown_arm = _wait(lambda: browser.js("window.modcSeen.arm"), 60, "the new arm's 4 sliders") / 1000 - t0
        assert "error[" not in browser.js(body) and "H1-L4-L3-L1" in browser.js(body)
        time.sleep(1.0)
        (tmp_path / "fixed.png").write_bytes(base64.b64decode(browser.call("Page.captureScreenshot")["data"]))
        print(f"save -> sent: diagnostics {sent_error:.2f} s, new arm {sent_arm:.2f} s; "
              f"save -> in the page: diagnostics {shown_error:.2f} s, new arm {shown_arm:.2f} s")
        assert sent_error < 1.0 and sent_arm < 1.0, (sent_error, sent_arm)


def _settle(browser, server) -> None:
    """The page is connected and its panel laid out (the torque table is the last part to come),
    so buttons stay where a click is aimed."""
    _wait(lambda: server.get_clients() and "τnom" in browser.js("document.body.textContent"), 60, "the panel")
    time.sleep(1.0)


def _click(browser, label: str) -> None:
    """A real click on the button whose text is label (the mouse at its centre)."""
    box = browser.js(f"""(() => {{ const b = [...document.querySelectorAll('button')]
        .find(b => b.textContent.trim() === {json.dumps(label)});
        if (!b) return null;
        const r = b.getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; }})()""")
    assert box, f"no button {label!r} in the page"
    for kind in ("mousePressed", "mouseReleased"):
        browser.call("Input.dispatchMouseEvent", type=kind, x=box[0], y=box[1], button="left", clickCount=1)


def test_buttons_page_the_ranking_go_to_poses_and_play(browser, tmp_path):
    import math

    from modc.sim.trajectory import Trajectory
    from modc.view.page import Ranking

    d = tmp_path / "designs"
    d.mkdir()
    (d / "a.mod").write_text("robot a {\n    chain H1 - L4(port=45deg) - L1\n    pose ready (30, -40, 60) deg\n}\n",
                             encoding="utf-8")
    (d / "b.mod").write_text("robot b {\n    chain H1 - L4(port=45deg) - L3 - L1\n}\n", encoding="utf-8")
    ranking = {"designs": [{"rank": 1, "file": "a.mod"}, {"rank": 2, "file": "b.mod"}]}
    (d / "ranking.json").write_text(json.dumps(ranking), encoding="utf-8")
    page = Page.for_ranking(Ranking(d / "ranking.json"))
    with running(page) as (server, view):
        browser.call("Page.navigate", url=view.url)
        _wait(lambda: browser.js(SLIDERS) == 3, 60, "design 1's 3 sliders")
        _settle(browser, server)
        _wait(lambda: _click(browser, "ready") or page.q[0] == pytest.approx(math.radians(30)), 60, "the ready pose")
        _wait(lambda: browser.js("[...document.querySelectorAll('input')].map(i => i.value).includes('30')"), 30,
              "the sliders to show the pose")
        _click(browser, "next design ▶")
        _wait(lambda: browser.js(SLIDERS) == 4 and page.index == 1, 60, "design 2's 4 sliders")
        assert "design 2 of 2" in browser.js("document.body.textContent")
        _click(browser, "◀ previous design")
        _wait(lambda: browser.js(SLIDERS) == 3 and page.index == 0, 60, "design 1 again")

    q = ((0.0, 0.0, 0.0), (0.3, 0.2, 0.1), (0.6, 0.4, 0.2))
    traj = Trajectory(("joint_1", "joint_2", "joint_3"), (0.0, 0.5, 1.0), q)
    page = Page([Source(FARM, traj=traj)])
    with running(page) as (server, view):
        browser.call("Page.navigate", url=view.url)
        _wait(lambda: browser.js(SLIDERS) == 4, 60, "3 joint sliders and the time slider")
        _settle(browser, server)
        _wait(lambda: page.t > 0 or _click(browser, "play"), 60, "playback to start")
        _wait(lambda: not page.playing, 60, "playback to run to the end")
        assert page.t == 1.0 and page.q == pytest.approx((0.6, 0.4, 0.2))
