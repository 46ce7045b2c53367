"""Drake's internal checks as ordinary exceptions.

pydrake raises a failed DRAKE_DEMAND (Drake's own check of its arguments, e.g. `Box(): condition 'width > 0'
failed`) as `SystemExit`, which a caller's `except Exception` does not catch: a sweep script would simply
exit. The package's API (`drake_biped.run_episode`, `build_diagram`, ...), the Dask episode task and the
command line turn it into `DrakeFailure`, a RuntimeError that names what was being done and Drake's check.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

__all__ = ["DrakeFailure", "drake_failure_message", "drake_failures_raised", "is_drake_failure",
           "raising_drake_failures"]

F = TypeVar("F", bound=Callable[..., Any])


class DrakeFailure(RuntimeError):
    """A check inside Drake failed (a DRAKE_DEMAND, which pydrake raises as SystemExit)."""


def is_drake_failure(exc: BaseException) -> bool:
    """Whether `exc` is pydrake's SystemExit for a failed internal check (its code is Drake's message,
    "Failure at FILE:LINE in FUNCTION(): condition '...' failed."), not a program's own exit."""
    code = exc.code if isinstance(exc, SystemExit) else None
    return isinstance(code, str) and code.startswith("Failure at ") and "condition" in code


def drake_failure_message(exc: SystemExit) -> str:
    """Drake's message on one line, without the source location: "in Box(): condition '...' failed. ..."."""
    text = " ".join(str(exc.code).split())
    _, sep, rest = text.partition(" in ")
    return f"in {rest}" if sep and rest else text


@contextmanager
def drake_failures_raised(what: str) -> Iterator[None]:
    """Inside the block, pydrake's SystemExit for a failed check becomes DrakeFailure("WHAT: Drake's check
    failed ..."); any other SystemExit passes unchanged."""
    try:
        yield
    except SystemExit as exc:
        if not is_drake_failure(exc):
            raise
        raise DrakeFailure(f"{what}: a check inside Drake failed ({drake_failure_message(exc)})") from None


def raising_drake_failures(fn: F) -> F:
    """`fn` with pydrake's SystemExit for a failed check raised as DrakeFailure naming `fn`."""

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with drake_failures_raised(fn.__name__):
            return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
