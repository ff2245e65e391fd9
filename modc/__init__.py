"""modc: a compiler for MOIRs Mark-2 modular robot arms (.mod -> URDF and friends).

Kept free of imports so that `modc lint` starts fast; the API lives in modc.api.
"""
__version__ = "0.1.0"


def load(path, robot=None, library=None):
    """The checked robot defined in a .mod or YAML file (see modc.api)."""
    from .api import load as _load

    return _load(path, robot, library)


def chain(robot):
    """Forward kinematics (the paper's three-frame product) of a loaded robot."""
    from .api import chain as _k

    return _k(robot)
