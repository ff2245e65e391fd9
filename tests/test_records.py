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
