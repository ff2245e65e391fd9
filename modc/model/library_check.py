"""The boundary of the module library: a library file validated by pydantic against the types of
modc.model.library (pydantic models made from those records' annotations, here only), and a
content-keyed cache of the validated values.

A file whose validated values are in modc's cache (modc.cache, kind "library") is rebuilt from
them as records: no YAML parser, no pydantic (a cold `modc lint` pays neither). An entry
is keyed by the file's bytes, modc's version and the library's types; it carries a digest of its
content, and one that is torn, altered or of another shape is ignored and rewritten.
"""
from __future__ import annotations

import json
import typing
from functools import cache
from typing import Annotated, Any

from .._version import __version__
from ..diagnostics.plain_words import plain_words
from ..records import Record, as_fields, is_record
from . import library as L
from .library_file import MAX_LIBRARY_BYTES, LibraryError, read_library, where

_KIND = "library"
FORMAT = "1"  # the entry's layout

def load_file(path: str) -> L.Library:
    """The validated library in the file at path (resolved); LibraryError if it is none."""
    from ..files import read_bounded

    try:
        raw, size = read_bounded(path, MAX_LIBRARY_BYTES)
    except OSError:
        raw, size = b"", -1  # read_library says why
    name = _entry_name(raw) if 0 <= size <= MAX_LIBRARY_BYTES else None
    if name is not None:
        hit = _from_cache(name)
        if hit is not None:
            return hit
    library = validate(path)
    if name is not None:
        _store(name, library)
    return library


def validate(path: str) -> L.Library:
    from pydantic import ValidationError

    text, data = read_library(path)
    try:
        return _adapter().validate_python(data)
    except ValidationError as e:
        first = e.errors()[0]
        ranged = _range_error(first, text, path)
        if ranged is not None:
            raise ranged from None
        loc = ".".join(str(p) for p in first["loc"] if p != "[key]")
        message = plain_words(first)
        raise LibraryError(f"{loc}: {message}" if loc else message, where(text, path, first["loc"]), text) from None


@cache
def _adapter():
    from pydantic import TypeAdapter

    return TypeAdapter(_schema(L.Library))


def _schema(tp: Any) -> Any:
    """tp for pydantic: each record type as a pydantic model of its fields that, once valid, is
    made into the record (whose own checks then run: their ValueError is pydantic's too)."""
    if is_record(tp):
        return _model(tp)
    args = typing.get_args(tp)
    if typing.get_origin(tp) is Annotated:
        return Annotated[(_schema(args[0]),) + tuple(tp.__metadata__)]
    if typing.get_origin(tp) in (dict, list):
        return typing.get_origin(tp)[tuple(_schema(a) for a in args)]
    return tp


@cache
def _model(cls: type) -> Any:
    from pydantic import AfterValidator, ConfigDict, create_model

    hints = _hints(cls, extras=True)
    fields: dict[str, Any] = {n: (_schema(hints[n]), cls._defaults.get(n, ...)) for n in cls._fields}  # type: ignore[attr-defined]
    model = create_model(cls.__name__, __config__=ConfigDict(extra="forbid", allow_inf_nan=False), **fields)
    return Annotated[model, AfterValidator(lambda m: cls(**{n: getattr(m, n) for n in cls._fields}))]  # type: ignore[attr-defined]


def _range_error(err, text: str, path: str) -> LibraryError | None:
    """A number beyond its field's upper bound: out-of-range, as for .mod quantities."""
    ctx = err.get("ctx") or {}
    if err.get("type") != "less_than_equal" or "le" not in ctx:
        return None
    try:  # YAML 1.1 reads 1e308 (no dot) as text, which pydantic takes for a number
        value = float(err.get("input"))
    except (TypeError, ValueError, OverflowError):
        return None
    unit = _unit(err["loc"])
    what = ".".join(str(p) for p in err["loc"])
    fields = {"what": what, "value": f"{value:g}{unit}", "limit": f"{ctx['le']:g}{unit}"}
    message = f"{what} = {fields['value']} is out of range (at most {fields['limit']})"
    return LibraryError(message, where(text, path, err["loc"]), text, "out-of-range", fields)


def _unit(loc: tuple) -> str:
    """' kg' for a location whose field's Bounds name a unit, else ''."""
    tp: Any = L.Library
    for part in loc:
        if is_record(tp) and isinstance(part, str):
            hints = _hints(tp, extras=True)
            if part not in hints:
                return ""
            tp = hints[part]
        elif typing.get_origin(tp) is dict:
            tp = typing.get_args(tp)[1]
        else:
            return ""
    unit = next((m.symbol for m in getattr(tp, "__metadata__", ()) if isinstance(m, L.Bounds)), "")
    return f" {unit}" if unit else ""


@cache
def _hints(cls: type, extras: bool = False) -> dict[str, Any]:
    hints = typing.get_type_hints(cls, include_extras=extras)
    return {name: hints[name] for name in cls._fields}  # type: ignore[attr-defined]


# --- the cache -----------------------------------------------------------------------------------

@cache
def _types_source() -> bytes:
    """The source of the library's types: an entry written by other types is another key."""
    from pathlib import Path

    from .. import records as record

    try:
        return b"".join(Path(m.__file__ or "").read_bytes() for m in (L, record))
    except OSError:  # no source beside the bytecode: modc's version alone tells
        return b""


def _entry_name(raw: bytes) -> str:
    from ..cache import key

    return key(_KIND, FORMAT, __version__, _types_source(), raw) + ".json"


def _from_cache(name: str) -> L.Library | None:
    from .. import cache as disk

    payload = disk.get_checked(_KIND, name)
    if payload is None:
        return None
    try:
        library = _decode(json.loads(payload))
    except (ValueError, TypeError, KeyError, AttributeError):  # not a library this modc wrote
        return None
    return library if isinstance(library, L.Library) else None


def _store(name: str, library: L.Library) -> None:
    from .. import cache as disk

    payload = json.dumps(_encode(library), allow_nan=False).encode()
    disk.put_checked(_KIND, name, payload)


# An entry is JSON in which a record is {"$record": its class's name, field: value...} and a dict
# (whose keys may be numbers) {"$items": [[key, value]...]}: rebuilding it needs no type hints.
_RECORDS = {name: cls for name, cls in vars(L).items() if is_record(cls) and cls.__module__ == L.__name__}


def _encode(v: Any) -> Any:
    if isinstance(v, Record):
        return {"$record": type(v).__name__, **{n: _encode(x) for n, x in as_fields(v).items()}}
    if isinstance(v, dict):
        return {"$items": [[_encode(k), _encode(x)] for k, x in v.items()]}
    if isinstance(v, list | tuple):
        return [_encode(x) for x in v]
    return v


def _decode(v: Any) -> Any:
    if isinstance(v, list):
        return [_decode(x) for x in v]
    if isinstance(v, dict):
        if "$items" in v:
            return {_decode(k): _decode(x) for k, x in v["$items"]}
        fields = dict(v)
        cls = _RECORDS[fields.pop("$record")]
        return cls(**{k: _decode(x) for k, x in fields.items()})
    return v
