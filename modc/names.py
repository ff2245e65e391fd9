"""The rules every user-given string obeys before anything is built from it.

A name reaches XML attributes, xacro and launch files, YAML keys, MoveIt's line-based .scene
format and file names (mod<n>_<name>.urdf.xacro, ROS package names). One rule for all of them,
in both input forms and in library files, so no backend ever sees anything else:

    identifier   robots, poses, targets, obstacles, joints, units: the .mod grammar's NAME,
                 [A-Za-z_][A-Za-z0-9_]*, at most MAX_NAME characters (file names stay far from
                 the 255-byte limit)
    variant      a library's module variants: letters only, at most MAX_VARIANT, because a unit
                 is written as variant + type number (H4) and the grammar lexes it that way
    label        a library's own name: the grammar's LIBRARY_REF (mark2-strict), at most MAX_NAME
    text         free text (descriptions, actuator models, sources): no control or line-breaking
                 characters, at most MAX_TEXT characters
    ROS package  --ros-package (REP 144): lowercase letters, digits and single underscores,
                 starting with a letter and not ending with '_', at most MAX_PACKAGE characters
                 (a robot's name and _moveit_config fit)

Every rule matches the WHOLE string (re.fullmatch): `^…$` with re.match would let a trailing
newline through ("pkg\n"), and that newline would reach launch files and package:// URIs.

Each rule is one function returning why a string breaks it (None when it does not), so the model's
validators, lowering and the library loader share the wording.
"""
from __future__ import annotations

import re
import unicodedata

IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
VARIANT = r"[A-Za-z]+"
LABEL = r"[A-Za-z_][A-Za-z0-9_.-]*"
ROS_PACKAGE = r"[a-z][a-z0-9_]*"
MAX_NAME = 64
MAX_PACKAGE = 100
MAX_VARIANT = 16
MAX_TEXT = 500

IDENTIFIER_RULE = f"ASCII letters, digits and '_', not starting with a digit, at most {MAX_NAME} characters"

_IDENTIFIER = re.compile(IDENTIFIER)
_VARIANT = re.compile(VARIANT)
_LABEL = re.compile(LABEL)
_ROS_PACKAGE = re.compile(ROS_PACKAGE)
# Cc/Cf/Cs/Co/Cn: controls, format (bidi overrides), surrogates, private use, unassigned;
# Zl/Zp: U+2028/U+2029, which YAML and JavaScript take for line breaks.
_BAD_CATEGORIES = {"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"}


def shown(text: str, limit: int = 40) -> str:
    """A string as a diagnostic message may quote it: one line, escaped, cut short."""
    cut = text if len(text) <= limit else text[:limit] + "…"
    return repr(cut)[1:-1]


def _first_bad(text: str, allowed: re.Pattern, what: str) -> str:
    for i, c in enumerate(text):
        if not allowed.fullmatch(text[: i + 1]):
            return f"{c!r} (character {i + 1}) is not allowed in {what}" if i else f"{what} cannot start with {c!r}"
    return f"not {what}"


def _check(text: str, allowed: re.Pattern, limit: int, what: str) -> str | None:
    if not isinstance(text, str):
        return f"expected {what}, got {type(text).__name__}"
    if not text:
        return "it is empty"
    if len(text) > limit:
        return f"it has {len(text):,} characters (at most {limit})"
    if not allowed.fullmatch(text):
        return _first_bad(text, allowed, what)
    return None


def identifier_problem(text: str) -> str | None:
    return _check(text, _IDENTIFIER, MAX_NAME, "a name")


def variant_problem(text: str) -> str | None:
    return _check(text, _VARIANT, MAX_VARIANT, "a variant name")


def label_problem(text: str) -> str | None:
    return _check(text, _LABEL, MAX_NAME, "a library name")


def ros_package_problem(text: str) -> str | None:
    """REP 144's package names."""
    what = "a ROS package name"
    problem = _check(text, _ROS_PACKAGE, MAX_PACKAGE, what)
    if problem is None and ("__" in text or text.endswith("_")):
        problem = f"{what} has single underscores, not at the end"
    return problem


def text_problem(text: str) -> str | None:
    if not isinstance(text, str):
        return f"expected text, got {type(text).__name__}"
    if len(text) > MAX_TEXT:
        return f"it has {len(text):,} characters (at most {MAX_TEXT})"
    for i, c in enumerate(text):
        if unicodedata.category(c) in _BAD_CATEGORIES:
            return f"control character {c!r} (character {i + 1}) is not allowed in text"
    return None
