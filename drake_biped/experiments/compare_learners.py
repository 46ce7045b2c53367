"""Learners side by side (`drake-biped compare-learners`): each learner over the same trials x episodes of
the same gait from the same start, against the window map's best walking window (the known optimum), and
each learner's final windows re-walked with the plant step halved and from a nudged start
(`drake_biped.common.walks.rewalk`).

Each learner's run is an ordinary learning run in OUT/NAME/ (the same records, figures and resume as
`drake-biped learn --learner NAME`); a learner given in `reuse` with a longer run of the same settings (the
paper's GARB run of `learn`, say) takes that run's first episodes (`learning_runs.replay_run`) instead of walking
them again; OUT/compare.json, compare.md and compare.png put them side by side
(`drake_biped.analysis.learner_comparison`). Rerunning the same command resumes every unfinished run.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drake_biped.analysis.learner_comparison import (
    RUNNING,
    best_walking_window,
    compare,
    markdown,
)
from drake_biped.common.options import (
    add_episode_options,
    add_resumable_run_options,
    check_learning_size,
    cluster,
    count,
    episode_config,
    learner_names,
    print_lines,
)
from drake_biped.legacy import config_of_record
from drake_biped.paper import GARB_MEAN_S, GARB_VARIANCE_S2
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
)
from drake_biped.records import read_json, write_record
from drake_biped.versions import versions

__all__ = ["CompareSettings", "run", "summary_lines"]


@dataclass(frozen=True)
class CompareSettings:
    """The gait, its window map (a folder or its window_map.json), the learners and the common budget."""

    config: EpisodeConfig
    window_map: str
    learners: tuple[str, ...] = ("garb", "cmaes", "pgpe")
    trials: int = 5
    episodes: int = 300
    seed: int = 0
    mean: tuple[float, float] = GARB_MEAN_S
    variance: float = GARB_VARIANCE_S2
    reuse: dict[str, str] = field(default_factory=dict)  # learner name: folder of a longer run to replay
    force: bool = False  # run more than MAX_EPISODES episodes over all learners

    def __post_init__(self) -> None:
        if not self.learners:
            raise ParameterError("--learners: name at least one learner")
        for name, value in (("--trials", self.trials), ("--episodes", self.episodes)):
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise ParameterError(f"{name} {value!r}: must be an integer >= 1")
        check_learning_size(f"--learners {','.join(self.learners)} x --trials {self.trials} x --episodes "
                            f"{self.episodes}", len(self.learners) * self.trials * self.episodes, self.force)

    def map_path(self) -> Path:
        source = Path(self.window_map)
        return source / "window_map.json" if source.is_dir() else source

    def read_map(self) -> dict[str, Any]:
        """The window map, refused (ParameterError naming it) if missing or made for another gait."""
        path = self.map_path()
        if not path.is_file():
            raise ParameterError(f"--window-map {self.window_map}: no window_map.json there (run drake-biped "
                                 "window-map with the same --params first)")
        record = read_json(path, "--window-map")
        try:
            made = config_of_record(record["config"])
        except (KeyError, TypeError) as exc:
            raise ParameterError(f"--window-map {path}: not a window map ({exc})") from None
        mine = self.config.replace(window=TorqueFreeWindow())
        if made.replace(window=TorqueFreeWindow()) != mine:
            raise ParameterError(f"--window-map {path} was made for another gait or episode settings than "
                                 "these learners walk; map this gait (same --params, --distance, ...)")
        return record


def _learning_settings(settings: CompareSettings, name: str):
    from drake_biped.common.learning_runs import LearningSettings

    return LearningSettings(settings.config, settings.trials, settings.episodes, settings.seed,
                            mean=tuple(settings.mean), variance=settings.variance, learner=name)


def check(settings: CompareSettings, out: Path) -> None:
    """Everything a run would refuse, before a cluster starts: the map, the learners, damaged records."""
    from drake_biped.common import learning_runs

    settings.read_map()
    for name in settings.learners:
        learning_runs.check_resume(_learning_settings(settings, name).record(), Path(out) / name)


def run(settings: CompareSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """Run (or resume) every learner on `client` (a LocalCluster when None); write compare.json, .md and
    .png into `out`; return the record."""
    check_settings(settings, CompareSettings, "compare_learners.run")
    from drake_biped.analysis.figures import learner_comparison_figure
    from drake_biped.common import learning_runs
    from drake_biped.common.executor import client_or_local

    out = Path(out)
    wmap = settings.read_map()
    try:
        best = best_walking_window(wmap)
    except ValueError:  # no window walks: the learners are still compared with each other and with none
        best = None
    rows, curves = {}, {}
    with client_or_local(client) as c:
        for name in settings.learners:
            learn_settings = _learning_settings(settings, name).record()
            source = settings.reuse.get(name)
            replayed = source is not None and learning_runs.replay_run(Path(source), out / name, learn_settings)
            record = learning_runs.run(learn_settings, out / name, c, progress=progress)
            wall = read_json(out / name / "run.json", "compare-learners")["learning_wall_s"]
            rows[name] = {**compare(record, best), "wall_s": wall, "replayed_from": source if replayed else None}
            curves[name] = [t["episodes"] for t in record["trials"]]
    record = {
        "settings": {"learners": list(settings.learners), "trials": settings.trials, "episodes": settings.episodes,
                     "seed": settings.seed, "mean": list(settings.mean), "variance": settings.variance,
                     "window_map": str(settings.map_path()), "config": settings.config.to_dict()},
        "best_window": None if best is None else {k: best[k] for k in ("t1", "t2", "cost_of_transport", "cmt_change")},
        "no_window_cost_of_transport": wmap["baseline"]["cost_of_transport"],
        "running_length": RUNNING,
        "learners": rows,
        "versions": versions(),
    }
    write_record(out, "compare", record, markdown, lambda rec, path: learner_comparison_figure(curves, rec, path))
    return record










def summary_lines(record: dict[str, Any], out: Path) -> list[str]:
    return [markdown(record), f"wrote {out}/compare.json, compare.md, compare.png and one learning run per learner"]


COMMAND = "compare-learners"
# Rerunning the command on the same --out resumes it from its records, and these counts may be given larger to extend the run (never smaller).
RESUMABLE = True
GROWABLE = ("episodes", "trials")
PARSER = dict(help="learners side by side against the window map's best window")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped compare-learners`'s options."""
    add_episode_options(p)
    p.add_argument("--window-map", required=True,
                   help="the gait's window map (a window-map folder or its window_map.json): the known optimum")
    p.add_argument("--learners", type=learner_names, default=["garb", "cmaes", "pgpe"],
                   help="comma-separated (default garb,cmaes,pgpe)")
    p.add_argument("--trials", type=count, default=5, help="trials per learner")
    p.add_argument("--episodes", type=count, default=300, help="episodes per trial")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> CompareSettings:
    """The comparison's settings from the command's options."""
    return CompareSettings(episode_config(args), args.window_map, learners=tuple(args.learners), trials=args.trials,
                           episodes=args.episodes, seed=args.seed if args.seed is not None else 0, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    settings = settings_from_args(args)
    out = Path(args.out)
    check(settings, out)  # before a cluster starts
    with cluster(args) as client:
        record = run(settings, out, client)
    print_lines(summary_lines(record, out))
    return 0
