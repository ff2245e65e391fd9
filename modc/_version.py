"""The one place modc's version is written: pyproject.toml reads it (hatch), modules import it."""
__version__ = "0.1.0"
