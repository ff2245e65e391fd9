"""`modc view`: a live 3D view of the arm in the browser."""
from __future__ import annotations

import click

from .app import _err, app, argument, library_option, usage_errors


def _open_browser(url: str) -> bool:
    """Open the page in the user's browser. On Linux without a display, Python's webbrowser would
    fall back to a text browser that takes over the terminal: don't try."""
    import os
    import sys
    import webbrowser

    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        return False
    return webbrowser.open(url)


@app.command("view")
@argument("file", help=".mod file (or its YAML form), or the ranking.json of `modc design`")
@click.option("--port", type=click.IntRange(0, 65535), default=8080, help="local port of the page (0: any free one)")
@click.option("--no-browser", is_flag=True, help="only print the page's address")
@click.option("--traj", help="trajectory JSON to play (`modc plan --json`)")
@click.option("--robot", help="the robot to show (files with several robots)")
@library_option
def view_cmd(file: str, port: int, no_browser: bool, traj: str | None, robot: str | None, library: str | None) -> None:
    """Live 3D view in the browser: the arm in its cell with its targets, a slider per joint, the
    named poses, tool0 and each joint's gravity torque against its actuator, trajectory playback.
    A ranking.json lists its designs and plays each design's task (its .traj.json).
    Saving the file updates the page; an error shows its diagnostics and keeps the last good arm.
    Ctrl-C stops it."""
    from ..view.page import Page, Source, ViewError, read_trajectory
    from ..view.ranking import Ranking, RankingPage
    from ..view.server import ServeError, run, start, stop_server

    # Ctrl-C before the address is printed is click's "Aborted!" (exit 1); after it, a clean stop (exit 0).
    with usage_errors("view", (ViewError, ServeError)):
        if file.endswith(".json"):
            if traj is not None:
                raise ViewError("--traj plays on one file, not on a ranking")
            page: Page = RankingPage(Ranking(file), library=library)
        else:
            source = Source(file, robot=robot, library=library, traj=read_trajectory(traj) if traj else None)
            source.load(strict=True)
            page = Page([source])
        if page.source.diagnostics:
            _err(page.source.diagnostics)
        server, view = start(page, port=port)
    try:
        # the token in the address is the page's key: only who has it (this terminal, the browser opened here) gets in
        print(f"modc view: {view.url}  (Ctrl-C stops)", flush=True)
        if not no_browser and not _open_browser(view.url):
            _err("modc view: no display to open a browser on; open the address above yourself")
        run(view)  # returns on Ctrl-C, the server stopped
    except KeyboardInterrupt:  # Ctrl-C between the address and the serving loop
        stop_server(server)
    print("modc view: stopped")
