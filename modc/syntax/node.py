"""The base of the AST's node classes: what `@dataclass(frozen=True, slots=True)` gives them
(fields from the annotations, in order, positional or by keyword, defaults; equality and hash
over the fields; a repr; no assignment after __init__), made by one small generated
__init__ a class instead of dataclasses' code generation, which cost every command ~0.7 ms a
class, ~20 ms for the AST's 32 (benchmarks/bench_startup.py). Type checkers see dataclasses
(dataclass_transform).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from typing_extensions import dataclass_transform
else:
    def dataclass_transform(**_kw):
        return lambda cls: cls


@dataclass_transform(frozen_default=True)
class Node:
    _fields: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        annotations = cls.__dict__.get("__annotations__", {})
        fields = tuple(n for n, a in annotations.items() if not str(a).startswith("ClassVar"))
        defaults = {n: cls.__dict__[n] for n in fields if n in cls.__dict__}
        if any(n not in defaults for n in fields[len(fields) - len(defaults):]):
            raise TypeError(f"{cls.__name__}: a field without a default follows one with a default")
        params = "".join(f", {n}=_default_{n}" if n in defaults else f", {n}" for n in fields)
        body = "".join(f"    _set(self, {n!r}, {n})\n" for n in fields) or "    pass\n"
        scope = {"_set": object.__setattr__, **{f"_default_{n}": v for n, v in defaults.items()}}
        exec(f"def __init__(self{params}):\n{body}", scope)  # noqa: S102 - names are the class's own fields
        scope["__init__"].__qualname__ = f"{cls.__qualname__}.__init__"
        setattr(cls, "__init__", scope["__init__"])  # noqa: B010 - a method made for this class
        cls._fields = fields
        setattr(cls, "__match_args__", fields)  # noqa: B010

    def _values(self) -> tuple:
        return tuple(getattr(self, n) for n in self._fields)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Node) or other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        inner = ", ".join(f"{n}={getattr(self, n)!r}" for n in self._fields)
        return f"{type(self).__qualname__}({inner})"

    def __setattr__(self, name: str, value: Any) -> None:
        from dataclasses import FrozenInstanceError

        raise FrozenInstanceError(f"cannot assign to field '{name}'")

    def __delattr__(self, name: str) -> None:
        from dataclasses import FrozenInstanceError

        raise FrozenInstanceError(f"cannot delete field '{name}'")

    def __getstate__(self) -> tuple:  # copy and pickle, past the frozen __setattr__
        return self._values()

    def __setstate__(self, state: tuple) -> None:
        for n, v in zip(self._fields, state, strict=True):
            object.__setattr__(self, n, v)


def fields(node: Node) -> tuple[str, ...]:
    """The node's field names, in order."""
    return node._fields


def replace(node: Node, **changes: Any) -> Node:
    """A copy of node with some fields changed (dataclasses.replace)."""
    return type(node)(**{n: changes.get(n, getattr(node, n)) for n in node._fields})
