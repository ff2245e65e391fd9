"""The one registry of diagnostic codes.

Codes are stable kebab-case names (tests, CI annotations and editors rely on them), each with
its default severity, a message template and a hint template. A code is created once here and
raised anywhere with ``CODE.at(span, **fields)``.
"""
from __future__ import annotations

from enum import Enum
from typing import TYPE_CHECKING

from ..records import Record
from .span import Span

if TYPE_CHECKING:
    from .diagnostic import Diagnostic


class Severity(str, Enum):
    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


class Code(Record, kw_only=False):
    name: str
    severity: Severity
    summary: str  # one line for docs and `modc codes`
    message: str  # str.format template
    hint: str = ""
    allowable: bool = False  # may be silenced with `allow NAME` inside a robot block (assembly rules)

    def at(self, span: Span, **fields) -> Diagnostic:
        from .diagnostic import Diagnostic

        return Diagnostic(
            code=self.name,
            severity=self.severity,
            span=span,
            message=self.message.format(**fields),
            hint=self.hint.format(**fields) if self.hint else "",
        )


REGISTRY: dict[str, Code] = {}


def _register(
    name: str, severity: Severity, summary: str, message: str, hint: str = "", allowable: bool = False
) -> Code:
    assert name not in REGISTRY, name
    code = Code(name, severity, summary, message, hint, allowable)
    REGISTRY[name] = code
    return code


E, W, N = Severity.ERROR, Severity.WARNING, Severity.NOTE

# --- syntax ------------------------------------------------------------------------------------
SYNTAX_ERROR = _register("syntax-error", E, "the file does not follow the .mod grammar",
    "unexpected {found}; expected {expected}", "{hint}")
UNEXPECTED_CHARACTER = _register("unexpected-character", E, "a character that cannot start any token",
    "unexpected character {char!r}", "names are letters, digits and '_'; comments start with '#'")
UNCLOSED_BLOCK = _register("unclosed-block", E, "a `robot NAME {` block is never closed",
    "the file ends inside robot block '{name}'", "add '}}' to close the block")
MISSING_DASH = _register("missing-dash", E, "two units in a chain without '-' between them",
    "expected '-' between units in a chain, found {found}", "write units as H1 - H4 - L4")
MISSING_EQUALS = _register("missing-equals", E, "a unit parameter without '='",
    "expected '=' after parameter name, found {found}", "write parameters as (pivot=45deg, port=90deg)")
EXPECTED_STATEMENT = _register("expected-statement", E, "something that is not a statement inside a robot block",
    "expected a statement, found {found}",
    "statements are: {statements}")
EXPECTED_ROBOT = _register(
    "expected-robot",
    E,
    "top-level content outside a `robot NAME { … }` block",
    "expected 'robot NAME {{', found {found}",
    "every statement lives inside a robot block: robot arm {{ chain H1 - L1 }}",
)
EMPTY_FILE = _register("empty-file", W, "a file with no robot block",
    "no robot is defined in this file", "add a block such as: robot arm {{ chain H1 - L1 }}")
INPUT_TOO_LARGE = _register("input-too-large", E, "a file or chain beyond the size modc accepts",
    "{what} is too large ({size}; the limit is {limit})", "split the file or check that it is really a .mod file")
BAD_ENCODING = _register("bad-encoding", E, "a file that is not UTF-8 text",
    "the file is not UTF-8 text ({detail})", "save the file as UTF-8")

# --- quantities and lowering -------------------------------------------------------------------
MISSING_UNIT = _register("missing-unit", E, "a number written without its unit of measure",
    "{what} needs a unit", "write e.g. {example}")
WRONG_UNIT = _register("wrong-unit", E, "a unit of the wrong kind (a length where an angle belongs, …)",
    "{what} takes {kind}, not '{unit}'", "use one of: {allowed}")
UNKNOWN_UNIT_OF_MEASURE = _register("unknown-unit-of-measure", E, "a unit of measure modc does not know",
    "unknown unit '{unit}'", "use one of: {allowed}")
