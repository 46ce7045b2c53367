"""Progress of a resumable run: a tqdm bar and the run log OUT/run.json (every session's count and wall time).

A run log belongs to one command (`grid`, `learn`, `slope`), named in it: another command's run into the same
folder is refused by name before any work (`check_run_log`), so no log counts two commands' episodes as one
run's sessions. A log written before logs named their command is taken over by the command that resumes it.
"""

from __future__ import annotations

import contextlib
import json
import math
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from drake_biped.params import ParameterError
from drake_biped.records import set_aside, write_atomic

__all__ = ["RUN_LOG", "RunProgress", "SessionLog", "check_run_log", "progress_bar", "run_log_command"]

RUN_LOG = "run.json"


def run_log_command(path: Path) -> str | None:
    """The command a run log names (None: no log, an unreadable one, or one from before logs named it)."""
    try:
        command = json.loads(Path(path).read_text()).get("command")
    except (OSError, json.JSONDecodeError, UnicodeDecodeError, AttributeError, RecursionError):
        return None
    return command if isinstance(command, str) else None


def check_run_log(out: Path, command: str) -> None:
    """ParameterError naming OUT/run.json and its command when another command's run log is there."""
    path = Path(out) / RUN_LOG
    owner = run_log_command(path)
    if owner is not None and owner != command:
        raise ParameterError(f"{path} is the run log of drake-biped {owner}: a run log belongs to one command, so "
                             f"{command} does not run into {Path(out)}; give it a folder of its own")


class SessionLog:
    """OUT/run.json: one entry per session of a run (a first run and each resume): when, on what, how many
    episodes in how long. Rewritten at most every `every_s` seconds while running, so a session that is
    killed keeps its numbers, and the next session counts any finished episode the log missed (`reconcile`).
    Wall times live here, not in learning.json, which a resume reproduces. An unreadable log is set aside as
    run.json.broken (with a warning), never dropped."""

    def __init__(self, path: Path, workers: int | None, scheduler: str | None, every_s: float = 10.0,
                 command: str | None = None):
        self.path = path
        self.command = command  # the command whose run this logs (written into the log)
        self.sessions: list[dict[str, Any]] = []
        if command is not None:
            check_run_log(path.parent, command)  # another command's log is refused, never merged
        if path.is_file():
            try:
                sessions = json.loads(path.read_text())["sessions"]
                if not (isinstance(sessions, list) and all(isinstance(x, dict) for x in sessions)):
                    raise TypeError("sessions is not a list of sessions")
                self.sessions = sessions
            except (json.JSONDecodeError, UnicodeDecodeError, KeyError, TypeError):
                set_aside(path, "is not a readable run log: a new session history starts (the run's results "
                          "are not affected)")
        self.t0 = time.perf_counter()
        self.every_s = every_s
        self._last = -math.inf
        self.written: int | None = None  # the count of this session the file holds
        self.current = {"started": time.strftime("%Y-%m-%d %H:%M:%S %Z"), "workers": workers,
                        "scheduler": scheduler, "episodes": 0, "learning_wall_s": 0.0, "wall_s": 0.0,
                        "episodes_per_min": None, "finished": False}

    def reconcile(self, done: int) -> None:
        """`done` units are finished in the run's records when this session starts: count those that no
        logged session counts (a session killed between two writes of the log, or a lost log) in the last
        unfinished session, or else in an entry of their own."""
        missing = done - sum(int(x.get("episodes", 0)) for x in self.sessions)
        if missing <= 0:
            return
        last = self.sessions[-1] if self.sessions else None
        if last is not None and not last.get("finished", False):
            last["episodes"] = int(last.get("episodes", 0)) + missing
            last["counted_from_records"] = missing
        else:
            self.sessions.append({"started": None, "workers": None, "scheduler": None, "episodes": missing,
                                  "learning_wall_s": 0.0, "wall_s": 0.0, "episodes_per_min": None,
                                  "finished": False, "counted_from_records": missing})

    def update(self, episodes: int, learning: bool = True, finished: bool = False, force: bool = False) -> None:
        now = time.perf_counter() - self.t0
        self.current["episodes"] = episodes
        if learning:
            self.current["learning_wall_s"] = now
            self.current["episodes_per_min"] = 60.0 * episodes / now if episodes and now > 0 else None
        self.current["wall_s"] = now
        self.current["finished"] = finished
        if force or finished or now - self._last >= self.every_s:
            self._last = now
            self.written = episodes
            done = [*self.sessions, self.current]
            episodes_all = sum(s["episodes"] for s in done)
            wall_all = sum(s["learning_wall_s"] for s in done)
            write_atomic(self.path, {
                **({"command": self.command} if self.command is not None else {}),
                "sessions": done, "episodes": episodes_all, "learning_wall_s": wall_all,
                "episodes_per_min": 60.0 * episodes_all / wall_all if episodes_all and wall_all > 0 else None})


class RunProgress:
    """A progress bar (when `bar` is set) and the run log OUT/run.json (`SessionLog`) of a resumable run of
    `command`; called as progress(done, total, latest_mean_reward=None) by the run as it goes."""

    def __init__(self, out: Path, workers: int | None, scheduler: str | None, desc: str, unit: str,
                 bar: bool = True, command: str | None = None):
        if command is not None:
            check_run_log(out, command)  # before the folder is made or anything written
        out.mkdir(parents=True, exist_ok=True)
        self.log = SessionLog(out / RUN_LOG, workers, scheduler, command=command)
        self.bar = None
        self._bar_args = (desc, unit) if bar else None  # the bar starts with the first report
        self.first: int | None = None
        self.done = 0

    def __call__(self, done: int, total: int, latest: float | None = None) -> None:
        if self.first is None:
            self.first = done
            self.log.reconcile(done)
        self.done = done
        self.log.update(done - self.first)
        if self.bar is None and self._bar_args is not None:
            from tqdm import tqdm

            self.bar = tqdm(total=total, initial=done, desc=self._bar_args[0], unit=self._bar_args[1])
        if self.bar is not None:
            self.bar.total = total
            self.bar.n = done
            if latest is not None:
                self.bar.set_postfix_str(f"latest mean reward {latest:.3f}", refresh=False)
            self.bar.refresh()

    @property
    def new(self) -> int:
        """What this session computed."""
        return 0 if self.first is None else self.done - self.first

    def close(self) -> None:
        """Close the bar; write the log if it misses units finished since its last write (a run stopped by
        Ctrl-C or an error between two writes)."""
        if self.bar is not None:
            self.bar.close()
        if self.log.written != self.new:
            self.log.update(self.new, force=True)


@contextlib.contextmanager
def progress_bar(total: int, desc: str, unit: str, enabled: bool = True) -> Iterator[Callable[[int, int], None]]:
    """tick(done, total): a tqdm bar of a sweep (none when not `enabled`; the total grows when a sweep finds
    more work), closed on leaving, also on an error."""
    bar = None
    if enabled:
        from tqdm import tqdm

        bar = tqdm(total=total, desc=desc, unit=unit)

    def tick(done: int, total: int) -> None:
        if bar is not None:
            bar.total = max(bar.total, total)
            bar.n = done
            bar.refresh()

    try:
        yield tick
    finally:
        if bar is not None:
            bar.close()
