"""The .mod language for the language server and the editor grammars.

What the grammar says is read from it (grammar/modc.lark through Lark's rules): which keywords
open a block, start a statement or a clause, which take a name, each keyword's syntax. What only
the model knows is written here, in words: the hover text of keywords, parameters and units of
measure, and which kind of quantity follows a keyword. Tests check that every keyword and every
value-taking keyword of the grammar has its entry.
"""

from __future__ import annotations

from ..model import lower, quantities

# The grammar's facts (keyword classes, name takers, syntax) are read in modc.syntax.keywords.
from ..syntax.keywords import (  # noqa: F401  (re-exported for the language server's modules)
    all_keywords,
    clause_keywords,
    declaration_keywords,
    grammar,
    keyword_of,
    literal_of,
    name_takers,
    statement_keywords,
    statements,
    syntax_of,
    terminal_of,
    value_keywords,
)


def reset() -> None:
    """Forget what was read from the grammar (tests that swap the grammar call this)."""
    from ..syntax import keywords
    from . import tolerant

    keywords.reset()
    tolerant._restart.cache_clear()
    tolerant._block_for.cache_clear()


# --- what the model knows ----------------------------------------------------------------------

# The kind of quantity after a value keyword (value_keywords(); a test keeps them in step).
QUANTITY_KINDS = {
    "at": "a length",
    "size": "a length",
    "radius": "a length",
    "length": "a length",
    "rpy": "an angle",
    "pose": "an angle",
    "limit": "an angle",
    "payload": "a mass",
    "within": "a length",  # then an angle: `within 5 mm, 2 deg`
    "links": "a length",
    "to": "a length",  # `links 150 mm to 300 mm` (`units 1 to 3` takes plain numbers)
    "step": "a length",
    "yaw": "an angle",  # `base within … yaw 0 to 90 deg step 45 deg`
    "pointing": "a direction",  # `pointing (0, 0, -1)`: no unit
    "turned": "an angle",  # a region's `turned (0, 0, 45) deg`
}
# Name-taking statements whose name refers to something (a joint) rather than declaring one.
REFERS = frozenset({"limit", "rank"})  # rank names objectives, not things it declares

