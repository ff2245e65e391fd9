"""PyBullet for modc: a smoke test of the compiled arm (`modc sim`), pictures (`modc render`) and
trajectory playback (`modc play`).

    scene.py       build a PyBullet world from a checked robot: its compiled URDF and meshes (in a
                   temporary directory), its obstacles and its target markers (reused by `plan`)
    contacts.py    the scene's collision queries (self, environment) and an SRDF's disabled pairs
    smoke.py       run_sim(path, ...) -> (ok, report lines, checked): PyBullet measures each pose
    verdict.py     the smoke test's checks and messages from what an engine measured (engine-neutral)
    render.py      render(path, out_png, pose=None, ...) -> (ok, report lines, checked)
    caption.py     caption bands and target labels on renders and GIF frames
    play.py        play(path, traj_json, record=None, engine=...) -> (ok, report lines, checked)
    mujoco_engine.py, mujoco_play.py   `sim` and `play` with --engine mujoco, on the MJCF scene
    (the trajectory file of `plan --json` / `play --traj` is modc/trajectory.py, below plan and view)

Frames: the world is the cell frame of `base …` (docs/language.md): each robot's base_link is put at
robot.base, gravity is -z of the world, and obstacles and targets, which the file gives in
base_link, are carried into the world through that same placement. With no `base` line the world
is base_link. Heavy libraries (pybullet, numpy, PIL) are imported inside functions.

Import the entry points from their modules (modc.sim.smoke.run_sim, modc.sim.render.render,
modc.sim.play.play): this package exports no functions, so that a function never shadows the
module of the same name.
"""
