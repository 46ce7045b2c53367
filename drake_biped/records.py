"""Result files: atomic JSON writes (nothing half-written survives a kill) and JSON reads that name the file."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from drake_biped.params import ParameterError

__all__ = ["atomic_file", "read_json", "read_kept", "save_figure", "set_aside", "warn", "write_atomic",
           "write_text_atomic"]


def write_text_atomic(path: Path, text: str) -> None:
    """Write `text` to `path` through a temporary file and a rename: the file is whole or absent."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as f:
        f.write(text)
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def write_atomic(path: Path, data: Any) -> None:
    """`data` as JSON (NaN refused), written atomically."""
    write_text_atomic(path, json.dumps(data, indent=1, allow_nan=False) + "\n")


def read_json(path: Path, what: str) -> Any:
    """The JSON in `path`, or ParameterError naming `what` (the option or command that gave the path) and the
    file: missing, unreadable, not text, not JSON, or nested beyond what Python can parse."""
    path = Path(path)
    if not path.is_file():
        raise ParameterError(f"{what}: no such file: {path}")
    try:
        text = path.read_text()
    except OSError as exc:
        raise ParameterError(f"{what} {path}: cannot be read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{what} {path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParameterError(f"{what} {path}: not valid JSON ({exc})") from None
    except RecursionError:
        raise ParameterError(f"{what} {path}: JSON nested too deeply to read (beyond Python's recursion limit); "
                             "not a file this toolkit writes") from None


def warn(message: str) -> None:
    """A one-line warning on standard error."""
    print(f"drake-biped: warning: {message}", file=sys.stderr, flush=True)


def set_aside(path: Path, why: str) -> Path:
    """Rename a damaged file to PATH.broken (PATH.broken-2, ... when taken), say so, and return the new name:
    nothing is deleted."""
    path = Path(path)
    target = path.with_name(path.name + ".broken")
    k = 2
    while target.exists():
        target = path.with_name(f"{path.name}.broken-{k}")
        k += 1
    os.replace(path, target)
    warn(f"{path} {why}; kept as {target.name}")
    return target


def read_kept(path: Path) -> Any | None:
    """A kept result that can be recomputed (one episode, an experiment's summary): its JSON, or None when
    the file is missing, or damaged (then set aside as PATH.broken, with a warning, and recomputed)."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError):
        set_aside(path, "is not valid JSON (a damaged result); it is computed again")
        return None


@contextmanager
def atomic_file(path: Path) -> Iterator[Path]:
    """A temporary path beside `path` (same suffix, so writers that go by it pick the format) to write to;
    renamed to `path` when the block ends without error, removed otherwise: `path` is whole or as it was."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def save_figure(fig, path: Path, **kwargs) -> None:
    """`fig.savefig(path, **kwargs)`, atomically."""
    with atomic_file(path) as tmp:
        fig.savefig(tmp, **kwargs)
