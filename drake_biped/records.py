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
                 option: str = "--out", growable: tuple[str, ...] = (),
                 gait: dict[str, Any] | None = None) -> Iterator[None]:
    """Hold the output folder `out` for one run of `command` with `settings` (a JSON-able mapping) while the
    block runs. `gait`: the identity of the gait the run walks (`resources.gait_identity`), recorded in RUN_FILE;
    a folder whose run walked another gait (another SHA-256: a parameter file edited between runs) is another
    run's.

    One process at a time: a second run into a folder held by another is refused, naming the holder. A folder
    holding another run's records (RUN_FILE names another command or other settings) is refused, naming both,
    unless `overwrite`; the same command with the same settings continues (a resume), and so does one whose
    `growable` settings (counts: episodes, trials, generations) are larger: a run is extended, never shortened.

    A run deletes only what the toolkit wrote. RUN_FILE lists the files and folders the folder's runs wrote
    ("files": whatever appeared while a run held the folder, found by listing it, so that nothing a run writes
    is missed, in subfolders or by any writer) and those they found there ("others"). `overwrite` deletes the
    listed files (and the listed folders left empty), never the others, and the run goes on beside them. A
    folder holding files without a RUN_FILE is refused, naming them, unless `overwrite`: then the run writes
    beside them (a file of the same name as one it writes is replaced) and takes over records it finds there,
    as a resume. A RUN_FILE written before runs listed their files (no "files") still resumes, and keeps no
    list; another run's `overwrite` there is refused, naming the files, since none can be shown to be the
    toolkit's. A file put into the folder while a run holds it, or after a killed run before its resume,
    counts as the run's. ParameterError naming `option`."""
    import fcntl

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
    try:
        lock.seek(0)
        lock.truncate()
        lock.write(f"process {os.getpid()}: drake-biped {command}\n")
        lock.flush()
        header = out / RUN_FILE
        this = {"command": command, "settings": settings, "gait": gait}
        before = _read_run_file(header)
        present = _listing(out)
        new_claim = before is None
        if before is None:  # no run's folder: empty, or files of unknown origin
            others = present
            if others and not overwrite:
                raise ParameterError(f"{option} {out} holds files no drake-biped run listed as its own (no {RUN_FILE}"
                                     f"): {_named(others)}; choose another folder, or give --overwrite to write "
                                     "beside them (they are kept; one of the same name as a file this run writes "
                                     "is replaced)")
            if others:
                warn(f"{option} {out}: writing beside files no drake-biped run listed as its own, which are kept "
                     f"as they are: {_named(others)}")
        else:
            shorter = _shortened(before, this, growable)
            if shorter and not overwrite:
                raise ParameterError(f"{option} {out} holds a longer run of the same command ({shorter}): a run is "
                                     "extended, never shortened; give the larger count, choose another folder, "
                                     "or give --overwrite to replace its records")
            replace = shorter or not _same_run(before, this, growable)
            if replace and not overwrite:
                raise ParameterError(f"{option} {out} holds the records of another run ({_difference(before, this)}"
                                     "): rerun that command to resume it, choose another folder, or give "
                                     "--overwrite to replace its records")
            listed = _listed(before) if present else (set(), set())
            if listed is None:  # written before runs listed their files: none can be shown to be the toolkit's
                if replace:
                    raise ParameterError(f"{option} {out} holds the records of another run whose {RUN_FILE} lists "
                                         "no files (an older drake-biped's, or unreadable), so --overwrite cannot "
                                         f"tell them from files of your own: {_named(present)}; move or delete them, "
                                         "or choose another folder")
                others = None
            else:
                files, others = listed
                if before.get("writing"):  # that run was stopped before it listed what it wrote
                    files = present - others
                files &= present
                others = present - files
                if replace:
                    _delete_listed(out, files)
                    others = _listing(out)
                    if others:
                        warn(f"{option} {out}: the records of the run replaced are deleted; files no drake-biped "
                             f"run listed as its own are kept as they are: {_named(others)}")
            new_claim = replace
        _write_run_file(out, this, others, writing=True)
        try:
            yield
        except BaseException:
            if others is not None and new_claim and not _listing(out) - others:
                # a run refused or failed in a folder it began, having written nothing: the folder keeps no claim
                header.unlink(missing_ok=True)
            else:
                _write_run_file(out, this, others, writing=False)
            raise
        _write_run_file(out, this, others, writing=False)
    finally:
        lock_path.unlink(missing_ok=True)
        fcntl.flock(lock, fcntl.LOCK_UN)
        lock.close()


# Files of the toolkit's own bookkeeping, at the top of an output folder: never listed, never deleted.
_BOOKKEEPING = (LOCK_FILE, RUN_FILE, RUN_FILE + ".tmp", ".drake-biped-write-test")


