"""The page itself, drawn with viser (a maintained 3D web viewer whose built web client ships in
its wheel: everything is served from this process, nothing is fetched from the internet).

Scene tree: /armN (N counts the arms shown) is base_link, at T_world_base; under it the cell
(obstacles, targets) and one node per link, moved as the joints move; the part meshes hang under
their link nodes. The GUI (right-hand panel) is rebuilt whenever a new arm comes in; values set from Python fire viser's
callbacks with no client, which the handlers ignore.
"""
from __future__ import annotations

import contextlib
import html
import io
import math
import threading
import time

from . import draw
from .arm import COLLISION_RGB, NAMED_RGB, Arm
from .camera import Camera
from .page import Page

PANEL_TEXT = "padding:0 0.75em;font-size:0.9em"  # HTML blocks aligned with viser's own panel text
TICK = 0.05  # s between looks at the file and playback steps: a saved file shows well within a second


def torque_table(arm: Arm, q) -> str:
    """HTML of the gravity torque of each joint: a bar of |τ| / τmax coloured by level, with a
    tick at τnom."""
    rows = []
    for j in arm.torques(q):
        r, g, b = j.rgb
        share = min(abs(j.tau) / j.tau_max, 1.0) * 100
        bar = (f'<div style="position:relative;background:#ddd;height:10px">'
               f'<div style="width:{share:.0f}%;height:10px;background:rgb({r},{g},{b})">'
               f'</div><div style="position:absolute;top:-2px;left:{j.tau_nom / j.tau_max * 100:.0f}%;width:2px;'
               f'height:14px;background:#444"></div></div>')
        rows.append(f'<tr data-level="{j.level}"><td>{html.escape(j.name)} ({html.escape(j.unit)})</td>'
                    f'<td style="text-align:right;padding-right:8px">{round(j.tau, 2) + 0.0:+.2f}</td>'
                    f'<td>{j.tau_nom:g} / {j.tau_max:g}</td><td style="width:30%">{bar}</td></tr>')
    return ('<table style="width:100%;font-size:0.8em;border-collapse:collapse">'
            '<tr><th align="left">joint</th><th align="right" style="padding-right:8px">τ N·m</th>'
            '<th align="left">τnom / τmax</th><th></th></tr>' + "".join(rows) + "</table>")


REAIM = (0.5, 2.0)  # s after a framing is sent: sent again (see View._camera)


def _aim(client, cam: Camera) -> None:
    with client.atomic():
        client.camera.fov = cam.fov
        client.camera.look_at = tuple(cam.look_at)
        client.camera.position = tuple(cam.position)


