"""The physical model of an assembled arm, in memory: what every backend renders and every
analysis consumes (no analysis reads modc's own output back).

    parts.py       the Mark-2 parts as primitives (cylinders, tubes, boxes)
    inertia.py     inertials of parts and links (parallel axes)
    meshes.py      the parts' triangle meshes (numpy) and their binary STL files
    assembly.py    describe(robot) -> Description: links, joints, frames, inertials, parts
    multibody.py   Description -> pinocchio Model and coal collision geometry, directly
    collisions.py  the SRDF's self-collision matrix
    statics.py     gravity torques in numpy (DH conversion's ranking; pinocchio's g(q) is the reference)
    constants.py   gravity, the simulation time step, the acceleration ramp: one value each
    evaluate.py    one candidate arm's tool pose, gravity torques and collisions (design search)
"""
