"""The Jinja environment: templates only format values prepared in Python."""
from __future__ import annotations

from functools import cache


@cache
def environment():
    import jinja2

    from ..resources import data_dir

    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )


def render(name: str, context: dict) -> str:
    return environment().get_template(name).render(**context)
