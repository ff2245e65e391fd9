"""`modc view` in a real browser: headless Chromium (Debian's `chromium` package) loads the page
from the in-process server, a screenshot shows the arm, dragging a joint slider moves it, and
every request the page makes stays on this machine; the first view frames the arm, a joint
dragged into the floor colours the links in contact, the compile's torque error shows with its
module highlighted, and the targets are labelled. Driven over the DevTools protocol with the
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


def page_text(browser) -> str:
    return browser.js("document.body ? document.body.textContent : ''") or ""


LIT = 1200  # coloured pixels in the 3D view once the scene is lit (~400 while its lighting still loads)


def settled(browser, timeout: float = 180, lit: bool = True) -> np.ndarray:
    """The page's picture once it is lit (the client decodes its environment light after the
    meshes arrive: until then the scene is washed out) and has stopped changing: two
    screenshots in a row alike. lit=False: a page already lit, showing little colour (the arm hidden)."""
    last = [browser.screenshot()]
    seen = {"moved": -1, "coloured": -1}

    def still():
        img = browser.screenshot()
        # alike: at most 0.1 % of the 3D view's pixels moved (a live page may blink a cursor or
        # fade a notice). The control panel is left out: what the tests measure is the 3D view,
        # and the panel may keep animating (a folder opening, a table filling) while it is still.
        part, before = scene_part(img), scene_part(last[0])
        moved = int((np.abs(part - before).sum(axis=2) > 30).sum()) if part.shape == before.shape else part.size
        colour = int(((part.max(axis=2) - part.min(axis=2)) > 60).sum())
        seen.update(moved=moved, coloured=colour)
        last[0] = img
        return moved < max(20, part.size // 3000) and (colour > LIT or not lit)

    try:
        _wait(still, timeout, "the picture to light up and settle", every=0.3)
    except AssertionError:  # say how far from settled it was: a flake should explain itself
        raise AssertionError(f"the 3D view did not settle in {timeout:.0f} s: {seen['moved']} pixels still moving "
                             f"between the last two pictures, {seen['coloured']} coloured (lit: > {LIT})") from None
    return last[0]


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


def panel_left(browser) -> int:
    """x (px) where the control panel starts: the 3D view is what lies left of it."""
    return int(browser.js("""Math.min(...[...document.querySelectorAll('.mantine-Paper-root')]
        .map(e => e.getBoundingClientRect()).filter(r => r.width > 100).map(r => r.left))"""))


def scene_part(img: np.ndarray, left: int | None = None) -> np.ndarray:
    """The 3D view, left of the control panel."""
    return img[:, : (left if left is not None else img.shape[1] * 2 // 3)]


def changed(a: np.ndarray, b: np.ndarray, left: int | None = None) -> np.ndarray:
    return np.abs(scene_part(a, left) - scene_part(b, left)).sum(axis=2) > 60


def arm_pixels(browser, view, before: np.ndarray, left: int) -> np.ndarray:
    """Where the arm is in the picture: what changes when its links are hidden."""
    for link in view._links.values():
        link.visible = False
    try:
        return changed(before, settled(browser, lit=False), left)
    finally:
        for link in view._links.values():
            link.visible = True


def box_share(mask: np.ndarray) -> float:
    """The mask's bounding box as a share of the mask's picture."""
    ys, xs = np.nonzero(mask)
    if not len(xs):
        return 0.0
    return (xs.max() - xs.min() + 1) * (ys.max() - ys.min() + 1) / mask.size


def open_page(browser, server, view, sliders: int) -> tuple[np.ndarray, int]:
    browser.call("Page.navigate", url=view.url)
    _wait(lambda: server.get_clients(), 60, "the page to connect to the server")
    _wait(lambda: browser.js(SLIDERS) == sliders, 60, f"{sliders} joint sliders")
    _wait(lambda: "τnom" in page_text(browser), 60, "the panel")
    browser.js(HIDE_NOTICES)
    return settled(browser), panel_left(browser)


def slider_drag(browser, index: int, to: float) -> None:
    """Drag slider `index` from its thumb to `to` (0..1) along its track."""
    box = browser.js(f"""(() => {{ const s = document.querySelectorAll('.mantine-Slider-root')[{index}];
        const t = s.querySelector('.mantine-Slider-thumb').getBoundingClientRect();
        const r = s.getBoundingClientRect();
        return [t.x + t.width / 2, t.y + t.height / 2, r.x + r.width * {to}]; }})()""")
    browser.drag(box[0], box[1], box[2])


def colour_pixels(img: np.ndarray, rgb, left: int, tol: int = 40) -> int:
    """Pixels of the 3D view near a colour (shading makes faces darker: the hue is what counts)."""
    part = scene_part(img, left).astype(float)
    want = np.array(rgb, dtype=float)
    bright = part.max(axis=2, keepdims=True)
    norm = part / np.maximum(bright, 1) * want.max()  # the same colour, lit more or less
    return int(((np.abs(norm - want).max(axis=2) < tol) & (bright[..., 0] > 40)).sum())


def _dense(mask: np.ndarray, r: int = 2, least: int = 8) -> np.ndarray:
    """The pixels of mask with at least `least` set pixels in their (2r+1)² neighbourhood."""
    padded = np.pad(mask.astype(int), r)
    h, w = mask.shape
    count = sum(padded[dy:dy + h, dx:dx + w] for dy in range(2 * r + 1) for dx in range(2 * r + 1))
    return mask & (count >= least)


def label_box(browser, label, left: int, name: str, tries: int = 4) -> tuple:
    """Where a label is drawn (and so that it is): what changes when it is hidden, against a fresh picture. A
    software-GL browser sometimes hands over a transient frame (the whole canvas differs): such a
    comparison says nothing about the label and is taken again."""
    for _ in range(tries):
        base = settled(browser)
        label.visible = False
        gone = changed(base, settled(browser, lit=False), left)
        label.visible = True
        dense = _dense(gone)  # a label is a solid box of changed pixels; flicker elsewhere is scattered
        if 30 < dense.sum() < 0.2 * dense.size:
            ys, xs = np.nonzero(dense)
            return xs.min(), xs.max(), ys.min(), ys.max()
    raise AssertionError(f"no label for target {name} ({gone.sum()} pixels changed when hiding it)")


@pytest.mark.slow
def test_page_shows_the_arm_framed_and_a_slider_moves_it(browser, tmp_path):
    page = Page([Source(FARM)])
    server, view = start(page, port=0)
    try:
        browser.call("Network.enable")
        browser.call("Page.enable")
        before, left = open_page(browser, server, view, 3)
        browser.screenshot(tmp_path / "before.png")
        arm = arm_pixels(browser, view, before, left)
        assert arm.sum() > 1500, f"the arm is hardly in the picture ({arm.sum()} pixels)"
        # framed: the arm's bounding box covers a quarter of the 3D view at least (it was 3-5 %)
        assert box_share(arm) >= 0.25, f"the arm covers {box_share(arm):.0%} of the 3D view"
        r, g, b = (scene_part(before, left)[..., k][arm] for k in range(3))
        light = ((r > g + 40) & (g > b + 30)).sum()  # the light (L) modules' orange
        heavy = ((b > r + 40) & (b > g + 10)).sum()  # the heavy (H1) module's blue
        assert light > 100 and heavy > 30, (light, heavy)

        # every target's label is drawn, each in its own place
        # (hiding one label lets the page re-stack the others, so pixels cannot tell where each one
        # sits: that they never overlap is tested on the layout itself, test_view.py
        # test_labels_do_not_overlap_on_screen)
        for name, label in view.labels.items():
            label_box(browser, label, left, name)
        assert set(view.labels) == {"plant", "tray"}
        settled(browser)

        # drag joint_1's slider from its thumb to near the right end of its track
        q0 = page.q
        slider_drag(browser, 0, 0.9)
        _wait(lambda: page.q[0] > q0[0] + 0.5, 20, "joint_1 to follow the slider")
        after = settled(browser)
        browser.screenshot(tmp_path / "after.png")
        assert page.q[1:] == q0[1:]
        moved = changed(after, before, left).sum()
        assert moved > 500, f"the picture hardly changed ({moved} pixels)"

        # everything the page loaded came from this process
        urls = {e["params"]["request"]["url"] for e in browser.events if e.get("method") == "Network.requestWillBeSent"}
        origin = f"127.0.0.1:{server.get_port()}"
        local = (f"http://{origin}/", f"ws://{origin}", "data:", "blob:")
        assert urls and all(u.startswith(local) for u in urls), sorted(u for u in urls if not u.startswith(local))
    finally:
        server.stop()


FLOOR = ("robot arm {\n    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)\n"
         "    box floor size (0.8, 0.8, 0.02) m at (0, 0, -0.01) m\n}\n")


@pytest.mark.slow
def test_a_joint_dragged_into_the_floor_colours_the_links_in_contact(browser, tmp_path):
    from modc.view.arm import COLLISION_RGB

    f = tmp_path / "floor.mod"
    f.write_text(FLOOR, encoding="utf-8")
    page = Page([Source(f)])
    with running(page) as (server, view):
        before, left = open_page(browser, server, view, 3)
        assert "no contact" in page_text(browser)
        red_before = colour_pixels(before, COLLISION_RGB, left)  # the tool0 axes' red
        slider_drag(browser, 1, 0.995)  # joint_2 to the end of its range: the arm folds onto the floor
        _wait(lambda: view.contacts, 30, "a contact")
        _wait(lambda: "link_2 with box 'floor'" in page_text(browser), 30, "the contact listed")
        img = settled(browser)
        browser.screenshot(tmp_path / "contact.png")
        red = colour_pixels(img, COLLISION_RGB, left) - red_before
        assert red > 500, f"the links in contact are hardly red ({red} more pixels)"
        assert {c.a for c in view.contacts} >= {"link_2"} and all(c.b == "floor" for c in view.contacts)


@pytest.mark.slow
def test_the_compile_s_torque_error_shows_with_its_module(browser, tmp_path):
    from modc.view.arm import NAMED_RGB

    f = tmp_path / "heavy.mod"
    f.write_text("robot heavy {\n    chain H1 - H4(pivot=-90deg) - L3\n    payload 5 kg\n}\n", encoding="utf-8")
    page = Page([Source(f)])
    with running(page) as (server, view):
        img, left = open_page(browser, server, view, 3)
        text = page_text(browser)
        assert "error[torque-over-peak]" in text and "highlighted in the view: H4 (warning), L3 (error)" in text
        assert colour_pixels(img, NAMED_RGB["error"], left) > 300


WATCH = """window.modcSeen = {};
setInterval(() => {  // every 20 ms: when each change has reached the page
    const seen = window.modcSeen;
    if (!seen.error && document.body.textContent.includes('error[')) seen.error = Date.now();
    if (!seen.arm && document.querySelectorAll('.mantine-Slider-root').length === 4) seen.arm = Date.now();
}, 20);"""


@pytest.mark.slow
def test_saving_the_file_updates_the_page(browser, tmp_path):
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
        _wait(lambda: "error[" in (view._diagnostics or ""), 60, "the server to send the diagnostics", every=0.005)
        sent_error = time.time() - t0
        shown_error = _wait(lambda: browser.js("window.modcSeen.error"), 60, "the diagnostics in the page") / 1000 - t0
        assert "showing the last good arm" in browser.js(body) and browser.js(sliders) == 3
        (tmp_path / "error.png").write_bytes(base64.b64decode(browser.call("Page.captureScreenshot")["data"]))

        fixed = text.replace("L3(link=180mm)", "L3(link=180mm) - L1").replace("(0, 0, 0) deg", "(0, 0, 0, 0) deg")
        generation = view._generation
        t0 = time.time()
        f.write_text(fixed.replace("(90, -45, -90) deg", "(90, -45, -90, 0) deg"), encoding="utf-8")
        _wait(lambda: view._generation != generation, 60, "the server to send the new arm", every=0.005)
        sent_arm = time.time() - t0
        shown_arm = _wait(lambda: browser.js("window.modcSeen.arm"), 60, "the new arm's 4 sliders") / 1000 - t0
        assert "error[" not in browser.js(body) and "H1-L4-L3-L1" in browser.js(body)
        settled(browser)
        (tmp_path / "fixed.png").write_bytes(base64.b64decode(browser.call("Page.captureScreenshot")["data"]))
        # the figures are printed (benchmarks judge speed); the behaviour is that both arrive
        print(f"save -> sent: diagnostics {sent_error:.2f} s, new arm {sent_arm:.2f} s; "
              f"save -> in the page: diagnostics {shown_error:.2f} s, new arm {shown_arm:.2f} s")


def _settle(browser, server) -> None:
    """The page is connected and its panel laid out (the torque table is the last part to come),
    so buttons stay where a click is aimed."""
    _wait(lambda: server.get_clients() and "τnom" in page_text(browser), 60, "the panel")
    settled(browser)


def _click(browser, label: str) -> None:
    """A real click on the button whose text is label (the mouse at its centre)."""
    box = browser.js(f"""(() => {{ const b = [...document.querySelectorAll('button')]
        .find(b => b.textContent.trim() === {json.dumps(label)});
        if (!b) return null;
        const r = b.getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; }})()""")
    assert box, f"no button {label!r} in the page"
    for kind in ("mousePressed", "mouseReleased"):
        browser.call("Input.dispatchMouseEvent", type=kind, x=box[0], y=box[1], button="left", clickCount=1)


@pytest.mark.slow
def test_buttons_page_the_ranking_go_to_poses_and_play(browser, tmp_path):
    import math

    from modc.trajectory import Trajectory
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
        assert "design 2 of 2" in page_text(browser)
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


@pytest.mark.slow
def test_a_page_opened_on_a_broken_file_frames_the_arm_once_fixed(browser, tmp_path):
    f = tmp_path / "farm.mod"
    text = FARM.read_text(encoding="utf-8")
    f.write_text(text.replace("- L3(link=180mm)", "- L3(link=180mm"), encoding="utf-8")
    page = Page([Source(f)])
    with running(page) as (server, view):
        browser.call("Page.navigate", url=view.url)
        _wait(lambda: "no good arm yet" in page_text(browser), 60, "the page on the broken file")
        browser.js(HIDE_NOTICES)
        f.write_text(text, encoding="utf-8")
        _wait(lambda: browser.js(SLIDERS) == 3 and "τnom" in page_text(browser), 60, "the arm")
        before = settled(browser)
        arm = arm_pixels(browser, view, before, panel_left(browser))
        assert box_share(arm) >= 0.25, f"the arm covers {box_share(arm):.0%} of the 3D view"


REGION = ("robot arm {\n    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)\n"
          "    target plant at (0.3, 0.1, 0.25) m\n"
          "    region tray box size (0.2, 0.1, 0) m at (0.1, -0.4, 0.1) m turned (0, 0, 30) deg grid 3 x 2 x 1\n}\n")


@pytest.mark.slow
def test_a_region_shows_its_points_in_the_picture(browser, tmp_path):
    """The region's points (and its box) are drawn in the target's red: the same arm without the
    region shows only the one target's."""
    from modc.physical.cell import TARGET_RGBA

    red = tuple(round(255 * c) for c in TARGET_RGBA[:3])
    counts = []
    for k, text in enumerate((REGION, REGION.replace(REGION.splitlines()[3] + "\n", ""))):
        f = tmp_path / f"arm{k}.mod"
        f.write_text(text, encoding="utf-8")
        page = Page([Source(f)])
        server, view = start(page, port=0)
        try:
            img, left = open_page(browser, server, view, 3)
            browser.screenshot(tmp_path / f"region{k}.png")
            counts.append(colour_pixels(img, red, left))
        finally:
            server.stop()
    with_region, without = counts
    assert with_region > without + 100, counts
