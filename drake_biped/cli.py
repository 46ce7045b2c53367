"""Command-line interface: `drake-biped COMMAND`, one command per experiment module plus `figures`.

Each experiment in EXPERIMENT_COMMANDS owns its command: it declares its options (`add_arguments`, with the
shared ones of `common.options`), builds its settings from them and calls its own `run(settings, out,
client)`, which writes every file (`command`). This module is the loop over them and what every command shares:
one line and an exit code for every failure, one run per output folder (records.claim_folder), sizes bounded
before any work, and `--version`.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

# MADE: the folders --out made; integer, number, windows: the option types the examples give their own parsers.
from drake_biped.common.options import MADE, integer, number, windows  # noqa: F401
from drake_biped.model import ModelError
from drake_biped.params import ParameterError


def cmd_figures(args: argparse.Namespace) -> int:
    from drake_biped.analysis.figures import learning_figures
    from drake_biped.common.learning_record import check_learning_record
    from drake_biped.common.options import check_writable
    from drake_biped.records import read_json

    given = Path(args.dir)  # the run's folder, or its learning.json
    path = given if given.is_file() or (given.suffix == ".json" and not given.is_dir()) else given / "learning.json"
    out = path.parent
    record = check_learning_record(read_json(path, "figures DIR"), f"figures DIR: {path}")
    check_writable(out, f"figures DIR: {str(out)!r}")
    for p in learning_figures(record, out):
        print(f"wrote {p}")
    return 0


class _HelpFormatter(argparse.HelpFormatter):
    """Every option's default in its help, unless the help already says it or there is none."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if "default" in text or action.required or default in (None, False, argparse.SUPPRESS):
            return text
        if isinstance(default, (list, tuple)):
            default = " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in default)
        return f"{text} (default: {default})"


class _Parser(argparse.ArgumentParser):
    """Option errors as one line naming the option and the value (exit code 2), without the usage block."""

    def exit(self, status: int = 0, message: str | None = None):
        _remove_empty_made_folders()  # --help or an option error: the command never ran
        super().exit(status, message)

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def script_parser(description: str | None) -> argparse.ArgumentParser:
    """An argument parser for a script of the toolkit (examples/) with the commands' contract: an option error
    is one line naming the option and the value, exit code 2; every default in the help. Give its options
    this module's types (`number("positive")`, `integer(1)`, `windows`) and run the script with `run_script`."""
    first_line = description.strip().splitlines()[0] if description and description.strip() else None
    return _Parser(description=first_line, formatter_class=_HelpFormatter)


def run_script(main: Callable[[], object], prog: str | None = None) -> None:
    """Run a script's `main()` under the commands' contract: bad input (ParameterError, ModelError) one line
    and exit 2, a failed run one line and exit 1, Ctrl-C exit 130; the traceback with DRAKE_BIPED_DEBUG=1."""
    prog = prog or Path(sys.argv[0]).name
    with _failures_as_one_line(prog, os.environ.get(DEBUG_ENV, "") not in ("", "0"), "run it again",
                               f"set {DEBUG_ENV}=1 for the traceback"):
        main()


class _VersionAction(argparse.Action):
    """--version: the package's version, the git commit of a source checkout and Drake's version
    (`versions.versions()`, as every record holds them); then exit 0."""

    def __init__(self, option_strings, dest, **kwargs):
        kwargs.update(nargs=0, default=argparse.SUPPRESS)
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from drake_biped.versions import versions

        v = versions()
        print(f"drake-biped {v['drake_biped']}, git commit {v['git_commit'] or 'unknown (not a source checkout)'}, "
              f"Drake {v['drake'] or 'unknown (no drake distribution found)'}")
        parser.exit()


# The experiments with a command of their own, in the order `drake-biped --help` lists them.
EXPERIMENT_COMMANDS = ("walk", "window_map", "gait_search", "time_step", "learning", "compare_learners", "landscape",
                       "stability", "rewalk", "floquet", "bifurcation", "basins", "push_margin", "grid", "slope",
                       "reproduce")


def experiment_commands() -> list:
    """The experiment modules that own a command (COMMAND, PARSER, add_arguments, settings_from_args, command)."""
    import importlib

    return [importlib.import_module(f"drake_biped.experiments.{name}") for name in EXPERIMENT_COMMANDS]


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="drake-biped", description=__doc__.splitlines()[0],
                     epilog=f"Exit codes: 0 done, 1 a run failed, 2 bad input, 130 interrupted. --debug (or "
                     f"{DEBUG_ENV}=1) shows the traceback of a failure.")
    parser.add_argument("--version", action=_VersionAction,
                        help="print the package's version, its git commit and Drake's version, and exit")
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", help=f"on a failure, show the traceback (also {DEBUG_ENV}=1)")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    _add = sub.add_parser

    def add_parser(name, **kwargs):
        kwargs.setdefault("formatter_class", _HelpFormatter)
        return _add(name, parents=[common], **kwargs)

    sub.add_parser = add_parser
    for module in experiment_commands():  # each experiment declares its options and runs its command
        command = sub.add_parser(module.COMMAND, **module.PARSER)
        module.add_arguments(command)
        # a module's RESUMABLE and GROWABLE: whether rerunning resumes, and the counts that may grow
        command.set_defaults(func=module.command, resumable=getattr(module, "RESUMABLE", False),
                             growable=tuple(getattr(module, "GROWABLE", ())))
    figs = sub.add_parser("figures", help="redraw a learning run's figures and Table V from its records")
    figs.add_argument("dir", help="the learning run's output folder (or its learning.json)")
    figs.set_defaults(func=cmd_figures)
    for command in sub.choices.values():  # every command that writes a folder can be told to replace it
        if any(a.dest == "out" for a in command._actions):
            command.add_argument("--overwrite", action="store_true",
                                 help="replace the records of another run (another command or other settings) "
                                      "in --out, deleting only the files its run file lists; write beside files no "
                                      "run listed; without it such a folder is refused")
    return parser


