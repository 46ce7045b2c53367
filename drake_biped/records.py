"""Result files: atomic JSON writes (nothing half-written survives a kill) and JSON reads that name the file."""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from drake_biped.params import ParameterError

__all__ = ["LOCK_FILE", "RUN_FILE", "atomic_file", "claim_folder", "read_json", "read_kept", "read_kept_lines",
           "save_figure", "set_aside", "stored", "warn", "write_atomic", "write_record",
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


def write_record(out: Path | str, name: str, record: dict[str, Any],
                 markdown: Callable[[dict[str, Any]], str] | None = None,
                 figure: Callable[[dict[str, Any], Path], Any] | None = None) -> None:
    """An experiment's outputs: out/NAME.json holds the record; out/NAME.md (its report) and out/NAME.png (its
    figure) are drawn from the record alone, where `markdown` and `figure` are given."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / f"{name}.json", record)
    if markdown is not None:
        write_text_atomic(out / f"{name}.md", markdown(record))
    if figure is not None:
        figure(record, out / f"{name}.png")


def stored(path: Path) -> Path:
    """Where the record `path` is kept: `path` itself, or PATH.gz when only the gzip-compressed form exists (a
    large record kept in the repository is compressed: benchmarks/results/)."""
    path = Path(path)
    packed = path.with_name(path.name + ".gz")
    return packed if not path.exists() and packed.is_file() else path


def read_json(path: Path, what: str) -> Any:
    """The JSON in `path` (or in PATH.gz, or in a gzip-compressed `path` ending in .gz), or ParameterError
    naming `what` (the option or command that gave the path) and the file: missing, unreadable, not text, not
    JSON, or nested beyond what Python can parse."""
    import gzip

    path = stored(path)
    if not path.is_file():
        raise ParameterError(f"{what}: no such file: {path}")
    try:
        if path.suffix == ".gz":
            with gzip.open(path, "rt") as f:
                text = f.read()
        else:
            text = path.read_text()
    except (OSError, EOFError) as exc:
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


def read_kept_lines(path: Path, what: str, readable: Callable[[Any], bool] = lambda entry: True,
                    in_order: bool = False) -> list[Any]:
    """The entries of a JSON-lines log a resumable run appends to (a finished episode, point or generation a
    line), [] when there is none. When a line does not read (JSON for which `readable` holds), the file is set
    aside as PATH.broken with a warning naming the lines, and PATH is written again with the lines that read
    (with `in_order`, a log whose lines build on each other, those before the first that does not): what was
    lost is computed again, and nothing is deleted."""
    path = Path(path)
    if not path.is_file():
        return []
    lines = path.read_text(errors="replace").splitlines()
    kept, bad = [], []
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            entry = json.loads(line)
            ok = readable(entry)
        except (ValueError, KeyError, TypeError, AttributeError, RecursionError):
            ok = False
        if not ok:
            bad.append(number)
        elif not (in_order and bad):
            kept.append((line, entry))
    if bad:
        shown = ", ".join(str(n) for n in bad[:5]) + (f" and {len(bad) - 5} more" if len(bad) > 5 else "")
        which = "before the first" if in_order else "that read"
        set_aside(path, f"has {len(bad)} line(s) that do not read as {what} (line {shown}: a damaged log or a write "
                  f"cut short); the {len(kept)} {which} carry over into a new {path.name}, the rest are computed "
                  "again")
        write_text_atomic(path, "".join(line + "\n" for line, _ in kept))
    return [entry for _, entry in kept]


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


# The run that wrote an output folder (its command and settings), and the lock of the process writing it now.
RUN_FILE = "drake-biped-run.json"
LOCK_FILE = ".drake-biped.lock"


@contextmanager
def claim_folder(out: Path, command: str, settings: dict[str, Any], overwrite: bool = False,
                 option: str = "--out", growable: tuple[str, ...] = ()) -> Iterator[None]:
    """Hold the output folder `out` for one run of `command` with `settings` (a JSON-able mapping) while the
    block runs.

    One process at a time: a second run into a folder held by another is refused, naming the holder. A folder
    holding another run's records (RUN_FILE names another command or other settings) is refused, naming both,
    unless `overwrite`, which empties it first; the same command with the same settings continues (a resume),
    and so does one whose `growable` settings (counts: episodes, trials, generations) are larger: a run is
    extended, never shortened. A folder of records written without RUN_FILE is taken over as it is.
    ParameterError naming `option`."""
    import fcntl
    import shutil

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lock_path = out / LOCK_FILE
    lock = open(lock_path, "a+")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        lock.seek(0)
        holder = lock.read().strip() or "another process"
        lock.close()
        raise ParameterError(f"{option} {out}: another run is writing this folder ({holder}); wait for it to end, "
                             "or choose another folder") from None
    fresh = False
    try:
        lock.seek(0)
        lock.truncate()
        lock.write(f"process {os.getpid()}: drake-biped {command}\n")
        lock.flush()
        header = out / RUN_FILE
        this = {"command": command, "settings": settings}
        if header.is_file():
            try:
                before = json.loads(header.read_text())
            except (OSError, ValueError):
                before = None
            shorter = _shortened(before, this, growable)
            if shorter and not overwrite:
                raise ParameterError(f"{option} {out} holds a longer run of the same command ({shorter}): a run is "
                                     "extended, never shortened; give the larger count, choose another folder, "
                                     "or give --overwrite to replace its records")
            if not _same_run(before, this, growable):
                if not overwrite:
                    raise ParameterError(f"{option} {out} holds the records of another run ({_difference(before, this)}"
                                         "): rerun that command to resume it, choose another folder, or give "
                                         "--overwrite to replace its records")
                for entry in out.iterdir():
                    if entry.name != LOCK_FILE:
                        shutil.rmtree(entry) if entry.is_dir() and not entry.is_symlink() else entry.unlink()
                fresh = True
        else:
            fresh = not any(p.name not in (LOCK_FILE, ".drake-biped-write-test") for p in out.iterdir())
        created = not header.is_file() or fresh
        write_text_atomic(header, json.dumps(this, indent=1, sort_keys=True) + "\n")
        try:
            yield
        except BaseException:
            if created:  # a run refused or failed in a folder it began: the folder keeps no claim of it
                header.unlink(missing_ok=True)
            raise
    finally:
        lock_path.unlink(missing_ok=True)
        fcntl.flock(lock, fcntl.LOCK_UN)
        lock.close()


def _same_run(before: Any, this: dict[str, Any], growable: tuple[str, ...]) -> bool:
    """Whether `this` run continues `before`: the same command and settings, `growable` counts aside."""
    if not isinstance(before, dict) or not isinstance(before.get("settings"), dict):
        return False
    drop = set(growable)
    return before.get("command") == this["command"] and \
        {k: v for k, v in before["settings"].items() if k not in drop} == \
        {k: v for k, v in this["settings"].items() if k not in drop}


def _shortened(before: Any, this: dict[str, Any], growable: tuple[str, ...]) -> str:
    """The growable counts `this` run asks fewer of than `before` ran, in the command line's words ("" when
    none, or when the runs differ otherwise)."""
    if not _same_run(before, this, growable):
        return ""
    old, new = before["settings"], this["settings"]
    fewer = [f"--{k} {new[k]} here, {old[k]} there" for k in growable
             if isinstance(old.get(k), int) and isinstance(new.get(k), int) and new[k] < old[k]]
    return "; ".join(fewer)


def _difference(before: Any, this: dict[str, Any]) -> str:
    """What differs between a folder's run and this one, in the command line's words."""
    if not isinstance(before, dict) or not isinstance(before.get("settings"), dict):
        return "an unreadable run record"
    if before.get("command") != this["command"]:
        return f"drake-biped {before.get('command')}; this run is drake-biped {this['command']}"
    old, new = before["settings"], this["settings"]
    changed = [f"--{k.replace('_', '-')} {old.get(k)!r} there, {new.get(k)!r} here"
               for k in sorted(set(old) | set(new)) if old.get(k) != new.get(k)]
    text = f"drake-biped {this['command']} with other settings: " + "; ".join(changed)
    return text if len(text) <= 240 else text[:237] + "..."
