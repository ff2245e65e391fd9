"""The Jinja environment: templates only format values prepared in Python.

Escaping is done here, by construction, not by each backend:
- XML templates (names ending in XML_TEMPLATES) autoescape every value: a value that is already
  XML or a trusted xacro expression must be passed as markupsafe.Markup, built from checked parts;
- every comment of every output (XML, xacro, YAML, launch, CMake) takes text from outside through
  comment(); XML text content (package.xml's description, maintainer) by autoescape alone;
- names are identifiers (modc.names), so nothing else reaches a name position; scene_token() keeps
  MoveIt's line-based .scene format one token per line anyway.
"""
from __future__ import annotations

import re
from functools import cache

# XML outputs: URDF, SRDF, xacro macros and robots, ROS 1 launch files, package.xml.
XML_TEMPLATES = (".xml.j2", ".xacro.j2", ".launch.j2")


def autoescape(name: str | None) -> bool:
    return name is not None and name.endswith(XML_TEMPLATES)


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
        autoescape=autoescape,
    )


def _bytecode_cache(jinja2):
    """Compiled templates kept in modc's disk cache: compiling the ~20 templates from source
    costs a compile more than rendering them (jinja keys each by its source's checksum)."""
    import os

    from ..cache import directory as cache_directory

    directory = cache_directory("jinja")  # None: no cache (off, or its folder holds an input)
    if directory is None:
        return None
    if not os.access(directory, os.W_OK):  # jinja would fail writing, and a read-only home means no cache
        return None
    return jinja2.FileSystemBytecodeCache(str(directory))


def render(name: str, context: dict) -> str:
    return environment().get_template(name).render(**context)


_EXPANDS = re.compile(r"\$(?=[{(])")  # ${...} (xacro, roslaunch) and $(...) (xacro, roslaunch substitution args)


def comment(text: str) -> str:
    """Any text from outside (a file name, a library description, a warning) as it may stand in a
    comment of any output: one line of printable ASCII (xacro reads files in the locale's encoding;
    control characters are not XML), no "--" and no final "-" (XML comments), and no "${" or "$("
    (expressions xacro and roslaunch would expand). Characters are escaped (\\n, \\xe9), never
    dropped, so the comment still says what the text was. XML metacharacters are left to
    autoescape (a comment shows &amp; for &; it stays well-formed)."""
    s = "".join(c if c.isascii() and c.isprintable() else ascii(c)[1:-1] for c in text)
    s = _EXPANDS.sub("$ ", s)
    while "--" in s:
        s = s.replace("--", "- -")
    return s + " " if s.endswith("-") else s


def scene_token(text: str) -> str:
    """A value of MoveIt's .scene format, which is one value per line: no line breaks or other
    whitespace can start a new record (names are identifiers already; this holds for any text)."""
    return re.sub(r"\s+", "_", text, flags=re.UNICODE) or "_"
