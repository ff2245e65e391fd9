"""The pipeline, end to end: source -> AST -> model -> passes -> backends -> files on disk."""
from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from .diagnostics import Diagnostic, Span, codes
from .diagnostics.errors import InputError, SourceError
from .model import Design
from .model.lower import lower
from .passes import Context, run_all
from .records import Record, field
from .syntax import ast

YAML_SUFFIXES = (".yaml", ".yml")
# What `modc FILE -o OUT` and `modc check` analyse beyond the checks lint runs.
COMPILE_ANALYSES = frozenset({"torque"})


class Checked(Record, kw_only=False, frozen=False):
    """A checked design, its diagnostics and the source texts they point into."""

    design: Design
    diagnostics: list[Diagnostic]
    sources: dict[str, str] = field(default_factory=dict)
    tree: ast.File | None = None  # the parse the design was lowered from (the LSP reuses it)

    @property
    def ok(self) -> bool:
        return not any(d.is_error for d in self.diagnostics)


def read_source(path: str | os.PathLike) -> str:
    """The text of an input file. Only regular files are read, and at most MAX_BYTES + 1 bytes of
    them (a link to /dev/zero or a FIFO is refused at once). InputError when it cannot be read;
    SourceError when it is too large or not UTF-8. A lone CR is read as a line end."""
    from .files import read_bounded
    from .syntax.parser import MAX_BYTES, normalize_newlines

    p = str(path)
    try:
        data, size = read_bounded(p, MAX_BYTES)
    except OSError as e:
        raise InputError(codes.FILE_NOT_FOUND.at(Span.point(p), path=p, detail=e.strerror or str(e))) from None
    if size > MAX_BYTES:
        raise SourceError(codes.INPUT_TOO_LARGE.at(Span.point(p), what="the file", size=f"{size:,} bytes",
                                                   limit=f"{MAX_BYTES:,} bytes"))
    try:
        return normalize_newlines(data.decode("utf-8-sig"))
    except UnicodeDecodeError as e:
        # line and column in characters, counting line ends as the parser does
        before = normalize_newlines(data[: e.start].decode("utf-8-sig"))
        line = before.count("\n") + 1
        col = len(before) - (before.rfind("\n") + 1) + 1
        at = Span(p, line, col, line, col + 1, len(before), len(before) + 1)
        diag = codes.BAD_ENCODING.at(at, detail=f"byte 0x{data[e.start]:02x}")
        raise SourceError(diag, normalize_newlines(data.decode("utf-8-sig", errors="replace"))) from None


def parse_text(text: str, path: str) -> tuple[ast.File, list[Diagnostic]]:
    if path.endswith(YAML_SUFFIXES):
        from .syntax.yaml_form import parse_yaml

        return parse_yaml(text, path)
    from .syntax import parse

    return parse(text, path)


def check_text(text: str, path: str = "<string>", library: str | None = None,
               before_analyses: Callable[[Design], object] | None = None, **options) -> Checked:
    """Parse, lower and run the passes. options go to the pass Context (analyses=…, torque_severity=…).
    before_analyses(design) is called once the checks have run, before the analyses (which may
    write modc's caches: check_compile protects the inputs the checks found there)."""
    from .syntax.parser import normalize_newlines

    text = normalize_newlines(text)  # the same length: offsets into the original stay right
    tree, diags = parse_text(text, path)
    if "torque" in options.get("analyses", ()) and "torque_analysis" not in options:
        from .dynamics.torque import analyse  # the passes run it, but only the compiler imports the physics

        options["torque_analysis"] = analyse
    ctx = Context(diagnostics=diags, library_override=library, **options)
    design = lower(tree, ctx.diagnostics)
    if before_analyses is None:
        design = run_all(design, ctx)
    else:
        from .passes import PASSES, check_torque

        first = PASSES.index(check_torque)  # the first pass that runs an analysis the driver hands in
        for p in PASSES[:first]:
            design = p.run(design, ctx)
        before_analyses(design)
        for p in PASSES[first:]:
            design = p.run(design, ctx)
    return Checked(design, ctx.diagnostics, {**ctx.sources, path: text}, tree)


def check_file(path: str | os.PathLike, library: str | None = None,
               before_analyses: Callable[[Design], object] | None = None, **options) -> Checked:
    p = str(path)
    if not p.endswith((".mod", *YAML_SUFFIXES)):
        raise InputError(codes.UNSUPPORTED_INPUT.at(Span.point(p), path=p))
    try:
        text = read_source(p)
    except SourceError as e:
        from .model import Design

        return Checked(Design(path=p), [e.diagnostic], {p: e.text} if e.text is not None else {})
    return check_text(text, p, library, before_analyses, **options)


def check_compile(file: str | os.PathLike, library: str | None = None, **options) -> tuple[Checked, list[str]]:
    """check_file with analyses (options as check_file's), and the command's inputs (inputs_of)
    from the same check: FILE and --library are protected from modc's caches at once, the library
    files the robots use as soon as the checks have found them, before the analyses write to the
    caches. One parse and one check where inputs_of, then check_file, made two. An unreadable
    FILE raises InputError as check_file does (FILE protected already)."""
    inputs = inputs_of(file, library, check=False)

    def found(design: Design) -> None:
        inputs[:] = inputs_of(file, library, Checked(design, []))

    return check_file(file, library, before_analyses=found, **options), inputs