VECTOR_ARITY = _register("vector-arity", E, "a vector with the wrong number of components",
    "{what} takes {expected} values, got {got}", "write it as {example}")
UNKNOWN_PARAMETER = _register("unknown-parameter", E, "a parameter that does not exist (on a unit or a DH row)",
    "unknown parameter '{name}'", "parameters here are {allowed}{suggest}")
DUPLICATE_PARAMETER = _register("duplicate-parameter", E, "the same parameter twice on one unit",
    "parameter '{name}' is given twice", "keep one of them")
DUPLICATE_STATEMENT = _register("duplicate-statement", E, "a statement that may appear once, given twice",
    "'{what}' is given twice in {block}", "keep one of them")
MISSING_CHAIN = _register("missing-chain", E, "a robot block without a chain or DH table",
    "robot '{robot}' has no chain", "add e.g.: chain H1 - H4(pivot=-90deg) - L4, or a dh {{ row … }} table")
CHAIN_AND_DH = _register("chain-and-dh", E, "a robot with both a chain and a DH table",
    "robot '{robot}' has both a chain and a dh table", "keep one: the dh table is converted into a chain")
DH_ROW_INCOMPLETE = _register("dh-row-incomplete", E, "a DH row without a, alpha or d",
    "DH row {row} lacks {missing}", "write rows as: row a=0.3 m, alpha=90deg, d=0 m (theta optional)")
NOT_FINITE = _register("not-finite", E, "a value that is infinite or not a number",
    "{what} must be a finite number", "write an ordinary decimal number")
OUT_OF_RANGE = _register("out-of-range", E, "a quantity far beyond anything a modular arm can have",
    "{what} = {value} is out of range (at most {limit})", "check the number and its unit")

# --- YAML form ---------------------------------------------------------------------------------
YAML_SYNTAX = _register("yaml-syntax", E, "a YAML file that does not parse",
    "YAML syntax error: {detail}", "check indentation and quoting near this line")
YAML_SCHEMA = _register("yaml-schema", E, "a YAML document that does not match the modc schema",
    "{detail}", "`modc schema` prints the JSON Schema of the YAML form")

# --- library -----------------------------------------------------------------------------------
LIBRARY_NOT_FOUND = _register("library-not-found", E, "a module library that cannot be found",
    "module library '{name}' not found", "give a built-in name ({builtins}) or a path to a library YAML file")
LIBRARY_INVALID = _register("library-invalid", E, "a module library file that fails validation",
    "module library '{name}' is invalid: {detail}", "compare with libraries/mark2.yaml shipped with modc")

# --- units and parameters ----------------------------------------------------------------------
UNKNOWN_MODULE = _register("unknown-module", E, "a unit name that the library does not define",
    "unknown module unit '{name}'", "units are a variant letter and a type 1-4: {known}{suggest}")
PARAMETER_NOT_APPLICABLE = _register("parameter-not-applicable", E, "`port` or `link` on a unit without a link module",
    "'{param}' does not apply to {unit}: type {kind} units have no link module",
    "use type 3 or 4 ({variant}3, {variant}4) to get a link module, or drop '{param}'")
LINK_LENGTH_RANGE = _register("link-length-range", E, "a link length outside what the library can print",
    "link length {value} is outside {low}..{high}", "choose a length between {low} and {high}")
TOO_MANY_UNITS = _register("too-many-units", E, "more units in a chain than the library can assemble",
    "the chain has {n}; the library allows at most {max}", "modules are limited by ε per variant: {limits}")
TOO_FEW_UNITS = _register("too-few-units", E, "fewer units than the library's minimum",
    "the chain has {n}; at least {min} are needed", "add units to the chain")

