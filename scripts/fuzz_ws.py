"""The "ws" generator of the fuzz campaign (scripts/fuzz_campaign.py): random websocket frames
(bytes, text, msgpack messages of viser's client types, GUI updates with the page's real element
ids and hostile values) to one `modc view --no-browser --port 0` server started for the campaign
on 127.0.0.1 (with the token of the URL it prints, if any, and the page's own origin). The server
must stay up and print no traceback.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from fuzz_surfaces import FARM, ROOT, Finding, tb_detail

CLIENT_TYPES = ["GuiUpdateMessage", "ViewerCameraMessage", "ScenePointerMessage", "SceneNodeClickMessage",
                "TransformControlsUpdateMessage", "GuiFormSubmitMessage", "GuiCloseModalMessage", "NoSuchMessage", ""]


def ws_frames():
    """A strategy: ("raw", bytes) | ("text", str) | ("msg", {…}) where a GuiUpdateMessage's uuid
    may be an int k meaning the k-th element id the page sent."""
    from hypothesis import strategies as st

    values = st.one_of(st.none(), st.booleans(), st.integers(-10**20, 10**20), st.floats(), st.text(max_size=12),
                       st.lists(st.floats(), max_size=5), st.sampled_from([10**40, "1e400", float("nan")]))
    fields = st.dictionaries(st.sampled_from(["value", "wxyz", "position", "fov", "near", "far", "uuid", "updates",
                                               "props", "x", "ray_origin"]), values, max_size=4)
    gui = st.tuples(st.integers(0, 200), st.dictionaries(st.sampled_from(["value", "visible", "disabled", "label"]),
                                                         values, min_size=1, max_size=2)).map(
        lambda t: ("msg", {"type": "GuiUpdateMessage", "uuid": t[0], "updates": t[1]}))
    return st.one_of(gui, gui, st.binary(max_size=64).map(lambda b: ("raw", b)),
                     st.text(max_size=64).map(lambda s: ("text", s)),
                     st.tuples(st.sampled_from(CLIENT_TYPES), fields).map(lambda t: ("msg", {"type": t[0], **t[1]})))


def _die_with_parent() -> None:
    """In the server's process: end it when the campaign ends, even by SIGKILL (Linux)."""
    import ctypes
    import signal

    try:
        ctypes.CDLL(None).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class ViewServer:
    """One `modc view FARM --no-browser --port 0` for the campaign, on 127.0.0.1 only; its URL
    (with the token it may carry) is the one it prints."""

    def __init__(self, work: Path):
        self.log = work / "view-stderr.txt"
        self.seen = 0
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
               "DISPLAY": "", "WAYLAND_DISPLAY": ""}
        with open(self.log, "wb") as f:
            self.proc = subprocess.Popen([sys.executable, "-m", "modc", "view", str(FARM), "--no-browser", "--port",
                                          "0"], stdout=subprocess.PIPE, stderr=f, env=env, text=True,
                                         preexec_fn=_die_with_parent)
        line = self.proc.stdout.readline()  # a hang here is the campaign's wall-clock alarm
        m = re.search(r"http://127\.0\.0\.1:(\d+)(/\S*)?", line)
        if not m:
            raise AssertionError(f"modc view printed no address: {line!r} {self.log.read_text()[-500:]}")
        self.origin = f"http://127.0.0.1:{m.group(1)}"
        self.url = "ws://127.0.0.1:" + m.group(1) + (m.group(2) or "/")
        self.ws = None
        self.uuids: list[str] = []

    def _connect(self):
        import viser
        from websockets.sync.client import connect

        self.ws = connect(self.url, origin=self.origin, max_size=None, open_timeout=30, compression=None,
                          subprotocols=[f"viser-v{viser.__version__}"])  # as the page's own client does
        self._drain(2.0)

    def _drain(self, seconds: float) -> None:
        """Read what the server sends for a moment, collecting the page's element ids."""
        import time

        import msgspec
        import zstandard

        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                raw = self.ws.recv(timeout=max(0.01, end - time.monotonic()))
            except TimeoutError:
                return
            if isinstance(raw, bytes) and len(raw) > 16:
                n, c = int.from_bytes(raw[:8], "little"), int.from_bytes(raw[8:16], "little")
                try:
                    doc = msgspec.msgpack.decode(zstandard.ZstdDecompressor().decompress(raw[16:16 + c], n))
                except Exception:  # noqa: BLE001  (not ours to judge: the page's own protocol)
                    continue
                for msg in doc.get("messages", ()):
                    if isinstance(msg, dict) and isinstance(msg.get("uuid"), str) and msg["uuid"] not in self.uuids:
                        self.uuids.append(msg["uuid"])

    def send(self, frame) -> None:
        import msgspec
        from websockets.exceptions import ConnectionClosed

        kind, payload = frame
        if kind == "msg" and isinstance(payload.get("uuid"), int):
            payload = {**payload, "uuid": self.uuids[payload["uuid"] % len(self.uuids)] if self.uuids else "x"}
        try:
            data = msgspec.msgpack.encode(payload) if kind == "msg" else payload
        except OverflowError:  # msgpack has no integer that wide: such a frame cannot be sent at all
            return
        try:
            if self.ws is None:
                self._connect()
            self.ws.send(data)
            self._drain(0.05)
        except ConnectionClosed:
            self.ws = None  # the server may close a connection that sent garbage: a new one next time
        self.check()

    def check(self) -> None:
        if self.proc.poll() is not None:
            raise Finding("traceback", f"modc view exited ({self.proc.returncode})", self.log.read_text()[-3000:])
        text = self.log.read_text(errors="replace")
        new, self.seen = text[self.seen:], len(text)
        if "Traceback" in new:
            raise Finding("traceback", f"modc view: {tb_detail(new)}", new[-3000:])

    def close(self) -> None:
        if self.ws is not None:
            self.ws.close()
        self.proc.terminate()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
