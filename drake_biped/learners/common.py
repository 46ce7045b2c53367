"""Checks every learner shares: its settings' numbers, its seed, and a saved state handed to `from_state`."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

from drake_biped.params import ParameterError

__all__ = ["check_mean", "check_number", "check_seed", "restored"]

T = TypeVar("T")


def check_seed(seed: Any, owner: str) -> int | None:
    """`seed` as an int (None stays None: a fresh seed), or ParameterError naming `owner`'s seed."""
    if seed is None:
        return None
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, (bool, np.bool_)) or seed < 0:
        raise ParameterError(f"{owner}: seed must be an integer >= 0 or None, got {seed!r}")
    return int(seed)


def _is_real(value: Any) -> bool:
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_))


def check_number(value: Any, owner: str, name: str, lo: float, hi: float = math.inf, lo_open: bool = False,
                 hi_open: bool = False) -> float:
    """`value` as a float: a finite number (a bool or a string is none) in [lo, hi] (an end open where told);
    ParameterError naming `owner`'s setting `name` and the value otherwise."""
    inside = _is_real(value) and math.isfinite(value) and (value > lo if lo_open else value >= lo) and \
        (value < hi if hi_open else value <= hi)
    if not inside:
        span = (f"{'>' if lo_open else '>='} {lo:g}" if hi == math.inf
                else f"in {'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}")
        raise ParameterError(f"{owner}: {name} must be a finite number {span}, got {value!r:.60}")
    return float(value)


def check_mean(mean: Any, owner: str) -> np.ndarray:
    """The policy's mean (t1, t2) in s as a float array: two finite numbers (no bools, no strings);
    ParameterError naming `owner`'s mean otherwise."""
    values = list(mean) if isinstance(mean, (Sequence, np.ndarray)) and not isinstance(mean, str) else None
    if values is None or len(values) != 2 or not all(_is_real(v) and math.isfinite(v) for v in values):
        raise ParameterError(f"{owner}: mean must be two finite numbers (t1, t2), got {mean!r:.60}")
    return np.asarray(values, dtype=float)


def restored(cls_name: str, state: Any, required: Sequence[str], restore: Callable[[Mapping[str, Any]], T]) -> T:
    """`restore(state)`, once `state` is a mapping holding every `required` key; ParameterError naming
    `cls_name`.from_state and what is wrong otherwise (also when a value cannot be restored)."""
    where = f"{cls_name}.from_state"
    if not isinstance(state, Mapping):
        shown = repr(state) if len(repr(state)) <= 60 else repr(state)[:57] + "..."
        raise ParameterError(f"{where}: expected the mapping a learner's state() returns, got "
                             f"{type(state).__name__} {shown}")
    missing = [key for key in required if key not in state]
    if missing:
        raise ParameterError(f"{where}: the state has no {', '.join(map(repr, missing))} (it holds "
                             f"{sorted(state)}); expected the mapping {cls_name}.state() returns")
    try:
        return restore(state)
    except ParameterError:
        raise
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise ParameterError(f"{where}: the state cannot be restored ({type(exc).__name__}: "
                             f"{' '.join(str(exc).split())})") from None
