"""Checks every learner shares: its seed, and a saved state handed to `from_state`."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypeVar

import numpy as np

from drake_biped.params import ParameterError

__all__ = ["check_seed", "restored"]

T = TypeVar("T")


def check_seed(seed: Any, owner: str) -> int | None:
    """`seed` as an int (None stays None: a fresh seed), or ParameterError naming `owner`'s seed."""
    if seed is None:
        return None
    if not isinstance(seed, (int, np.integer)) or isinstance(seed, (bool, np.bool_)) or seed < 0:
        raise ParameterError(f"{owner}: seed must be an integer >= 0 or None, got {seed!r}")
    return int(seed)


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