KEYWORDS = {
    "robot": "`robot NAME { … }` — one arm; a file holds one or more robot blocks.",
    "chain": "`chain H1 - H4(pivot=-90deg) - L4` — the modular units, base first (required unless a `dh` table is "
    "given).",
    "dh": "`dh [fit-links] { row a=…, alpha=…, d=… … }` — a standard DH table that modc turns into a chain of "
    "units (paper section 4.2).",
    "row": "`row a=0.3 m, alpha=-90deg, d=0 m[, theta=0deg]` — one row of a `dh` table (standard DH), base first.",
    "fit-links": "`dh fit-links { … }` — print link modules whose length realises each row's `a` exactly.",
    "library": '`library mark2` | `library mark2-strict` | `library "path.yaml"` — '
    "the module library this robot is built from (default mark2).",
    "base": "`base at (x, y, z) m rpy (r, p, y) deg` — where base_link sits in the cell (for simulation and planning); "
    "in a design block, `base within box size (…) m at (…) m step 50 mm [yaw 0 to 90 deg step 45 deg]` lets the "
    "search place it.",
    "tool": "`tool at (x, y, z) m rpy (r, p, y) deg` — tool0 relative to the last unit's last frame.",
    "payload": "`payload 0.2 kg at (x, y, z) m` — a payload's mass and its centre of mass in tool0.",
    "pose": "`pose NAME (q1, …, qn) deg` — a named joint pose, one angle per joint; `home` is the robot's home pose.",
    "limit": "`limit joint_N (lower, upper) deg` — narrow joint N's range (within the library's).",
    "box": "`box NAME size (x, y, z) m at (x, y, z) m [rpy (…) deg]` — a box obstacle in base_link (size = full "
    "edge lengths).",
    "sphere": "`sphere NAME radius R m at (x, y, z) m` — a sphere obstacle in base_link.",
    "cylinder": "`cylinder NAME radius R m length L m at (x, y, z) m [rpy (…) deg]` — a cylinder obstacle in "
    "base_link, axis along z before rpy.",
    "target": "`target NAME at (x, y, z) m [rpy (r, p, y) deg] [within 5 mm, 2 deg]` — a position (and orientation) "
    "for tool0, in base_link, with its tolerances.",
    "allow": "`allow first-variant, …` — silence one of the paper's assembly rules for this robot on purpose (e.g. "
    "for a wrist).",
    "at": "`at (x, y, z) m` — a position (in base_link for obstacles and targets, in tool0 for a payload).",
    "rpy": "`rpy (roll, pitch, yaw) deg` — an orientation as fixed-axis roll, pitch, yaw (as in URDF).",
    "size": "`size (x, y, z) m` — a box's full edge lengths.",
    "radius": "`radius R m` — the radius of a sphere or cylinder.",
    "length": "`length L m` — a cylinder's length along its axis.",
    "design": "`design NAME { … }` — a design problem for `modc design`: the cell and its targets, search bounds "
              "and objectives, no chain.",
    "units": "`units 1 to 3` — (design) how many units a chain may have.",
    "modules": "`modules H1, H3, L4` — (design) the unit types a chain may use.",
    "links": "`links 150 mm to 300 mm step 50 mm` — (design) the link-module lengths to try.",
    "rank": "`rank modules, mass, margin` — (design) the objectives in order of importance.",
    "compare": "`compare with chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)` — (design) a reference arm, "
    "checked on the cell as the designs are and shown beside them in report.html and ranking.json.",
    "with": "`compare with chain …` — (design) the reference arm's chain follows.",
    "to": "`… to …` — the upper end of a range (`units 1 to 3`, `links 150 mm to 300 mm`).",
    "step": "`step 50 mm` — the spacing of the link lengths a design search tries.",
    "within": "`within 5 mm, 2 deg` — a target's position (and orientation) tolerance (default 5 mm, 2°).",
    "region": "`region NAME box size (x, y, z) m at (x, y, z) m [turned (r, p, y) deg] grid NX x NY x NZ [rpy (…) deg] "
    "[within 5 mm, 2 deg]` — targets evenly spaced over a box, faces included, named NAME[i,j,k] (0-based).",
    "turned": "`turned (0, 0, 45) deg` — a region's box turned (fixed-axis rpy, as an obstacle's): its points turn "
    "with it; the tool's orientation (`rpy`, `pointing`) does not.",
    "task": "`task NAME { visit a, tray, tray[1,0,0] }` — collision-free joint-space motions through the targets (a "
    "region: its points in order); `modc plan FILE --task NAME` plans and times it.",
    "path": "`path NAME from a to b straight` — tool0 along the straight segment a -> b (orientation interpolated), "
    "within the targets' tolerances.",
    "grid": "`grid 3 x 2 x 1` — a region's number of points along x, y and z.",
    "visit": "`visit a, b, …` — the targets (or region points) a task goes through, in order.",
    "straight": "`straight` — the path is the straight segment between its ends.",
    "yaw": "`yaw 0 to 90 deg step 45 deg` — (design) the base yaws to try.",
}

# What each parameter does, in words; their names and kinds are the lowering's (model/lower.py).
PARAM_TEXT = {
    "pivot": (
        "turns the joint axis in the adaptive twist unit: a rotation about y before the joint "
        "(intersecting axes, the paper's type III twist)."
    ),
    "port": (
        "turns the next module where it meets the end of the link: a rotation about x (skew axes, "
        "the paper's type II twist). Only units with a link module (types 3 and 4)."
    ),
    "link": ("the printed link module's length (x23). Only units with a link module (types 3 and 4)."),
    "a": ("DH `a`: length of the common normal, along x_i (standard DH: Rz(θ) Tz(d) Tx(a) Rx(α))."),
    "alpha": ("DH `alpha`: twist about x_i between consecutive joint axes."),
    "d": ("DH `d`: offset along z_(i-1)."),
    "theta": ("DH `theta`: joint angle offset about z_(i-1) (default 0)."),
}
UNIT_PARAMS = tuple(lower.UNIT_PARAMS)
DH_PARAMS = tuple(lower.DH_PARAMS)
PARAMS = {name: (kind, PARAM_TEXT.get(name, "")) for name, kind in {**lower.UNIT_PARAMS, **lower.DH_PARAMS}.items()}
MEASURES = {
    **{u: ("an angle", n) for u, n in (("deg", "degrees"), ("rad", "radians"))},
    **{u: ("a length", n) for u, n in (("m", "metres"), ("cm", "centimetres"), ("mm", "millimetres"))},
    **{u: ("a mass", n) for u, n in (("kg", "kilograms"), ("g", "grams"))},
}
assert set(MEASURES) == set(quantities.ALL)
KIND_MEASURES = {kind: list(table) for kind, table in quantities.KINDS.items()}
KIND_MEASURES["a direction"] = []  # a `pointing` vector takes no unit


def keyword_doc(keyword: str) -> str:
    """Hover text of a keyword: its prose when written, else its syntax from the grammar."""
    return KEYWORDS.get(keyword) or f"`{syntax_of(keyword)}`"