# --- assembly rules (paper section 3) ----------------------------------------------------------
FIRST_VARIANT = _register("first-variant", E, "link 1 must be of the base variant (paper rule 1: H)",
    "the first unit is {unit}; the paper's rule 1 fixes link 1 as {want}", "start the chain with an {want} unit, "
    "or write `allow first-variant` for a sub-assembly such as a wrist", allowable=True)
LAST_VARIANT = _register(
    "last-variant",
    E,
    "link n must be of the end variant (paper rule 1: L)",
    "the last unit is {unit}; the paper's rule 1 fixes link n as {want}",
    "end the chain with an {want} unit",
    allowable=True,
)
ILLEGAL_SUCCESSION = _register(
    "illegal-succession",
    E,
    "a variant that may not follow the previous one (L→H)",
    "{after} may not follow {before} (paper rules 2-3: {allowed})",
    "heavier modules go nearer the base",
    allowable=True,
)
EPSILON_EXCEEDED = _register(
    "epsilon-exceeded",
    E,
    "more modules of one variant than ε allows",
    "{count} {variant} modules exceed ε = {eps} (paper rule 4, Table 1)",
    "replace some {variant} units or use another variant",
    allowable=True,
)

# --- twists ------------------------------------------------------------------------------------
TWIST_NOT_REALISABLE = _register("twist-not-realisable", E, "a twist the library's hardware cannot set",
    "{what} {value} cannot be set: {reason}", "nearest realisable value: {nearest}")

# --- DH conversion (paper section 4.2) ---------------------------------------------------------
TWIST_ROUNDED = _register("twist-rounded", W, "a DH twist the modules can only approximate",
    "DH row {row}: alpha {requested} is realised as {realised} ({where})", "the library sets twists in steps of {step}")
DH_APPROXIMATION = _register("dh-approximation", N, "how closely the converted modules realise a DH table",
    "robot '{robot}' realises its DH table within |da| <= {da}, |dalpha| <= {dalpha}, |dd| <= {dd}",
    "{hint}")
DH_CSV_HEADER = _register(
    "dh-csv-header",
    E,
    "a DH CSV file whose header is not a,alpha,d,theta",
    "the header must name the columns a, alpha, d, theta; found {found}",
    "the first line reads: a,alpha,d,theta (metres and radians)",
)
DH_CSV_VALUE = _register(
    "dh-csv-value",
    E,
    "a DH CSV cell that is not a finite number",
    "row {row}, column '{column}': {problem}",
    "cells are plain numbers: metres for a and d, radians for alpha and theta",
)
DH_EMPTY = _register("dh-empty", E, "a DH table (CSV file or dh block) without complete rows",
    "the DH table has no rows", "add one row per joint, base first")

# --- torque (paper section 3: epsilon comes from a worst-case torque analysis) -------------------
TORQUE_OVER_PEAK = _register(
    "torque-over-peak",
    E,
    "a joint whose worst static gravity torque exceeds its actuator's peak",
    "{joint} ({unit}) must hold {tau} against gravity at q = {pose}, above its peak {tau_max}",
    "use a stronger module there, shorter links or a lighter payload{eps}",
)
TORQUE_OVER_NOMINAL = _register(
    "torque-over-nominal",
    W,
    "a joint whose worst static gravity torque exceeds its nominal torque",
    "{joint} ({unit}) must hold {tau} against gravity at q = {pose}, above its nominal {tau_nom} (peak {tau_max})",
    "the actuator can hold this only briefly; use a stronger module, shorter links or a lighter payload{eps}",
)
EPSILON_DISAGREES = _register("epsilon-disagrees", N, "the paper's ε rule and the torque check disagree",
    "{message}", "ε is the paper's rule of thumb; the torque check is the physics behind it")
BAD_PAYLOAD = _register("bad-payload", E, "a --payload value that is not a mass",
    "--payload {value!r} is not a mass", "write e.g. --payload 0.5kg or --payload 500g (a plain number means kg)")

TRAJ_INVALID = _register(
    "traj-invalid",
    E,
    "a trajectory file that does not fit the format or the robot",
    "{detail}",
    'a trajectory is {{"joint_names": [...], "points": [{{"t": s, "q": [rad, ...]}}, ...]}}, '
    "as `modc plan --json` prints",
)

