"""The one record base (modc.records): the AST nodes and the model records behave as the frozen
dataclasses they replaced."""
from __future__ import annotations

import copy
import dataclasses
import pickle

import pytest

from modc.diagnostics import Span
from modc.records import fields, replace
from modc.syntax import ast

S = Span.point("t.mod")


def test_fields_in_order_positional_or_by_keyword_with_defaults():
    name, at = ast.Name("p", S), ast.Vector((0.1, 0.2, 0.3), "m", S)
    t = ast.Target(name, at, S)
    assert fields(t) == ("name", "at", "span", "rpy", "within", "pointing") == ast.Target.__match_args__
    assert (t.rpy, t.within, t.pointing) == (None, None, None)
    assert ast.Target(name=name, at=at, span=S, pointing=at).pointing is at
    with pytest.raises(TypeError):
        ast.Quantity(1.0, "m")  # a field missing
    with pytest.raises(TypeError):
        ast.Quantity(1.0, "m", S, 4)  # one too many


def test_equality_hash_repr_and_no_assignment():
    a, b = ast.Quantity(1.0, "m", S), ast.Quantity(1.0, "m", S)
    assert a == b and hash(a) == hash(b) and a != ast.Quantity(2.0, "m", S)
    assert a != ast.Name("m", S) and a != (1.0, "m", S)
    assert repr(a) == f"Quantity(value=1.0, unit='m', span={S!r})"
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.value = 2.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del a.unit  # type: ignore[misc]


def test_copy_pickle_and_replace():
    within = ast.Within(ast.Quantity(5, "mm", S), None, S)
    t = ast.Target(ast.Name("p", S), ast.Vector((1.0,), None, S), S, within=within)
    assert copy.deepcopy(t) == t and pickle.loads(pickle.dumps(t)) == t
    moved = replace(t, span=Span.point("u.mod"))
    assert moved.span.file == "u.mod" and moved.name is t.name and t.span is S


def test_class_patterns_match():
    match ast.Pose(ast.Name("home", S), ast.Vector((0.0,), "deg", S), S):
        case ast.Pose(name=ast.Name(text=text)):
            assert text == "home"
        case _:
            pytest.fail("no match")


def test_a_keyword_record_takes_any_field_name_and_fills_defaults_and_factories():
    """The model's records are keyword-only; a field may be called as the generated __init__'s
    own locals might be (DH's `d`), and a factory gives each record its own value."""
    from modc.records import Record, field

    class Row(Record):
        d: float
        a: float = 0.0
        notes: list = field(default_factory=list)

    r, s = Row(d=0.1), Row(d=0.1)
    assert (r.d, r.a, r.notes) == (0.1, 0.0, []) and r == s and r.notes is not s.notes
    with pytest.raises(TypeError):
        Row(0.1)  # type: ignore[misc]  # keyword-only
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.d = 0.2  # type: ignore[misc]


def test_a_mutable_record_takes_assignments_and_has_no_hash_as_a_plain_dataclass():
    """frozen=False: what @dataclass (not frozen) was for the compile's mutable values (Build,
    Description, Link)."""
    from modc.records import Record, field

    class Box(Record, kw_only=False, frozen=False):
        name: str
        items: list = field(default_factory=list)

    b = Box("a")
    b.name = "b"
    b.items.append(1)
    assert b == Box("b", [1]) and b != Box("b")
    with pytest.raises(TypeError):
        hash(b)
    del b.items
    assert not hasattr(b, "items")


def test_uncompared_and_not_init_fields_as_in_dataclasses():
    """field(compare=False) is outside equality and hash; field(init=False) is set by
    __post_init__ (or its default), never an __init__ parameter."""
    from modc.records import Record, field

    class Matrix(Record, kw_only=False):
        links: tuple
        stats: dict = field(default_factory=dict, compare=False)

    assert Matrix(("a",), {"n": 1}) == Matrix(("a",), {"n": 2})
    assert hash(Matrix(("a",))) == hash(Matrix(("a",), {"x": 0}))
    assert Matrix(("a",)) != Matrix(("b",))

    class Built(Record, kw_only=False, frozen=False):
        design: str
        count: int = field(default=3, init=False)
        robots: tuple = field(init=False)

        def __post_init__(self) -> None:
            self.robots = (self.design,) * self.count

    b = Built("arm")
    assert (b.robots, b.count) == (("arm",) * 3, 3) and fields(b) == ("design", "count", "robots")
    with pytest.raises(TypeError):
        Built("arm", robots=())  # type: ignore[call-arg]


def test_the_compile_path_builds_no_dataclass(tmp_path):
    """The first compile of a new arm builds records, not dataclasses (issue 25: each
    dataclass cost ~0.7 ms of start-up), and does not even import the dataclasses module."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    run = ("from modc.cli import main\n"
           "try:\n"
           "    main(sys.argv[1:])\n"
           "except SystemExit:\n"
           "    pass\n")
    spy = ("import dataclasses, sys\n"
           "made = []\n"
           "orig = dataclasses._process_class\n"
           "def spy(cls, *a, **k):\n"
           "    made.append(cls.__module__ + '.' + cls.__qualname__)\n"
           "    return orig(cls, *a, **k)\n"
           "dataclasses._process_class = spy\n" + run + "print('MADE', *made)\n")
    plain = "import sys\n" + run + "print('MODULE', 'dataclasses' in sys.modules)\n"
    root = Path(__file__).resolve().parents[1]
    env = {**os.environ, "PYTHONPATH": str(root), "MODC_CACHE_DIR": str(tmp_path / "cache")}
    args = [str(root / "examples" / "farm.mod"), "-o", str(tmp_path / "o")]
    out = [subprocess.run([sys.executable, "-c", probe, *args], env=env, capture_output=True, text=True,
                          cwd=tmp_path, check=True).stdout for probe in (spy, plain)]
    made = out[0].split("MADE", 1)[1].split()
    assert [m for m in made if m.startswith("modc.")] == []
    assert out[1].split("MODULE", 1)[1].split() == ["False"]
