"""Common mistakes, by example: Lark's match_examples labels a parse error with the code whose
examples fail in the same parser state. The examples double as documentation of the codes."""
from __future__ import annotations

EXAMPLES: dict[str, list[str]] = {
    "missing-dash": [
        "robot a { chain H1 H4 }",
        "robot a { chain H1 - H4 L4 }",
        "robot a { chain H1(pivot=90deg) H4 }",
        "robot a { chain H1 - H4(port=90deg) L4 }",
    ],
    "missing-equals": [
        "robot a { chain H1(pivot 90deg) }",
        "robot a { chain H1 - H4(port 45deg) }",
        "robot a { chain H1 - H4(pivot=90deg, port 45deg) }",
    ],
    "expected-statement": [
        "robot a { H1 - L1 }",
        "robot a { chain H1 - L1 foo }",
        "robot a { chain H1 - L1 pose home (0, 0) deg foo }",
        "robot a { 42 }",
        "robot a { chain H1 - L1 box b size (1, 1, 1) m at (0, 0, 0) m bar }",
    ],
    "expected-robot": [
        "chain H1 - L1",
        "robot a { chain H1 - L1 } chain",
        "robot a { chain H1 - L1 } }",
        "foo",
    ],
}

# What Lark calls a terminal -> what a user should read.
TERMINAL_NAMES = {
    "NAME": "a name",
    "UNIT_NAME": "a unit such as H1 or L4",
    "NUMBER": "a number",
    "MEASURE": "a unit of measure",
    "STRING": "a \"quoted path\"",
    "LIBRARY_REF": "a library name such as mark2",
    "CODE_NAME": "a diagnostic code such as first-variant",
    "$END": "end of file",
}

HINTS = {
    "UNIT_NAME": "units are written H1..H4 or L1..L4, e.g. chain H1 - H4 - L4",
    "NAME": "names start with a letter or '_'",
    "NUMBER": "write a number followed by its unit, e.g. 45deg or 0.22 m",
    "LPAR": "vectors are written as (x, y, z) followed by a unit",
    "LBRACE": "a robot is written: robot NAME { chain … }",
}
