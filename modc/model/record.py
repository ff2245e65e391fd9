"""Frozen records: the value types of the checked model and of the module library.

A record is what a frozen, keyword-only dataclass is (fields from the class's annotations,
defaults, equality and hash over the fields, a repr, no assignment after __init__), made without
dataclasses' code generation: that cost ~0.7 ms a class at import, about 20 ms of every command
for the model's and the library's 30 classes (benchmarks/bench_startup.py). Type checkers see
dataclasses (dataclass_transform).
"""
from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from typing_extensions import dataclass_transform
else:
    def dataclass_transform(**_kw):
        return lambda cls: cls

_MISSING: Any = object()


class Field:
    """A field's default (or factory), and whether repr and dumps leave it out (spans, caches)."""

    __slots__ = ("default", "default_factory", "hidden")

    def __init__(self, default: Any, default_factory: Callable[[], Any] | None, hidden: bool):
        self.default, self.default_factory, self.hidden = default, default_factory, hidden


def field(*, default: Any = _MISSING, default_factory: Callable[[], Any] | None = None, hidden: bool = False) -> Any:
    return Field(default, default_factory, hidden)


@dataclass_transform(kw_only_default=True, frozen_default=True, field_specifiers=(field,))
class Record:
    _fields: ClassVar[tuple[str, ...]] = ()
    _defaults: ClassVar[dict[str, Any]] = {}
    _factories: ClassVar[dict[str, Callable[[], Any]]] = {}
    _hidden: ClassVar[frozenset[str]] = frozenset()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        fields, defaults, factories = list(cls._fields), dict(cls._defaults), dict(cls._factories)
        hidden = set(cls._hidden)
        for name, annotation in cls.__dict__.get("__annotations__", {}).items():
            if str(annotation).startswith(("ClassVar", "typing.ClassVar")):
                continue
            if name not in fields:
                fields.append(name)
            value = cls.__dict__.get(name, _MISSING)
            if value is _MISSING:  # redeclared without a default (a narrower type): required, as in dataclasses
                defaults.pop(name, None)
                factories.pop(name, None)
                continue
            if isinstance(value, Field):
                delattr(cls, name)
                if value.hidden:
                    hidden.add(name)
                if value.default_factory is not None:
                    factories[name] = value.default_factory
                value = value.default
            if value is not _MISSING:
                defaults[name] = value
        cls._fields, cls._defaults, cls._factories, cls._hidden = tuple(fields), defaults, factories, frozenset(hidden)

    def __init__(self, **values: Any) -> None:
        d = self.__dict__
        for name in self._fields:
            if name in values:
                d[name] = values.pop(name)
            elif name in self._defaults:
                d[name] = self._defaults[name]
            elif name in self._factories:
                d[name] = self._factories[name]()
            else:
                raise TypeError(f"{type(self).__name__}() missing field '{name}'")
        if values:
            raise TypeError(f"{type(self).__name__}() got an unexpected field '{next(iter(values))}'")
        self.__post_init__()

    def __post_init__(self) -> None:
        """Checks and conversions of a new record (assign with object.__setattr__)."""

    def __setattr__(self, name: str, value: Any) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field '{name}'")

    def __delattr__(self, name: str) -> None:
        raise dataclasses.FrozenInstanceError(f"cannot delete field '{name}'")

    def _values(self) -> tuple:
        d = self.__dict__
        return tuple(d[name] for name in self._fields)

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        shown = ", ".join(f"{n}={self.__dict__[n]!r}" for n in self._fields if n not in self._hidden)
        return f"{type(self).__name__}({shown})"


def is_record(tp: Any) -> bool:
    return isinstance(tp, type) and issubclass(tp, Record)


def as_fields(r: Record) -> dict[str, Any]:
    """A record's fields by name, in order."""
    return {n: r.__dict__[n] for n in r._fields}


def as_plain(v: Any, hidden: bool = True) -> Any:
    """Records as dicts of their fields (hidden ones too, unless hidden=False), recursively."""
    if isinstance(v, Record):
        return {n: as_plain(v.__dict__[n], hidden) for n in v._fields if hidden or n not in v._hidden}
    if isinstance(v, tuple | list):
        return type(v)(as_plain(x, hidden) for x in v)
    if isinstance(v, dict):
        return {k: as_plain(x, hidden) for k, x in v.items()}
    return v
