"""What the checked model's types (modc.model.robot) share: a record base that checks names and
converts numbers and sequences when a value is built, and the methods of pydantic's models
(which these types were) that callers use."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar, TypeVar

from .. import names
from ..records import Record, as_plain, field


class InvalidModel(ValueError):
    """A model value that breaks the model's own rules (a bad name): lowering reports these as
    diagnostics first, so this is the guarantee that no backend sees one, not the user's path."""


def _identifier(text: str) -> str:
    problem = names.identifier_problem(text)
    if problem:
        raise InvalidModel(problem)
    return text


def vec3(v: Any) -> tuple[float, float, float]:
    x, y, z = v
    return (float(x), float(y), float(z))


def floats(v: Any) -> tuple[float, ...]:
    return tuple(float(x) for x in v)


def grid3(v: Any) -> tuple[int, int, int]:
    i, j, k = v
    return (int(i), int(j), int(k))


def optional(convert: Callable[[Any], Any]) -> Callable[[Any], Any]:
    return lambda v: None if v is None else convert(v)


def hidden(default: Any = None, *, default_factory: Callable[[], Any] | None = None) -> Any:
    """A field left out of repr and model_dump (spans, analyses' results)."""
    if default_factory is not None:
        return field(default_factory=default_factory, hidden=True)
    return field(default=default, hidden=True)


_T = TypeVar("_T", bound="Value")


class Value(Record):
    """The checked model's values: frozen records, checked when built (names, numbers as
    floats, sequences as tuples) and never after. The methods are those of pydantic's models
    (which these types were) that callers use."""

    _names: ClassVar[tuple[str, ...]] = ()  # fields that are identifiers
    _convert: ClassVar[tuple[tuple[str, Callable[[Any], Any]], ...]] = ()  # (field, to its type)

    def __post_init__(self) -> None:
        for f in self._names:
            _identifier(getattr(self, f))
        for f, convert in self._convert:
            object.__setattr__(self, f, convert(getattr(self, f)))

    def model_copy(self: _T, update: dict[str, Any] | None = None) -> _T:
        """A copy with some fields replaced, unchecked (as pydantic's model_copy)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        for k, v in (update or {}).items():
            if k not in new.__dict__:
                raise TypeError(f"{type(self).__name__} has no field {k!r}")
            new.__dict__[k] = v
        return new

    @classmethod
    def model_construct(cls: type[_T], **values: Any) -> _T:
        """An instance built unchecked, missing fields at their defaults (as pydantic's)."""
        new = object.__new__(cls)
        for name in cls._fields:
            if name in values:
                new.__dict__[name] = values[name]
            elif name in cls._defaults:
                new.__dict__[name] = cls._defaults[name]
            elif name in cls._factories:
                new.__dict__[name] = cls._factories[name]()
        return new

    def model_dump(self) -> dict[str, Any]:
        """The fields as plain values, spans and analyses' results left out."""
        return as_plain(self, hidden=False)


