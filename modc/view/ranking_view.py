"""The page of a ranking.json (ranking.py) as viser draws it: the View of one design (server.py:
the same arm, cell, collision colouring, diagnostics, framing and playback), with the list of the
designs on top (rank, chain, cycle time) and, for a design with a task, the segment being played
and the time; for a design without one, a button per target pose ranking.json gives."""
from __future__ import annotations

import html

from .ranking import RankingPage
from .server import PANEL_TEXT, View


class RankingView(View):
    page: RankingPage

    def __init__(self, server, page: RankingPage):
        self._segment = None  # the html handle of the segment on view, when the design plays a task
        options = [page.ranking.choice(k) for k in range(len(page.sources))]
        # made before the View's own panel, so the list of designs heads it
        self._designs = server.gui.add_dropdown("design", options, initial_value=options[page.index])
        self._designs.on_update(self._on_choose)
        super().__init__(server, page)

    def _on_choose(self, event) -> None:
        if event.client is None:  # our own update, after the previous/next buttons
            return
        k = self._designs.options.index(event.target.value)
        with self.lock:
            if k != self.page.index:
                self.page.choose(k)
                self._rebuild()

    def _build(self) -> None:
        self._segment = None
        super()._build()
        page, gui = self.page, self.server.gui
        self._designs.value = self._designs.options[page.index]
        arm = page.arm
        if arm is None:
            return
        if page.source.trajectory is not None:
            task = gui.add_folder("Task")
            self._gui.append(task)
            with task:
                self._segment = gui.add_html("")
                rows = "".join(f"<li>{html.escape(s.label())}</li>" for s in page.segments())
                if rows:
                    gui.add_html(f'<div style="{PANEL_TEXT};font-size:0.8em"><ol start="0" style="margin:2px 0;'
                                 f'padding-left:1.6em">{rows}</ol></div>')
            self._show_segment()
            return
        poses = page.ranking.target_poses(page.index, arm.dof)
        if poses:
            folder = gui.add_folder("Target poses (ranking.json)")
            self._gui.append(folder)
            with folder:
                for name, q in poses:
                    b = gui.add_button(f"at {name}")
                    b.on_click(self._on_target(q))

    def _on_target(self, q):
        def handler(event) -> None:
            def go() -> None:
                assert self.page.arm is not None
                self.page.q = self.page.arm.clamp(q)
                self.page.playing = False

            self._locked(go)
        return handler

    def _move(self) -> None:
        super()._move()
        self._show_segment()

    def _show_segment(self) -> None:
        traj, page = self.page.source.trajectory, self.page
        if self._segment is None or traj is None:
            return
        seg, segs = page.segment(), page.segments()
        where = ""
        if seg is not None:
            k = segs.index(seg)
            where = f" · {'approach' if seg.kind == 'approach' else f'segment {k} of {len(segs) - 1}'}: " + \
                html.escape(f"{seg.start} → {seg.end}")
        self._segment.content = (f'<div style="{PANEL_TEXT}" data-segment="{segs.index(seg) if seg else -1}">'
                                 f"t = {page.t:.2f} s of {traj.t[-1]:.2f} s{where}</div>")
