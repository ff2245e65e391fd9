"""modc: a compiler for MOIRs Mark-2 modular robot arms (.mod -> URDF and friends)."""
__version__ = "0.1.0"