class View:
    def __init__(self, server, page: Page):
        self.server = server
        self.page = page
        self.url = ""  # the page's address with its token, set by start()
        self.lock = threading.RLock()
        self._generation = (-1, -1)  # (design index, arm generation) on show
        self._framed: int | None = None  # design index the connected browsers' cameras were framed on
        self._diagnostics: str | None = None
        self._nodes: list = []
        self._shown = 0
        self._gui: list = []
        self._links: dict = {}
        self._meshes: list = []  # (Shape, handle, colour shown)
        self.labels: dict = {}  # target name -> its label's handle
        self._sliders: list = []
        self.camera: Camera | None = None  # the framing camera of the arm on view
        self.contacts: list = []  # what touches at the pose shown (physical.checker.Contact)
        self.named: dict[int, str] = {}  # module index -> "error" | "warning": modules the diagnostics name
        gui = server.gui
        server.scene.set_up_direction("+z")
        server.scene.add_grid("/grid", width=2.0, height=2.0, cell_size=0.1, section_size=0.5)
        self._title = gui.add_html("")  # HTML, escaped: file names and ranking.json text are the user's
        if len(page.sources) > 1:
            prev, nxt = gui.add_button("◀ previous design"), gui.add_button("next design ▶")
            prev.on_click(lambda e: self._go(-1))
            nxt.on_click(lambda e: self._go(+1))
        self._errors = gui.add_html("", visible=False)
        self._contacts = gui.add_html("")
        self._rebuild()

    # -- building -----------------------------------------------------------------------------

    def _clear(self) -> None:
        for h in self._nodes[:1] + self._gui:  # the arm's root node takes everything under it along
            h.remove()
        self._nodes, self._gui, self._links, self._sliders, self._meshes = [], [], {}, [], []

    def _rebuild(self) -> None:
        self._build()
        self.server.flush()

    def _build(self) -> None:
        page, arm = self.page, self.page.arm
        self._clear()
        self._generation = (page.index, page.source.generation)
        who = (f"robot <code>{html.escape(arm.robot.name)}</code>: {html.escape(arm.robot.sequence)}" if arm is not None
               else "no good arm yet")
        self._title.content = f'<div style="{PANEL_TEXT}"><b>{html.escape(page.caption)}</b><br>{who}</div>'
        self._diagnostics = None
        self._show_diagnostics()
        if arm is None:
            self._framed = None
            self._contacts.content = ""
            return
        scene, gui = self.server.scene, self.server.gui
        T = arm.T_world_base
        self._shown += 1
        base = f"/arm{self._shown}"  # fresh names for every arm: browsers never see a name removed and re-added
        self._nodes.append(scene.add_frame(base, show_axes=False, position=T[:3, 3], wxyz=draw.wxyz(T)))
        cam = self._camera(arm)
        nodes, self.labels = draw.cell(scene, base, arm, cam)
        self._nodes += nodes
        for link in arm.description.links:
            self._links[link.name] = scene.add_frame(f"{base}/{link.name}", show_axes=link.name == "tool0",
                                                     axes_length=draw.AXES, axes_radius=0.003)
            self._nodes.append(self._links[link.name])
        self._nodes += draw.tool_and_payload(scene, base, arm)
        for s in arm.shapes():
            h = scene.add_mesh_simple(f"{base}/{s.link}/{s.name}", s.vertices, s.faces, color=s.rgb, flat_shading=True)
            self._meshes.append([s, h, s.rgb])
            self._nodes.append(h)

        joints = gui.add_folder("Joints")
        self._gui.append(joints)
        with joints:
            for i, (name, (lo, hi)) in enumerate(zip(arm.joint_names, arm.limits, strict=True)):
                unit = arm.robot.units[i].name
                s = gui.add_slider(f"{name} ({unit}) °", min=round(math.degrees(lo), 1), max=round(math.degrees(hi), 1),
                                   step=0.1, initial_value=round(math.degrees(page.q[i]), 1))
                s.on_update(self._on_slider(i))
                self._sliders.append(s)
        poses = gui.add_folder("Poses")
        self._gui.append(poses)
        with poses:
            for name, _ in arm.poses:
                b = gui.add_button(name)
                b.on_click(self._on_pose(name))
            reset = gui.add_button("frame the arm")
            reset.on_click(lambda e: self._locked(lambda: self._camera(arm, everyone=True)))
        readout = gui.add_folder("tool0 and torques")
        self._gui.append(readout)
        with readout:
            self._tool = gui.add_markdown("")
            self._torques = gui.add_html("")
        if page.source.trajectory is not None:
            traj = page.source.trajectory
            play = gui.add_folder("Trajectory")
            self._gui.append(play)
            with play:
                run, stop = gui.add_button("play"), gui.add_button("pause")
                self._time = gui.add_slider("t (s)", min=0.0, max=round(traj.t[-1], 3), step=0.01, initial_value=0.0)
                run.on_click(lambda e: self._locked(page.play))
                stop.on_click(lambda e: self._locked(page.pause))
                self._time.on_update(self._on_time)
        self._move()

    def _camera(self, arm: Arm, everyone: bool = False) -> Camera:
        """The arm at its pose with its cell and targets, framed beside the panel (camera.py), for
        new browsers and "reset view"; browsers already open are framed too when they had no arm
        to look at, see a new design, or ask (everyone)."""
        from ..sim.render import VIEWS
        from .camera import frame

        cam = frame(arm.extent(self.page.q), math.radians(VIEWS[0][0]), math.radians(VIEWS[0][1]))
        self.camera = cam
        initial = self.server.initial_camera
        initial.fov, initial.look_at, initial.position = cam.fov, tuple(cam.look_at), tuple(cam.position)
        if everyone or self._framed != self.page.index:
            self._framed = self.page.index
            clients = list(self.server.get_clients().values())
            for client in clients:
                _aim(client, cam)
            # a browser still starting up may apply its own camera after ours (seen: a page opened
            # on a broken file, fixed later, kept viser's default view): aim once more, a moment
            # later, unless the arm on view changed meanwhile
            index = self.page.index
            for delay in REAIM:
                timer = threading.Timer(delay, self._reaim, (clients, cam, index))
                timer.daemon = True
                timer.start()
        return cam

    def _reaim(self, clients, cam: Camera, index: int) -> None:
        with self.lock:
            if self.camera is cam and self.page.index == index:
                for client in clients:
                    with contextlib.suppress(Exception):  # a browser gone meanwhile
                        _aim(client, cam)
                self.server.flush()

    def _show_diagnostics(self) -> None:
        text = self.page.source.diagnostics
        if text == self._diagnostics:
            return
        self._diagnostics = text
        source, arm = self.page.source, self.page.arm
        errors = source.errors
        shown_is_checked = arm is not None and source.current
        head = ("errors: showing the last good arm" if errors and arm is not None and not shown_is_checked
                else "errors" if errors else "warnings")
        pre = '<pre style="white-space:pre-wrap;font-size:0.72em;margin:4px 0">'
        self.named = {}
        if shown_is_checked:
            assert arm is not None
            for d in sorted(source.found, key=lambda d: not d.is_error):  # errors win over warnings
                i = arm.unit_named(d)
                if i is not None:
                    self.named.setdefault(i, "error" if d.is_error else "warning")
        marked = ", ".join(f"{arm.robot.units[i].name} ({level})" for i, level in sorted(self.named.items())) \
            if arm is not None else ""
        note = f'<div style="font-size:0.8em">highlighted in the view: {html.escape(marked)}</div>' if marked else ""
        self._errors.content = (f'<div style="{PANEL_TEXT}"><b style="color:#b42318">{head}</b>{note}{pre}'
                                f'{html.escape(text)}</pre></div>') if text else ""
        self._errors.visible = bool(text)
        self._paint()
        self.server.flush()

    def _paint(self) -> None:
        """Colour the meshes: links in contact red, modules a diagnostic names magenta (error) or
        amber (warning), the rest as the URDF colours them. Only changed colours are sent."""
        touching = {c.a for c in self.contacts} | {c.b for c in self.contacts if not c.b_is_obstacle}
        for m in self._meshes:
            s, h, shown = m
            rgb = COLLISION_RGB if s.link in touching else NAMED_RGB[self.named[s.unit]] if s.unit in self.named \
                else s.rgb
            if rgb != shown:
                h.color, m[2] = rgb, rgb

    def _show_contacts(self) -> None:
        arm = self.page.arm
        assert arm is not None
        self.contacts = arm.contacts(self.page.q)
        if self.contacts:
            rows = "".join(f"<li>{html.escape(c.describe())}</li>" for c in self.contacts)
            self._contacts.content = (f'<div style="{PANEL_TEXT}" data-contacts="{len(self.contacts)}">'
                                      f'<b style="color:#b42318">in contact</b> (as <code>modc plan</code> checks)'
                                      f'<ul style="margin:2px 0;padding-left:1.2em;font-size:0.85em">{rows}</ul></div>')
        else:
            self._contacts.content = '<div style="padding:0 0.75em;font-size:0.8em" data-contacts="0">no contact</div>'
        self._paint()

    def _show_pose(self) -> None:
        with self.server.atomic():  # every link moves in the same frame
            self._move()
        self.server.flush()

    def _move(self) -> None:
        page, arm = self.page, self.page.arm
        if arm is None:
            return
        for name, T in arm.link_poses(page.q).items():
            if name in self._links:
                self._links[name].position = T[:3, 3]
                self._links[name].wxyz = draw.wxyz(T)
        for s, x in zip(self._sliders, page.q, strict=True):
            s.value = round(math.degrees(x), 1)
        x, y, z = arm.tool0(page.q)
        self._tool.content = f"tool0 in base_link: ({x:.4f}, {y:.4f}, {z:.4f}) m"
        self._torques.content = torque_table(arm, page.q)
        self._show_contacts()
        if page.source.trajectory is not None:
            self._time.value = round(page.t, 3)

    # -- events -------------------------------------------------------------------------------

    def _locked(self, action) -> None:
        with self.lock:
            action()
            self._show_pose()

    def _on_slider(self, i: int):
        def handler(event) -> None:
            if event.client is None:  # our own update of the slider
                return
            self._locked(lambda: self.page.set_joint(i, math.radians(event.target.value)))
        return handler

    def _on_pose(self, name: str):
        return lambda event: self._locked(lambda: self.page.go_pose(name))

    def _on_time(self, event) -> None:
        if event.client is not None:
            self._locked(lambda: self.page.seek(event.target.value, stop=True))

    def _go(self, delta: int) -> None:
        with self.lock:
            self.page.go(delta)
            self._rebuild()

    def step(self, dt: float) -> None:
        """Look at the file and move playback on; called every TICK by run()."""
        with self.lock:
            self.page.poll()
            if self._generation != (self.page.index, self.page.source.generation):
                self._rebuild()
            else:
                self._show_diagnostics()
                if self.page.tick(dt):
                    self._show_pose()


