"""What the package's API adds around the functions that run Drake (`drake_biped.run_episode`,
`build_diagram`, `simulate`, `build_plant`): their configuration arguments checked by name, and Drake's
failed internal checks raised as ordinary exceptions.

pydrake raises a failed DRAKE_DEMAND (Drake's own check of its arguments, e.g. `Box(): condition 'width > 0'
failed`) as `SystemExit`, which a caller's `except Exception` does not catch: a sweep script would simply
exit. The API, the Dask episode task and the command line turn it into `DrakeFailure`, a RuntimeError that
names the call and Drake's check.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from typing import Any, TypeVar

from drake_biped.params import EpisodeConfig, Ground, ParameterError, SimulationParams, check_declared

__all__ = ["DrakeFailure", "api_function", "check_argument", "drake_failure_message", "drake_failures_raised",
           "is_drake_failure"]

F = TypeVar("F", bound=Callable[..., Any])

# The arguments, by name, that the API's Drake functions take as configuration, and their types; a flag is a
# bool, never a string or a number that reads as one ("no" is true).
ARGUMENT_TYPES: dict[str, type] = {"config": EpisodeConfig, "ground": Ground, "record": bool,
                                   "record_trajectory": bool}
# The numbers they take that an EpisodeConfig declares: checked against that one declaration (`params.param`).
DECLARED_ARGUMENTS: dict[str, tuple[type, str]] = {"time_step_s": (SimulationParams, "time_step_s")}


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
    """Inside the block, pydrake's SystemExit for a failed check becomes DrakeFailure("WHAT: a check inside
    Drake failed (...)"); any other SystemExit passes unchanged."""
    try:
        yield
    except SystemExit as exc:
        if not is_drake_failure(exc):
            raise
        raise DrakeFailure(f"{what}: a check inside Drake failed ({drake_failure_message(exc)})") from None


def check_argument(function: str, name: str, value: Any, optional: bool) -> None:
    """ParameterError naming `function`, the argument and its value unless `value` is of the type
    ARGUMENT_TYPES[name] (or None, when `optional`), or within its declaration (DECLARED_ARGUMENTS)."""
    if name in DECLARED_ARGUMENTS:
        check_declared(*DECLARED_ARGUMENTS[name], value, function)
        return
    cls = ARGUMENT_TYPES[name]
    if isinstance(value, cls) or (optional and value is None):
        return
    shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
    hint = f"; build it with {cls.__name__}.from_dict(...)" if isinstance(value, Mapping) else ""
    raise ParameterError(f"{function}: {name} must be a{'n' if cls.__name__[0] in 'AEIOU' else ''} {cls.__name__}"
                         f"{' or None' if optional else ''}, got {type(value).__name__} {shown}{hint}")


def api_function(fn: F) -> F:
    """`fn` as the API hands it out: its configuration arguments (ARGUMENT_TYPES) checked by name, and
    pydrake's SystemExit for a failed check raised as DrakeFailure naming `fn`."""
    signature = inspect.signature(fn)
    checked = {name: p.default is None for name, p in signature.parameters.items()
               if name in ARGUMENT_TYPES or name in DECLARED_ARGUMENTS}

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            bound = signature.bind(*args, **kwargs).arguments
        except TypeError:  # a wrong call: the function itself says how
            bound = {}
        for name, optional in checked.items():
            if name in bound:
                check_argument(fn.__name__, name, bound[name], optional)
        with drake_failures_raised(fn.__name__):
            return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
