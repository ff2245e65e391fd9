"""PyBullet for modc: a smoke test of the compiled arm (`modc sim`), pictures (`modc render`) and
trajectory playback (`modc play`).

    scene.py       build a PyBullet world from a checked robot: its compiled URDF and meshes (in a
                   temporary directory), its obstacles and its target markers (reused by `plan`)
    smoke.py       run_sim(path, ...)  -> (ok, report lines, checked)
    render.py      render(path, out_png, pose=None, ...) -> report lines
    play.py        play(path, traj_json, record=None, ...) -> (ok, report lines)
    trajectory.py  the trajectory file of `plan --json` / `play --traj` (SPEC section 6): load, validate

Frames: the world is the cell frame of `base …` (SPEC section 4): each robot's base_link is put at
robot.base, gravity is -z of the world, and obstacles and targets, which the file gives in
base_link, are carried into the world through that same placement. With no `base` line the world
is base_link. Heavy libraries (pybullet, numpy, PIL) are imported inside functions.
"""
from __future__ import annotations


def run_sim(*args, **kwargs):
    from .smoke import run_sim as f

    return f(*args, **kwargs)


def render(*args, **kwargs):
    from .render import render as f

    return f(*args, **kwargs)


def play(*args, **kwargs):
    from .play import play as f

    return f(*args, **kwargs)


__all__ = ["run_sim", "render", "play"]
