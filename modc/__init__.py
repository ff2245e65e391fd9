"""modc: a compiler for MOIRs Mark-2 modular robot arms (.mod -> URDF and friends).

It imports only the version (modc/_version.py) so that `modc lint` starts fast and no layer below the
API reaches it through `__version__`; the API lives in modc.api and is imported when first called.
"""
from ._version import __version__

__all__ = ["__version__", "chain", "load"]


def load(path, robot=None, library=None):
    """The checked robot defined in a .mod or YAML file (see modc.api)."""
    from .api import load as _load

    return _load(path, robot, library)


def chain(robot):
    """Forward kinematics (the paper's three-frame product) of a loaded robot."""
    from .api import chain as _k

    return _k(robot)
