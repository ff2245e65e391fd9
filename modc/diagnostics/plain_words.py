"""pydantic's validation errors in a file author's words.

Library files and the YAML form of a .mod file are validated by pydantic, whose messages name
Python types ("Input should be a valid dictionary or instance of Variant"). Both readers report
a failed check through this one table, with the error's own bounds ("at least 1").
"""
from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

_FIXED = {
    "model_type": "expected a mapping (key: value lines)",
    "dict_type": "expected a mapping (key: value lines)",
    "model_attributes_type": "expected a mapping (key: value lines)",
    "list_type": "expected a list",
    "tuple_type": "expected a list",
    "string_type": "expected text",
    "missing": "required but missing",
    "extra_forbidden": "unknown key",
    "float_type": "expected a number",
    "float_parsing": "expected a number",
    "int_type": "expected a whole number",
    "int_parsing": "expected a whole number",
    "int_from_float": "expected a whole number",
    "bool_type": "expected true or false",
    "bool_parsing": "expected true or false",
    "finite_number": "expected a finite number",
}

# constraint errors: the bound comes from the error's context
_BOUNDS = {
    "greater_than_equal": ("ge", "must be at least {}"),
    "greater_than": ("gt", "must be greater than {}"),
    "less_than_equal": ("le", "must be at most {}"),
    "less_than": ("lt", "must be less than {}"),
    "string_too_long": ("max_length", "must be at most {} characters long"),
    "too_long": ("max_length", "must have at most {} items"),
    "too_short": ("min_length", "must have at least {} items"),
}


def plain_words(err: Mapping[str, Any]) -> str:
    """One pydantic error (an item of ValidationError.errors()) as a short phrase."""
    kind = err.get("type", "")
    if kind in _FIXED:
        return _FIXED[kind]
    ctx = err.get("ctx") or {}
    if kind in _BOUNDS and _BOUNDS[kind][0] in ctx:
        key, text = _BOUNDS[kind]
        return text.format(ctx[key])
    message = str(err.get("msg", "")).removeprefix("Value error, ")
    return re.sub(r" or (an )?instance of \w+", "", message)