def _listing(out: Path) -> set[str]:
    """Everything in `out` (its own bookkeeping aside) as paths relative to it, a folder's ending in "/";
    links are not followed."""
    found: set[str] = set()

    def walk(folder: Path, prefix: str) -> None:
        with os.scandir(folder) as entries:
            for entry in entries:
                name = prefix + entry.name
                if not prefix and entry.name in _BOOKKEEPING:
                    continue
                if entry.is_dir(follow_symlinks=False):
                    found.add(name + "/")
                    walk(Path(entry.path), name + "/")
                else:
                    found.add(name)

    walk(Path(out), "")
    return found


def _named(paths: set[str], most: int = 5) -> str:
    """`paths` for a one-line message: a folder holding more than one of them stands for them; the first
    `most`, then a count."""
    shown: list[str] = []

    def visit(prefix: str) -> None:
        inside = [p for p in paths if p.startswith(prefix) and p != prefix]
        children = sorted({prefix + p[len(prefix):].split("/")[0] + ("/" if "/" in p[len(prefix):] else "")
                           for p in inside})
        for child in children:
            if not child.endswith("/"):
                shown.append(child)
                continue
            files = [p for p in paths if p.startswith(child) and not p.endswith("/")]
            if len(files) == 1:
                visit(child)
            else:  # several files, or an empty folder
                shown.append(child)

    visit("")
    return ", ".join(shown[:most]) + (f" and {len(shown) - most} more" if len(shown) > most else "")


def _read_run_file(header: Path) -> Any:
    """The JSON of RUN_FILE; None when there is none; {} when it does not read (it names no run)."""
    if not header.is_file():
        return None
    try:
        before = json.loads(header.read_text())
    except (OSError, ValueError):
        return {}
    return before if isinstance(before, dict) else {}


def _listed(before: dict[str, Any]) -> tuple[set[str], set[str]] | None:
    """RUN_FILE's lists (files the runs wrote, others found there); None when it holds none (an older run's, or
    an unreadable one)."""
    files, others = before.get("files"), before.get("others")
    if not (isinstance(files, list) and isinstance(others, list)
            and all(isinstance(p, str) for p in files + others)):
        return None
    return set(files), set(others)


def _write_run_file(out: Path, this: dict[str, Any], others: set[str] | None, writing: bool) -> None:
    """out/RUN_FILE: the run's command and settings, and, where `others` is known, what the folder holds now
    split into the files the runs wrote (all but `others`) and the others. "writing" while the run holds the
    folder: left in place when the run is killed, so that its resume counts what appeared since as the run's."""
    record: dict[str, Any] = {"command": this["command"],
                              "settings": json.loads(json.dumps(this["settings"], sort_keys=True))}
    if this.get("gait"):
        record["gait"] = this["gait"]
    if others is not None:
        present = _listing(out)
        if writing:
            record["writing"] = True
        record["files"] = sorted(present - others)
        record["others"] = sorted(others & present)
    write_text_atomic(out / RUN_FILE, json.dumps(record, indent=1) + "\n")


def _delete_listed(out: Path, files: set[str]) -> None:
    """Delete the files listed in `files`, then the listed folders left empty (the deepest first)."""
    for name in files:
        if not name.endswith("/"):
            (out / name).unlink(missing_ok=True)
    for name in sorted((n for n in files if n.endswith("/")), key=lambda n: n.count("/"), reverse=True):
        try:
            (out / name).rmdir()
        except OSError:  # holds a file of the user's: kept
            pass


def _other_gait(before: dict[str, Any], this: dict[str, Any]) -> bool:
    """Whether both runs record the gait they walk and it differs (a record older than the gait's is not asked)."""
    old, new = before.get("gait"), this.get("gait")
    return isinstance(old, dict) and isinstance(new, dict) and old.get("sha256") != new.get("sha256")


def _same_run(before: Any, this: dict[str, Any], growable: tuple[str, ...]) -> bool:
    """Whether `this` run continues `before`: the same command and settings, `growable` counts aside."""
    if not isinstance(before, dict) or not isinstance(before.get("settings"), dict):
        return False
    drop = set(growable)
    if _other_gait(before, this):
        return False
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
    if _other_gait(before, this):
        def named(gait):
            return f"{gait.get('name') or 'another gait'} (sha256 {str(gait.get('sha256'))[:12]})"

        return f"drake-biped {this['command']} on another gait: {named(before['gait'])} there, " \
            f"{named(this['gait'])} here"
    old, new = before["settings"], this["settings"]
    changed = [f"--{k.replace('_', '-')} {old.get(k)!r} there, {new.get(k)!r} here"
               for k in sorted(set(old) | set(new)) if old.get(k) != new.get(k)]
    text = f"drake-biped {this['command']} with other settings: " + "; ".join(changed)
    return text if len(text) <= 240 else text[:237] + "..."