# --- planning: `modc plan` (exit 1; 2 for names given on the command line) ----------------------
TARGET_UNKNOWN = _register("target-unknown", E, "`plan --to` naming a target the robot does not declare",
    "robot {robot} has no target '{target}'", "{known}")
POSE_UNKNOWN = _register("pose-unknown", E, "`plan --start` naming a pose the robot does not declare",
    "robot {robot} has no pose '{pose}'", "{known}")
ROBOT_UNKNOWN = _register("robot-unknown", E, "`--robot` naming no robot of the file, or a target several robots have",
    "{detail}", "{known}")
START_IN_COLLISION = _register("start-in-collision", E, "the pose a plan starts from is in collision",
    "the start pose '{pose}' collides: {contacts}", "{hint}")
TARGET_UNREACHABLE = _register("target-unreachable", E, "a target tool0 cannot reach within the joint limits",
    "target '{target}' is out of reach, {why}", "{hint}")
TARGET_IN_COLLISION = _register("target-in-collision", E, "a target the arm reaches only in collision",
    "target '{target}' is reachable only in collision: {contacts}", "{hint}")
NO_PATH = _register("no-path", E, "no collision-free motion to a target was found",
    "no collision-free path from '{pose}' to target '{target}' found ({detail})", "{hint}")
TARGET_OUT_OF_REACH = _register("target-out-of-reach", W, "a target no joint angles can bring tool0 to",
    "target '{target}' is out of reach: it is {distance} m from joint_1, and tool0 is always {bound}", "{hint}")

# --- names, poses, limits, environment ---------------------------------------------------------
DUPLICATE_ROBOT = _register("duplicate-robot", E, "two robots with one name in a file",
    "robot '{name}' is defined twice", "rename one of them; output files are named after robots")
INVALID_NAME = _register("invalid-name", E, "a name that is not an identifier, or too long",
    "{what} name '{name}' is not allowed: {problem}",
    "names are {rule}: they become XML, file and ROS names")
DUPLICATE_NAME = _register("duplicate-name", E, "two poses, targets or obstacles with one name",
    "'{name}' is already defined in {block}", "names of poses, targets and obstacles must be unique")
POSE_ARITY = _register("pose-arity", E, "a pose with the wrong number of joint values",
    "pose '{name}' has {got}; robot '{robot}' has {dof}", "give one angle per joint, base first")
POSE_OUT_OF_LIMITS = _register("pose-out-of-limits", E, "a pose outside the joint limits",
    "pose '{name}': joint_{joint} = {value} is outside its limits {low}..{high}", "change the pose or the joint limit")
UNKNOWN_JOINT = _register("unknown-joint", E, "a joint name that does not exist",
    "robot '{robot}' has no joint '{name}'", "joints are named joint_1 … joint_{dof}")
LIMIT_ORDER = _register("limit-order", E, "a joint limit whose lower bound is not below its upper bound",
    "limit for {joint}: lower {low} is not below upper {high}", "write the limit as (lower, upper)")
LIMIT_DISJOINT = _register(
    "limit-disjoint",
    E,
    "a joint limit that does not overlap the module's range at all",
    "limit for {joint} ({low}..{high}) lies outside the module's range {hlow}..{hhigh}",
    "give a range inside {hlow}..{hhigh}",
)
LIMIT_EXCEEDS_HARDWARE = _register("limit-exceeds-hardware", W, "a joint limit wider than the module's range",
    "limit for {joint} ({low}..{high}) is wider than the module's range {hlow}..{hhigh}",
    "the library's range is used where yours is wider")
NONPOSITIVE_SIZE = _register("nonpositive-size", E, "an obstacle size, radius or mass that is zero or negative",
    "{what} must be positive, got {value}", "give a positive value")
