"""Declared fields: a dataclass field declared once with its default, unit, meaning and bounds (`param`), and a
mixin (`Validated`) that checks every field against its declaration wherever a value enters: at construction, from
a mapping (`from_dict`, sections built from their own mappings) and as a function's argument (`check_declared`).
The parameter dataclasses (`params`) are built on it; the controller's Context parameter and docs/PARAMETERS.md
read the declarations (`control_law`)."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import field, fields
from typing import Any

__all__ = ["ParameterError", "Validated", "check_declared", "param", "parameter_info"]

# Every Validated class by name: a field declared with one of these types is a section, built from its mapping.
_DECLARED: dict[str, type] = {}


class ParameterError(ValueError):
    """A parameter is unknown, non-finite or out of its range. The message names it."""


def _check_finite(owner: str, name: str, value: float) -> None:
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
        raise ParameterError(f"{owner}.{name} must be a finite number, got {value!r}")


def _check_range(owner: str, name: str, value: float, lo: float | None, hi: float | None) -> None:
    _check_finite(owner, name, value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        lo_s = "-inf" if lo is None else f"{lo:g}"
        hi_s = "inf" if hi is None else f"{hi:g}"
        raise ParameterError(f"{owner}.{name} = {value!r} is outside [{lo_s}, {hi_s}]")


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def param(default: Any, unit: str, doc: str, lo: float | None = None, hi: float | None = None) -> Any:
    """A parameter declared once: its default, its unit ("1" for a pure number, "" for a choice or a flag),
    what it means and its bounds (None: unbounded on that side), as Drake's named vectors declare theirs. The
    dataclass checks the bounds; the controller's Context parameter (control_law.LAW) and docs/PARAMETERS.md
    read the unit and the text from here."""
    return field(default=default, metadata={"unit": unit, "doc": doc, "bounds": (lo, hi)})


def parameter_info(cls: type, name: str) -> dict[str, Any]:
    """The declaration of `cls`'s field `name` (`param`): its unit, doc and bounds."""
    for f in fields(cls):
        if f.name == name:
            if "doc" not in f.metadata:
                raise KeyError(f"{cls.__name__}.{name} is not declared with param()")
            return dict(f.metadata)
    raise KeyError(f"{cls.__name__} has no field {name!r}")


def _declared_value(owner: str, f: dataclasses.Field, value: Any) -> Any:
    """`value` checked against the field `f`'s declaration (its type, and `param`'s bounds or finiteness; an int
    given for a float comes back a float); ParameterError naming `owner`.`f.name` and the value otherwise."""
    kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
    optional = kind.endswith("| None")
    kind = kind.removesuffix("| None").strip()
    if value is None and optional:
        return value
    if kind == "float":
        if not _is_number(value):
            raise ParameterError(f"{owner}.{f.name} must be a number, got {_shown(value)}")
        value = float(value)
    elif kind == "int":
        if not isinstance(value, int) or isinstance(value, bool):
            raise ParameterError(f"{owner}.{f.name} must be an integer, got {_shown(value)}")
    elif kind == "str":
        if not isinstance(value, str):
            raise ParameterError(f"{owner}.{f.name} must be a string, got {_shown(value)}")
    elif kind in _DECLARED and not isinstance(value, _DECLARED[kind]):
        hint = f"; build it with {kind}(...) or {kind}.from_dict(...)" if isinstance(value, dict) else ""
        raise ParameterError(f"{owner}.{f.name} must be a {kind}, got {type(value).__name__} {_shown(value)}{hint}")
    bounds = f.metadata.get("bounds")
    if bounds is not None and _is_number(value):
        _check_range(owner, f.name, value, *bounds)
    elif isinstance(value, float):
        _check_finite(owner, f.name, value)
    return value


def _shown(value: Any) -> str:
    """`value` for a one-line message: its repr, cut to 60 characters."""
    text = " ".join(repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


def check_declared(cls: type, name: str, value: Any, where: str) -> Any:
    """`value` checked against the declaration of `cls`'s field `name` (`param`: its type and bounds), for a
    value that enters elsewhere than through the dataclass (a function's argument); ParameterError naming
    `where` otherwise. Returns the value (an int given for a float as a float)."""
    for f in fields(cls):
        if f.name == name:
            try:
                return _declared_value(cls.__name__, f, value)
            except ParameterError as exc:
                raise ParameterError(f"{where}: {exc}") from None
    raise KeyError(f"{cls.__name__} has no field {name!r}")


def _section_class(f: dataclasses.Field) -> type | None:
    """The Validated class a field is declared with (a section), else None."""
    kind = f.type if isinstance(f.type, str) else getattr(f.type, "__name__", str(f.type))
    return _DECLARED.get(kind.removesuffix("| None").strip())


class Validated:
    """Mixin: every field is checked against its declared type after init (an int given for a float is
    stored as a float), and every number against its declared bounds (`param`) or for being finite."""

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        _DECLARED[cls.__name__] = cls

    def __post_init__(self) -> None:
        owner = type(self).__name__
        for f in fields(self):
            value = _declared_value(owner, f, getattr(self, f.name))
            if value is not getattr(self, f.name):
                object.__setattr__(self, f.name, value)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any] | None, where: str | None = None, base: Any = None):
        """An instance from a mapping of its fields (a JSON object); ParameterError naming `where` (default:
        the class) for anything else, an unknown field or a bad value. A field declared as a Validated class (a
        section) is built from its own mapping, its missing fields taken from `base`'s section (an instance of
        this class), where `base` is given."""
        where = where or cls.__name__
        if data is None:
            data = {}
        if not isinstance(data, Mapping):
            raise ParameterError(f"{where}: expected a mapping of {cls.__name__} fields, got {type(data).__name__} "
                                 f"{_shown(data)}")
        known = {f.name: f for f in fields(cls)}
        unknown = sorted(set(data) - set(known))
        if unknown:
            raise ParameterError(f"{where}: unknown parameter(s) {unknown}; known: {sorted(known)}")
        kwargs = {}
        for name, value in data.items():
            sub = _section_class(known[name])
            if sub is not None:
                inner = f"{where}.{name}" if where == cls.__name__ else f"{where}, section {name!r}"
                default = getattr(base, name) if base is not None else None
                if default is not None and isinstance(value, Mapping):
                    value = {**default.to_dict(), **value}
                kwargs[name] = None if value is None else sub.from_dict(value, inner)
            else:
                kwargs[name] = value
        try:
            return cls(**kwargs)
        except ParameterError as exc:
            if where == cls.__name__:
                raise
            raise ParameterError(f"{where}: {exc}") from None