# What does not change a run's records: where it runs and how it reports. Every other option is part of the
# settings an output folder is held for (records.claim_folder).
_NOT_SETTINGS = {"out", "workers", "scheduler", "force", "debug", "overwrite", "func", "command", "replot",
                 "resumable", "growable"}


def _settings_of(args: argparse.Namespace) -> dict:
    """The options of a command that decide its records, as JSON values."""
    def plain(value):
        if isinstance(value, Path):
            return str(value)
        if isinstance(value, (list, tuple)):
            return [plain(v) for v in value]
        if isinstance(value, (str, int, float, bool)) or value is None:
            return value
        return str(value)

    return {k: plain(v) for k, v in sorted(vars(args).items()) if k not in _NOT_SETTINGS}


@contextmanager
def _holding_the_out_folder(args: argparse.Namespace) -> Iterator[None]:
    """records.claim_folder on --out for a command that writes one (not a --replot, which redraws its own)."""
    out = getattr(args, "out", None)
    if out is None or getattr(args, "replot", False):
        yield
        return
    from drake_biped.records import claim_folder

    with claim_folder(Path(out), args.command, _settings_of(args), overwrite=getattr(args, "overwrite", False),
                      growable=getattr(args, "growable", ()), gait=_gait_of(args)):
        yield


def _gait_of(args: argparse.Namespace) -> dict | None:
    """The identity of the gait a command walks (`resources.gait_identity`): its --params (a reproduction's
    --gait), else the paper's walker; None for a command that walks no gait of its options."""
    from drake_biped.params import EpisodeConfig
    from drake_biped.resources import gait_identity, load_gait

    if args.command == "reproduce":
        from drake_biped.experiments.reproduce import DEFAULT_STORY

        return gait_identity(load_gait(getattr(args, "gait", None) or DEFAULT_STORY))
    if not hasattr(args, "params"):
        return None
    return gait_identity(EpisodeConfig() if args.params is None else load_gait(args.params))


DEBUG_ENV = "DRAKE_BIPED_DEBUG"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 400 else text[:397] + "..."


def main(argv: list[str] | None = None) -> int:
    """Run one command. Exit codes: 0 done; 2 bad input (an option, a file, the model), one line naming it;
    1 a run that failed, one line; 130 interrupted (Ctrl-C), 143 stopped (SIGTERM, as a batch scheduler or
    `kill` stops a job), one line saying how to resume. A traceback only with --debug or DRAKE_BIPED_DEBUG=1."""
    parser = build_parser()
    args = parser.parse_args(argv)
    # tqdm's monitor thread, stopped by an atexit hook, prints a traceback of its own when a second Ctrl-C
    # arrives while the process exits; the bars need no monitor.
    from tqdm import tqdm

    tqdm.monitor_interval = 0
    debug = bool(getattr(args, "debug", False)) or os.environ.get(DEBUG_ENV, "") not in ("", "0")
    out = getattr(args, "out", None)
    again = ("run the same command again to resume: finished work is kept in " + str(out)
             if getattr(args, "resumable", False) and out else "run the same command again")
    with _failures_as_one_line(f"drake-biped {args.command}", debug, again), _sigterm_as_interrupt():
        with _holding_the_out_folder(args):
            return args.func(args)
    return 0  # not reached: a failure leaves by SystemExit


class Stopped(KeyboardInterrupt):
    """SIGTERM, raised in the main thread as Ctrl-C is: the run stops the same way and says how to resume."""


@contextmanager
def _sigterm_as_interrupt() -> Iterator[None]:
    """SIGTERM raises Stopped inside this block (in the main thread; elsewhere nothing changes)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise Stopped()

    previous = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def _failures_as_one_line(prefix: str, debug: bool, again: str,
                          traceback_hint: str = "rerun with --debug for the traceback") -> Iterator[None]:
    """The contract of `main` (and of `run_script`) around a command's work: every failure one line on
    standard error starting with `prefix`, and its exit code."""
    try:
        yield
    except KeyboardInterrupt as exc:
        if debug:
            raise
        if isinstance(exc, Stopped):
            _exit(143, f"{prefix}: stopped (SIGTERM); {again}")
        _exit(130, f"{prefix}: interrupted; {again}")
    except (ParameterError, ModelError) as exc:
        _remove_empty_made_folders()
        if debug:  # the traceback too, but bad input keeps its exit code
            import traceback

            traceback.print_exc()
        _exit(2, f"{prefix}: error: {_one_line(exc)}")
    except Exception as exc:  # a failed run: one line, the traceback on request
        if debug:
            raise
        _exit(1, f"{prefix}: failed: {type(exc).__name__}: {_one_line(exc)} ({traceback_hint})")
    except SystemExit as exc:  # pydrake raises a failed check inside Drake (DRAKE_DEMAND) as SystemExit
        from drake_biped.api_guard import drake_failure_message, is_drake_failure

        if debug or not is_drake_failure(exc):
            raise
        _exit(1, f"{prefix}: failed: DrakeFailure: a check inside Drake failed ({drake_failure_message(exc)}) "
                 f"({traceback_hint})")


def _remove_empty_made_folders() -> None:
    for folder in reversed(MADE):
        try:
            folder.rmdir()  # only an empty folder goes
        except OSError:
            pass
    MADE.clear()


def _exit(code: int, message: str) -> None:
    sys.stderr.flush()
    print(message, file=sys.stderr, flush=True)
    raise SystemExit(code)


if __name__ == "__main__":
    sys.exit(main())