UNKNOWN_ALLOW = _register("unknown-allow", E, "`allow` naming a code that cannot be silenced",
    "'{name}' cannot be allowed", "allowable codes: {allowable}")

# --- tasks (region, task, path, base within; docs/language.md) -----------------------------------
REGION_GRID = _register("region-grid", E, "a region's grid that gives no points, or absurdly many",
    "{what}", "{hint}")
UNKNOWN_TASK_TARGET = _register("unknown-task-target", E, "a task or path naming no target or region point",
    "{kind} '{name}' names '{ref}', {why}", "{known}")
TASK_NO_MOTION = _register("task-no-motion", W, "a task or path with nothing to move between",
    "{kind} '{name}' has no motion: {why}",
    "a task visits two or more places, a straight path joins two different points")
BASE_WITHIN_ROBOT = _register("base-within-robot", E, "`base within` in a robot block",
    "`base within` belongs in design blocks: robot '{robot}' stands at one base pose",
    "write the pose as `base at (x, y, z) m [rpy (r, p, y) deg]`, or move the statement into a `design` block")
TASK_UNKNOWN = _register("task-unknown", E, "`plan --task` naming a task the robot does not declare",
    "robot {robot} has no task or path '{task}'", "{known}")
TASK_SEGMENT_FAILED = _register("task-segment-failed", E, "a segment of a task that cannot be planned or timed",
    "{kind} '{task}', segment {segment}: {detail}", "{hint}")

# --- design problems (`design NAME { … }`, modc design) -----------------------------------------
DESIGN_BOUND = _register("design-bound", E, "a search bound of a design block that cannot be searched",
    "{what}", "{hint}")
UNKNOWN_OBJECTIVE = _register("unknown-objective", E, "`rank` naming an objective modc does not know",
    "unknown objective '{name}'", "objectives are {known}, written in order of importance")
DUPLICATE_OBJECTIVE = _register("duplicate-objective", E, "`rank` naming one objective twice",
    "objective '{name}' is ranked twice in {block}",
    "name each objective once, in order of importance (the first place counts)")
OBJECTIVE_NEEDS_TASK = _register("objective-needs-task", E, "`rank` naming a task objective in a cell without a task",
    "objective '{name}' ranks the cell's tasks, but design '{block}' has no `task` and no `path`",
    "add `task NAME {{ visit a, b }}` or `path NAME from a to b straight`, or rank by {static}")
DESIGN_NO_TARGETS = _register("design-no-targets", E, "a design block without any target",
    "design '{name}' has no targets: nothing to design the arm for", "add `target NAME at (x, y, z) m` to the block")
NO_DESIGN = _register("no-design", E, "`modc design` found no chain that does every task of the cell",
    "no design of {units} does every task of '{name}': {closest}",
    "widen the search (more units, more module types, other link lengths) or move the targets")

# --- command line / IO (rendered like the others, exit code 2) ---------------------------------
FILE_NOT_FOUND = _register("file-not-found", E, "an input file that cannot be read",
    "cannot read '{path}': {detail}", "check the path")
OUTPUT_NOT_MODC = _register("output-not-modc", E, "an output directory that modc did not create",
    "'{path}' is not modc's output: {found}",
    "modc replaces only a directory it wrote (listed, unchanged, in its .modc-manifest.json); choose a new or "
    "empty directory, or pass --force to replace it and everything in it")
OUTPUT_UNSAFE = _register("output-unsafe", E, "an output directory modc never replaces, even with --force",
    "'{path}' is {what}; replacing it would delete it", "{hint}")
OUTPUT_UNWRITABLE = _register("output-unwritable", E, "an output directory modc cannot create or write",
    "cannot write '{path}': {why}", "choose a directory you may write, e.g. -o out/ under your working directory")
UNSUPPORTED_INPUT = _register("unsupported-input", E, "an input file type modc cannot read",
    "'{path}' is neither .mod nor .yaml/.yml", "pass a .mod file or its YAML form")

del E, W, N