class ServeError(OSError):
    """The page cannot be served: the port is taken, or viser is not installed (exit 2)."""


def check_port(host: str, port: int) -> None:
    """viser moves to the next free port when one is taken; the user asked for this one."""
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((host, port))
        except OSError as e:
            raise ServeError(f"port {port} on {host} is busy ({e.strerror or e}); choose another with --port") from None


def start(page: Page, host: str = "127.0.0.1", port: int = 8080):
    """A running viser server showing the page, open only to this run's token (guard.py);
    returns (server, view), the page's address with its token in view.url. port 0: any free port."""
    try:
        import viser
    except ImportError:
        raise ServeError("modc view needs the viser package: pip install viser") from None
    from .guard import Guard, guarding, quiet_malformed_messages

    if port:
        check_port(host, port)
    guard = Guard(host)
    quiet_malformed_messages()
    with guarding(guard) as used, contextlib.redirect_stdout(io.StringIO()):  # viser's banner: modc prints the address
        server = viser.ViserServer(host=host, port=port, label="modc view", verbose=False)
    try:
        if not used:  # a viser that no longer serves through websockets' serve(): never serve unguarded
            raise ServeError("this viser version serves requests modc view cannot guard; install viser 1.1")
        if port and server.get_port() != port:  # taken between the check and the bind
            raise ServeError(f"port {port} on {host} is busy; choose another with --port")
        # no share button: the share link would leave the machine
        server.gui.configure_theme(show_share_button=False, control_width="large")
        view = view_of(server, page)
    except BaseException:  # Ctrl-C while the page is built included: no server left behind
        stop_server(server)
        raise
    view.url = guard.url(server.get_port())
    return server, view


def view_of(server, page: Page) -> View:
    """The View for the page: a ranking's adds the list of designs and the task's segments (ranking_view.py)."""
    from .ranking import RankingPage

    if isinstance(page, RankingPage):
        from .ranking_view import RankingView

        return RankingView(server, page)
    return View(server, page)


def stop_server(server) -> None:
    with contextlib.redirect_stdout(io.StringIO()):  # viser's "Server stopped"
        server.stop()


def run(view: View, stop: threading.Event | None = None) -> None:
    """Serve until Ctrl-C (or `stop` is set)."""
    last = time.monotonic()
    try:
        while stop is None or not stop.is_set():
            time.sleep(TICK)
            now = time.monotonic()
            view.step(now - last)
            last = now
    except KeyboardInterrupt:
        pass
    finally:
        stop_server(view.server)
