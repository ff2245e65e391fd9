"""The Jinja environment: templates only format values prepared in Python."""
from __future__ import annotations

from functools import cache


@cache
def environment():
    import jinja2

    from ..resources import data_dir

    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        bytecode_cache=_bytecode_cache(jinja2),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )


def _bytecode_cache(jinja2):
    """Compiled templates kept in modc's disk cache: compiling the ~20 templates from source
    costs a compile more than rendering them (jinja keys each by its source's checksum)."""
    import os

    from ..cache import root

    if os.environ.get("MODC_NO_CACHE"):
        return None
    directory = root() / "jinja"
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    if not os.access(directory, os.W_OK):  # jinja would fail writing, and a read-only home means no cache
        return None
    return jinja2.FileSystemBytecodeCache(str(directory))


def render(name: str, context: dict) -> str:
    return environment().get_template(name).render(**context)
