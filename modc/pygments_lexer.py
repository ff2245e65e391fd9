"""Pygments lexer for the .mod language (grammar/modc.lark), for Sphinx, MkDocs, `pygmentize`.

Registered as the Pygments plugin `modc` (entry point group "pygments.lexers"), so
`pygments.lexers.get_lexer_by_name("modc")` and ```` ```mod ```` code blocks work once modc is
installed. The module imports nothing but Pygments (it also loads with
`pygments.lexers.load_lexer_from_file(path, "ModLexer")`).

Token types: `robot` Keyword.Declaration, the other keywords Keyword, unit names (H1 … L4)
Name.Builtin, units of measure (deg, rad, m, cm, mm, kg, g) Keyword.Type (as Pygments' CSS
lexer does for px, em …), numbers Number.Float, parameter names Name.Attribute, declared names
Name.Class (robot), Name.Function (pose, target), Name.Variable (obstacle, joint), library
names Name.Namespace, diagnostic codes after `allow` Name.Constant, comments Comment.Single.
The keyword lists below are compared with the Lark grammar by tests/test_editor_grammars.py.
"""

from __future__ import annotations

import re

from pygments.lexer import RegexLexer, bygroups, default, include, words
from pygments.token import (
    Comment,
    Keyword,
    Name,
    Number,
    Operator,
    Punctuation,
    String,
    Whitespace,
)

__all__ = ["ModLexer"]

#: Keyword that opens a robot block.
DECLARATIONS = ("design", "robot")
#: Keywords that start a statement inside a robot block (`row` starts a row of a `dh` block).
STATEMENTS = ("allow", "base", "box", "chain", "compare", "cylinder", "dh", "library", "limit", "links",
              "modules", "path", "payload", "pose", "rank", "region", "row", "sphere", "target", "task",
              "tool", "units")
#: Keywords inside a statement (`fit-links` is the grammar's named terminal DH_FIT).
CLAUSES = ("at", "fit-links", "from", "grid", "length", "pointing", "radius", "rpy", "size", "step",
           "straight", "to", "turned", "visit", "with", "within", "x", "yaw")
#: Every keyword of the language.
KEYWORDS = frozenset(DECLARATIONS + STATEMENTS + CLAUSES)
#: Units of measure (modc.model.quantities.ALL).
MEASURES = ("cm", "deg", "g", "kg", "m", "mm", "rad")

_NAME = r"[A-Za-z_][A-Za-z0-9_]*"
_NUMBER = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_MEASURE = words(MEASURES, suffix=r"(?![\w/])")
_WORD_END = r"(?![\w-])"


class ModLexer(RegexLexer):
    """The .mod robot description language of modc (MOIRs Mark-2 modular arms)."""

    name = "modc"
    aliases = ["mod", "modc"]
    filenames = ["*.mod"]
    mimetypes = ["text/x-modc"]

    tokens = {
        "common": [
            (r"\s+", Whitespace),
            (r"#.*?$", Comment.Single),
        ],
        "quantity": [
            (r"(" + _NAME + r")(\s*)(=)", bygroups(Name.Attribute, Whitespace, Operator)),
            (r"(" + _NUMBER + r")(\s*)" + _MEASURE.get(), bygroups(Number.Float, Whitespace, Keyword.Type)),
            (_NUMBER, Number.Float),
            (r"(\))(\s*)" + _MEASURE.get(), bygroups(Punctuation, Whitespace, Keyword.Type)),
            (r"[(),]", Punctuation),
        ],
        "root": [
            # a file: robot blocks
            include("common"),
            (r"(robot|design)(\s+)(" + _NAME + r")", bygroups(Keyword.Declaration, Whitespace, Name.Class)),
            (r"(robot|design)\b", Keyword.Declaration),
            (r"\{", Punctuation, "body"),
            (_NAME, Name),
        ],
        "body": [
            include("common"),
            (r"\}", Punctuation, "#pop"),
            (r"\{", Punctuation, "body"),  # task NAME { visit … }
            (r"[\[\]]", Punctuation),  # a region point: tray[1,0,0]
            (r"chain\b", Keyword, "chain"),
            (r"dh\b", Keyword, "dh"),
            (r"allow\b", Keyword, "allow"),
            (r'(library)(\s+)("[^"\n]*")', bygroups(Keyword, Whitespace, String.Double)),
            (r"(library)(\s+)([A-Za-z_][A-Za-z0-9_.-]*)", bygroups(Keyword, Whitespace, Name.Namespace)),
            (r"(pose|target)(\s+)(" + _NAME + r")", bygroups(Keyword, Whitespace, Name.Function)),
            (r"(region|task|path)(\s+)(" + _NAME + r")", bygroups(Keyword, Whitespace, Name.Function)),
            (r"(box)(\s+)(size)\b", bygroups(Keyword, Whitespace, Keyword)),  # region r box size, base within box size
            (r"(box|sphere|cylinder|limit)(\s+)(" + _NAME + r")", bygroups(Keyword, Whitespace, Name.Variable)),
            (words(DECLARATIONS, suffix=r"\b"), Keyword.Declaration),
            (words(STATEMENTS + CLAUSES, suffix=_WORD_END), Keyword),
            include("quantity"),
            (r'"[^"\n]*"', String.Double),
            (_NAME, Name),
        ],
        "chain": [
            # H1 - H4(pivot=-90deg) - L4, over any number of lines; ends at the next statement
            (r"\s+", Whitespace),
            (r"#.*?$", Comment.Single),
            (r"[A-Za-z]+[0-9]+\b", Name.Builtin),
            (r"-", Punctuation),
            (r"\(", Punctuation, "parameters"),
            default("#pop"),
        ],
        "parameters": [
            include("common"),
            (r"\)", Punctuation, "#pop"),
            include("quantity"),
        ],
        "dh": [
            include("common"),
            (r"fit-links" + _WORD_END, Keyword),
            (r"\{", Punctuation, ("#pop", "dh-rows")),
            default("#pop"),
        ],
        "dh-rows": [
            include("common"),
            (r"\}", Punctuation, "#pop"),
            (r"row\b", Keyword),
            include("quantity"),
        ],
        "allow": [
            # diagnostic codes up to the end of the line
            (r"[ \t]+", Whitespace),
            (r"[a-z][a-z0-9]*(?:-[a-z0-9]+)*", Name.Constant),
            (r",", Punctuation),
            default("#pop"),
        ],
    }

    def analyse_text(text):
        """A `robot NAME {` block: tells .mod robot files from Modula-2 modules."""
        if re.search(r"^\s*robot\s+[A-Za-z_]\w*\s*\{", text, re.MULTILINE):
            return 0.9 if re.search(r"\b(chain|dh)\b", text) else 0.5
        return 0.0