def build(checked: Checked, only: list[str] | None = None, **options) -> dict[str, str | bytes]:
    """Run the backends over a design without errors. Nothing touches the disk.
    options set Build fields (collision_samples=…, seed=…)."""
    from .backends import Build, load_all

    assert checked.ok, "build() needs a design without errors"
    backends = load_all()
    names = [n for n in backends if only is None or n in only or n == "report"]
    b = Build(checked.design, diagnostics=list(checked.diagnostics), **options)
    for name in names:
        for rel, content in backends[name].emit(b).items():
            b.files[rel] = content
    return dict(sorted(b.files.items()))


_BUILDS = "builds"  # modc's cache: whole builds (build_cached)
KEEP_BUILDS = 16  # the newest builds kept: editing one file and compiling it again and again stays small


def build_cached(checked: Checked, only: list[str] | None = None, **options) -> dict[str, str | bytes]:
    """build(), its files kept in modc's cache under a digest of everything it reads: the checked
    design (libraries and torque results included), the warnings, the sources, the options, the
    working directory and modc's own code. A hit (a compile of an unchanged file) imports no
    numpy, jinja2 or pinocchio; a damaged entry is built again, never trusted."""
    import marshal

    from . import cache

    name = _build_key(checked, only, options)
    payload = cache.get_checked(_BUILDS, name)
    if payload is not None:
        try:
            files = marshal.loads(payload)
        except (ValueError, EOFError, TypeError):
            files = None
        if isinstance(files, dict) and all(isinstance(k, str) and isinstance(v, str | bytes) for k, v in files.items()):
            return files
    files = build(checked, only, **options)
    cache.put_checked(_BUILDS, name, marshal.dumps(files))
    cache.prune(_BUILDS, ".build", KEEP_BUILDS)
    return files


def _build_key(checked: Checked, only: list[str] | None, options: dict) -> str:
    from . import cache
    from ._version import __version__
    from .records import as_plain

    design = checked.design
    return cache.key(__version__, _code_stamp(), repr(as_plain(design, hidden=False)),
                     repr([r.torque for r in design.robots]), repr(checked.diagnostics),
                     repr(sorted(checked.sources.items())), repr(only), repr(sorted(options.items())),
                     os.getcwd()) + ".build"


def _code_stamp(root: str | None = None) -> str:
    """modc's own files as installed (name, size, modification time): a changed template or
    backend is another build. (os.scandir, not os.walk and path joins: this runs on every compile,
    a cached one too, over ~180 files.)"""
    stamp: list[str] = []

    def walk(folder: str, rel: str) -> None:
        with os.scandir(folder) as it:
            entries = sorted(it, key=lambda e: e.name)
        for e in entries:
            if e.is_dir():
                if e.name != "__pycache__" and not e.is_symlink():  # as os.walk: a linked folder is not entered
                    walk(e.path, f"{rel}{e.name}/")
            elif not e.name.endswith((".pyc", ".pyo")):
                st = e.stat()
                stamp.append(f"{rel}{e.name}:{st.st_size}:{st.st_mtime_ns}")

    walk(root or os.path.dirname(os.path.abspath(__file__)), "")
    return "\n".join(stamp)


def write_tree(files: dict[str, str | bytes], out: str | os.PathLike, force: bool = False,
               inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Write files into a fresh directory next to OUT and exchange it with OUT atomically, when
    the one output rule allows it: modc.outputs.write_tree (never an input, a folder holding
    one, the working directory; a foreign OUT only with force)."""
    from .outputs import write_tree as write

    write(files, out, force, inputs)


def inputs_of(file: str | os.PathLike, library: str | None = None, checked: Checked | None = None,
              more: Iterable[str | os.PathLike] = (), check: bool = True) -> list[str]:
    """Every input file of a command: FILE, the --library file, each library file FILE's robots
    and design blocks use (from checked, a modc.compiler.Checked; found by checking FILE when not
    given, unless check is False), and `more` (a trajectory file). Built-in libraries ship with
    modc and are left out. They are protected from the caches (protect) from this call on."""
    from .model import library as lib
    from .outputs import protect

    found = [os.fspath(file), *(os.fspath(m) for m in more)]
    if library and library not in lib.BUILTIN:
        found.append(library)
    if checked is None and check:
        try:
            checked = check_file(file, library)
        except (InputError, OSError, ValueError):  # the command itself reports an unreadable file
            checked = None
    if checked is not None:
        robots = [*checked.design.robots, *(p.cell for p in checked.design.problems)]
        for r in robots:
            ref = library or r.library_ref
            if ref in lib.BUILTIN:
                continue
            where = Path(r.library_dir) if r.library_dir and not library else None
            path = lib.resolve(ref, where)
            if path is not None:
                found.append(str(path))
    found = list(dict.fromkeys(found))
    protect(found)
    return found
