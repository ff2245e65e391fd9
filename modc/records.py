"""Frozen records: the value types of the AST, the checked model and the module library.

A record is what a frozen dataclass is (fields from the class's annotations, in order,
defaults, equality and hash over the fields, a repr, no assignment after __init__), made without
dataclasses' code generation: that cost ~0.7 ms a class at import, about 40 ms of every command
for the AST's, the model's and the library's ~60 classes (benchmarks/bench_startup.py). Fields
are keyword-only, as the model's are, unless the class says `kw_only=False` (the AST's nodes,
built positionally by the parser). A class saying `frozen=False` takes assignments and has no
hash, as a plain dataclass; a field(compare=False) is left out of equality and hash. Each class
gets one small generated __init__. Type checkers see dataclasses (dataclass_transform).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from typing_extensions import dataclass_transform
else:
    def dataclass_transform(**_kw):
        return lambda cls: cls

_MISSING: Any = object()


class Field:
    """A field's default (or factory), whether repr and dumps leave it out (spans, caches),
    whether equality and hash read it, and whether __init__ takes it (else __post_init__ sets it)."""

    __slots__ = ("default", "default_factory", "hidden", "compare", "init")

    def __init__(self, default: Any, default_factory: Callable[[], Any] | None, hidden: bool, compare: bool = True,
                 init: bool = True):
        self.default, self.default_factory, self.hidden = default, default_factory, hidden
        self.compare, self.init = compare, init


def field(*, default: Any = _MISSING, default_factory: Callable[[], Any] | None = None, hidden: bool = False,
          compare: bool = True, init: bool = True) -> Any:
    return Field(default, default_factory, hidden, compare, init)


@dataclass_transform(kw_only_default=True, frozen_default=True, field_specifiers=(field,))
class Record:
    _fields: ClassVar[tuple[str, ...]] = ()
    _defaults: ClassVar[dict[str, Any]] = {}
    _factories: ClassVar[dict[str, Callable[[], Any]]] = {}
    _hidden: ClassVar[frozenset[str]] = frozenset()
    _uncompared: ClassVar[frozenset[str]] = frozenset()
    _compared: ClassVar[tuple[str, ...]] = ()
    _not_init: ClassVar[frozenset[str]] = frozenset()

    def __init_subclass__(cls, kw_only: bool = True, frozen: bool = True, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        fields, defaults, factories = list(cls._fields), dict(cls._defaults), dict(cls._factories)
        hidden, uncompared, not_init = set(cls._hidden), set(cls._uncompared), set(cls._not_init)
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
                if not value.compare:
                    uncompared.add(name)
                if not value.init:
                    not_init.add(name)
                if value.default_factory is not None:
                    factories[name] = value.default_factory
                value = value.default
            if value is not _MISSING:
                defaults[name] = value
        cls._fields, cls._defaults, cls._factories, cls._hidden = tuple(fields), defaults, factories, frozenset(hidden)
        cls._uncompared, cls._not_init = frozenset(uncompared), frozenset(not_init)
        cls._compared = tuple(n for n in fields if n not in uncompared)
        if not frozen:  # a plain (mutable) dataclass's behaviour: assignments, and no hash
            cls.__setattr__ = object.__setattr__  # type: ignore[method-assign,assignment]
            cls.__delattr__ = object.__delattr__  # type: ignore[method-assign]
            cls.__hash__ = None  # type: ignore[assignment]
        cls.__init__ = _make_init(cls, not kw_only)  # type: ignore[method-assign]
        if not kw_only:
            setattr(cls, "__match_args__", cls._fields)  # noqa: B010 - mypy reads __match_args__ as fixed

    def __post_init__(self) -> None:
        """Checks and conversions of a new record (assign with object.__setattr__)."""

    def __init__(self, **values: Any) -> None:  # replaced in each subclass by _make_init's
        raise TypeError("Record is a base class")

    def __setattr__(self, name: str, value: Any) -> None:
        import dataclasses  # dataclasses' own error, imported when raised: its import is ~5 ms of start-up

        raise dataclasses.FrozenInstanceError(f"cannot assign to field '{name}'")

    def __delattr__(self, name: str) -> None:
        import dataclasses

        raise dataclasses.FrozenInstanceError(f"cannot delete field '{name}'")

    def _values(self) -> tuple:
        d = self.__dict__
        return tuple(d[name] for name in self._compared)

    def __eq__(self, other: object) -> bool:
        if other.__class__ is not self.__class__:
            return NotImplemented
        return self._values() == other._values()

    def __hash__(self) -> int:
        return hash(self._values())

    def __repr__(self) -> str:
        shown = ", ".join(f"{n}={self.__dict__[n]!r}" for n in self._fields if n not in self._hidden)
        return f"{type(self).__name__}({shown})"


def _make_init(cls: type[Record], positional: bool) -> Callable[..., None]:
    """The class's __init__: its fields as parameters (keyword-only unless positional), defaults
    and factories filled in, then __post_init__."""
    params, body = [], []
    scope: dict[str, Any] = {"_MISSING": _MISSING}
    for n in cls._fields:
        if n in cls._not_init:  # set by __post_init__, or its default's
            if n in cls._defaults or n in cls._factories:
                scope[f"_d_{n}"], scope[f"_f_{n}"] = cls._defaults.get(n), cls._factories.get(n)
                body.append(f"    _record_dict[{n!r}] = _f_{n}()\n" if n in cls._factories
                            else f"    _record_dict[{n!r}] = _d_{n}\n")
            continue
        if n in cls._defaults:
            scope[f"_d_{n}"] = cls._defaults[n]
            params.append(f"{n}=_d_{n}")
        elif n in cls._factories:
            scope[f"_f_{n}"] = cls._factories[n]
            params.append(f"{n}=_MISSING")
        else:
            params.append(n)
        body.append(f"    _record_dict[{n!r}] = _f_{n}() if {n} is _MISSING else {n}\n" if n in cls._factories
                    else f"    _record_dict[{n!r}] = {n}\n")
    if positional and any(p.count("=") == 0 for p in params[next((i for i, p in enumerate(params) if "=" in p),
                                                                  len(params)):]):
        raise TypeError(f"{cls.__name__}: a field without a default follows one with a default")
    head = ", ".join(params) if positional else ("*, " + ", ".join(params) if params else "")
    signature = f"def __init__(self{', ' if head else ''}{head}):\n"
    # (locals start with _record_ or _d_/_f_: a field may be called d, as DH's is)
    source = f"{signature}    _record_dict = self.__dict__\n{''.join(body)}    self.__post_init__()\n"
    exec(_compiled(source), scope)  # noqa: S102 - parameter names are the class's own field names (identifiers)
    init = scope["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    return init


_CODE: dict[str, Any] | None = None  # generated __init__ source -> its compiled code, this Python's
_CODE_KIND = "records"
_DIRTY = False  # code compiled by this process that the cache does not hold yet


def _compiled(source: str):
    """The code of a generated __init__: compiling the ~110 of them cost ~35 ms of every command, so
    their code objects are kept in modc's cache (marshal, this Python's version in the key, a
    digest checked on reading) and written back once at exit when new ones were made."""
    global _CODE, _DIRTY
    if _CODE is None:
        _CODE = _load_codes()
    code = _CODE.get(source)
    if code is None:
        if not _DIRTY:  # the first new one: save them all at exit
            import atexit

            atexit.register(_save_codes)
            _DIRTY = True
        code = _CODE[source] = compile(source, "<modc.records>", "exec")
    return code


def _codes_name() -> str:
    import sys

    from . import cache

    return cache.key(_CODE_KIND, sys.version, str(sys.implementation.cache_tag)) + ".marshal"


def _load_codes() -> dict[str, Any]:
    import marshal

    from . import cache

    try:
        payload = cache.get_checked(_CODE_KIND, _codes_name())
        codes = marshal.loads(payload) if payload is not None else {}
    except (OSError, ValueError, EOFError, TypeError):
        return {}
    if not isinstance(codes, dict):
        return {}
    code_type = type(_load_codes.__code__)
    return {k: v for k, v in codes.items() if isinstance(k, str) and isinstance(v, code_type)}


def _save_codes() -> None:
    import marshal

    from . import cache

    if _CODE is None:
        return
    try:
        cache.put_checked(_CODE_KIND, _codes_name(),
                          marshal.dumps(_CODE))
    except (OSError, ValueError):
        pass  # no cache: the next command compiles them again


def fields(r: Record) -> tuple[str, ...]:
    """The record's field names, in order."""
    return r._fields


def replace(r: Record, **changes: Any) -> Any:
    """A copy of the record with some fields changed (dataclasses.replace)."""
    return type(r)(**{n: changes.get(n, r.__dict__[n]) for n in r._fields})


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
