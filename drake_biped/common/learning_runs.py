"""A learning run (Experiment 1): trials x episodes of a learner (GARB by default) learning the torque-free
period, on Dask.

Each trial is a learner (`drake_biped.learners`: "garb", "cmaes", "pgpe" or a registered one) with its own
seed; its episodes are sequential (episode i+1 samples from the
policy that episode i updated). Trials run in parallel: the driver (this process) holds the learners and
submits one episode task per trial at a time, each as soon as that trial's previous episode is recorded,
so the workers stay busy whatever the number of trials. Workers receive EpisodeConfig dictionaries.

Nothing lost: after every episode the trial's record (every episode so far and the learner's state) is
rewritten atomically (temporary file + rename) in OUT/trials/trial_K.json. Rerunning the same command
resumes every trial from its last recorded episode, and, since episodes are deterministic and the learner
carries its random generator, ends with exactly the result of an uninterrupted run. A worker that dies
costs the episode it was running: Dask runs that task again elsewhere. A rerun may ask for more trials or
episodes (a trial runs until it holds at least --episodes; one that holds more keeps them all, and its
evaluation uses the policy it ended with); seed, configuration and learner must match.

Reward (eq. 13, with a fall rule; `drake_biped.analysis.reward`): r = min(d / D, 1) / C_mt, where C_mt =
E+ / (m g d) is the dimensionless cost of transport (as in Table V), d the distance walked and D the
episode's target distance (10 m). A walk that completes gets 1 / C_mt; a fall is scaled down by the fraction
of the distance it covered. No distance or no work: r = 0.

Sampled times below 0 act as 0 in the episode (the learner updates with the sample itself); t2 <= t1
means no torque-free period, as in the paper.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.long_run import measure_text
from drake_biped.analysis.rewalks import measured_cost
from drake_biped.analysis.reward import reward
from drake_biped.common.learning_record import best_learned_trial, check_learning_record
from drake_biped.common.options import (
    check_learning_size,
)
from drake_biped.common.walks import REWALK_M, rewalk, window_of
from drake_biped.learners.garb import GarbLearner
from drake_biped.learners.registry import DEFAULT_LEARNER, learner_class, learner_from_state
from drake_biped.legacy import config_of_record
from drake_biped.paper import (
    GARB_BETA,
    GARB_MEAN_S,
    GARB_VARIANCE_S2,
    LEARNING_EPISODES,
    LEARNING_TRIALS,
    TABLE_II,
)
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    parameter_info,
)
from drake_biped.records import read_json, write_atomic
from drake_biped.versions import versions

# The paper's episode: walk 10 m (a run with shorter episodes is a small one, re-walked at its own length).
PAPER_EPISODE_M = 10.0

__all__ = ["LearningSettings", "Trial", "best_learned_trial", "check_learning_record", "check_resume",
           "check_rewalk_distance", "evaluate", "make_settings", "replay_run", "reward", "run", "run_learning"]

RECORD_VERSION = 1
# Where a run keeps its final means' re-walks, walk by walk, so that an interrupted evaluation resumes.
REWALKS_DIR = "rewalks"


def trial_seed(seed: int, trial: int) -> int:
    """The learner seed of trial `trial` in a run seeded `seed` (independent streams per trial)."""
    return int(np.random.SeedSequence([seed, trial]).generate_state(1)[0])


def _fixed(settings: dict[str, Any]) -> dict[str, Any]:
    """The settings a trial's record must share with the command resuming it: all but how many trials and
    episodes (a run may be extended; the schedule depends on the episode number only). Records that name no
    learner are GARB's."""
    fixed = {k: v for k, v in settings.items() if k not in ("trials", "episodes")}
    if "learner" in fixed:
        ls = {"name": DEFAULT_LEARNER, "options": {}, **fixed["learner"]}
        own = ("name", "mean", "variance", "options", "start_state", *learner_class(ls["name"]).SETTINGS)
        fixed["learner"] = {k: v for k, v in ls.items() if k in own}  # (records once gave every learner GARB's)
    return fixed


def new_learner(learner_settings: dict[str, Any], seed: int):
    """The learner of a run's settings["learner"] (make_settings), seeded `seed`."""
    return learner_class(learner_settings.get("name", DEFAULT_LEARNER)).from_settings(learner_settings, seed)


class Trial:
    """One trial's learner and record, kept on disk after every episode."""

    def __init__(self, out: Path, index: int, settings: dict[str, Any]):
        self.index = index
        self.path = out / "trials" / f"trial_{index}.json"
        self.settings = settings
        self.config = config_of_record(settings["config"])
        start = settings["learner"].get("start_state")
        if self.path.is_file():
            record = self._read_record()
            if _fixed(record.get("settings", {})) != _fixed(settings):
                raise ParameterError(
                    f"{self.path} was made with other settings (seed, episodes' config or learner); "
                    "use another --out, or the original options to resume"
                )
            self.episodes: list[dict[str, Any]] = record["episodes"]
            self.learner = learner_from_state(record["learner"])
        elif start is not None:  # a new run from a learned policy (the slope experiment)
            self.episodes = []
            self.learner = learner_from_state(start).restarted(seed=trial_seed(settings["seed"], index))
        else:
            self.episodes = []
            self.learner = new_learner(settings["learner"], trial_seed(settings["seed"], index))
        self.pending: np.ndarray | None = None

    def _read_record(self) -> dict[str, Any]:
        """The trial's record, or ParameterError naming the file and what to do: it is never overwritten."""
        remedy = (f"restore it, or delete it to run trial {self.index} again from its first episode (the same "
                  "seed gives the same episodes; the other trials are kept)")
        try:
            record = read_json(self.path, "trial record")
            learner_from_state(record["learner"])
            record["episodes"][:0]
        except ParameterError as exc:
            raise ParameterError(f"{exc}; {remedy}") from None
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(f"{self.path}: not a trial record ({type(exc).__name__}: {exc}); {remedy}") from None
        return record

    @property
    def done(self) -> int:
        return len(self.episodes)

    def next_config(self) -> dict[str, Any]:
        """Sample the next episode's window; its EpisodeConfig as a dictionary for a worker."""
        self.pending = self.learner.ask()
        return self.config.replace(window=window_of(self.pending), seed=self.settings["seed"]).to_dict()

    def record(self, result: dict[str, Any]) -> dict[str, Any]:
        """Update the learner with the finished episode and write the trial's record."""
        sample, self.pending = self.pending, None
        r = reward(result["cost_of_transport"], result["distance_m"], self.config.sim.distance_m)
        self.learner.tell(sample, r)
        row = {
            "episode": self.done + 1,
            "t1": float(sample[0]),
            "t2": float(sample[1]),
            "mean_t1": float(self.learner.mean[0]),
            "mean_t2": float(self.learner.mean[1]),
            "reward": r,
            **self.learner.info(),
            "cost_of_transport": result["cost_of_transport"],
            "distance_m": result["distance_m"],
            "fell": result["fell"],
            "fall_reason": result["fall_reason"],
            "duration_s": result["duration_s"],
            "steps": len(result["steps"]),
        }
        self.episodes.append(row)
        self._write()
        return row

    def replay(self, episodes: list[dict[str, Any]]) -> None:
        """Take the first episodes of another run of this trial's learner, seed and configuration (a longer run
        of the same fixed settings): the learner draws each sample again, which must be the recorded one, and
        is told the recorded reward; no episode is walked. The record is written once, at the end."""
        for e in episodes:
            sample = self.learner.ask()
            if (float(sample[0]), float(sample[1])) != (e["t1"], e["t2"]):
                raise ParameterError(f"trial {self.index}, episode {e['episode']}: the learner draws "
                                     f"({sample[0]!r}, {sample[1]!r}), the record holds ({e['t1']!r}, {e['t2']!r}); "
                                     "the record was not made by this learner and seed")
            self.learner.tell(sample, e["reward"])
            self.episodes.append(e)
        self._write()

    def _write(self) -> None:
        write_atomic(self.path, {"record_version": RECORD_VERSION, "trial": self.index,
                                 "learner_seed": trial_seed(self.settings["seed"], self.index),
                                 "settings": self.settings, "episodes": self.episodes,
                                 "learner": self.learner.state()})


def check_policy_spread(variance: float) -> None:
    """ParameterError naming --variance when the policy's standard deviation per time exceeds the span a window's
    time is declared over (TorqueFreeWindow's bounds, 0-10 s): its draws would mostly fall outside the windows
    an episode can walk (below 0 they act as 0), and what it learned would say nothing of the windows."""
    lo, hi = parameter_info(TorqueFreeWindow, "start_s")["bounds"]
    if isinstance(variance, (int, float)) and math.isfinite(variance) and variance > (hi - lo) ** 2:
        raise ParameterError(f"--variance {variance:g}: a standard deviation of {math.sqrt(variance):g} s is wider "
                             f"than a window's declared times ({lo:g}-{hi:g} s); give at most {(hi - lo) ** 2:g} s^2")


def make_settings(config: EpisodeConfig, trials: int, episodes: int, seed: int,
                  mean=(0.5, 0.5), variance: float = 0.04, beta: float = 0.8, schedule=TABLE_II,
                  learner: str = DEFAULT_LEARNER, options: dict[str, Any] | None = None, force: bool = False
                  ) -> dict[str, Any]:
    """The settings record of a learning run, checked (ParameterError naming the option), its size bounded
    (`check_learning_size`) before any work."""
    if not isinstance(trials, int) or isinstance(trials, bool) or trials < 1:
        raise ParameterError(f"--trials {trials!r}: must be an integer >= 1")
    if not isinstance(episodes, int) or isinstance(episodes, bool) or episodes < 1:
        raise ParameterError(f"--episodes {episodes!r}: must be an integer >= 1")
    check_learning_size(f"--trials {trials} x --episodes {episodes}", trials * episodes, force)
    if not isinstance(seed, int) or seed < 0:
        raise ParameterError(f"--seed {seed!r}: must be an integer >= 0")
    check_policy_spread(variance)
    try:
        cls = learner_class(learner)
    except ParameterError as exc:
        raise ParameterError(f"--learner {learner!r}: {exc}") from None
    own = {"beta": float(beta), "schedule": [list(b) for b in schedule]}  # GARB's settings
    if "beta" in cls.SETTINGS:
        GarbLearner(mean, variance, beta, schedule)  # validates them
    elif own != {"beta": GARB_BETA, "schedule": [list(b) for b in TABLE_II]}:
        raise ParameterError(f"beta and schedule are the settings of GARB's learning rate; learner {learner!r} "
                             "takes none (its own are its options)")
    learner_settings = {"mean": list(map(float, mean)), "variance": float(variance),
                        **{k: own[k] for k in cls.SETTINGS}}
    if learner != DEFAULT_LEARNER or options:  # a record names its learner unless it is the default's
        learner_settings.update(name=learner, options=dict(options or {}))
        try:
            new_learner(learner_settings, 0)  # validates the name and the options
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"--learner {learner!r}: {exc}") from None
    return {
        "trials": trials,
        "episodes": episodes,
        "seed": seed,
        "config": config.replace(window=TorqueFreeWindow(0.0, 0.0)).to_dict(),
        "learner": learner_settings,
    }


# What the learning figures and Table V read of each recorded episode.
def replay_run(source: Path, out: Path, settings: dict[str, Any]) -> bool:
    """Write into `out` the trial records of the run `settings` from a run in `source` with the same fixed
    settings and at least as many trials and episodes: each trial's first settings["episodes"] episodes, its
    learner replayed through them (`Trial.replay`), exactly the records the run itself would write, without
    walking an episode. Trials `out` already holds are kept. False, writing nothing, when `source` cannot give
    them."""
    records = []
    for k in range(settings["trials"]):
        path = Path(source) / "trials" / f"trial_{k}.json"
        record = read_json(path, "trial record") if path.is_file() else None
        if record is None or _fixed(record.get("settings", {})) != _fixed(settings) \
                or len(record.get("episodes", [])) < settings["episodes"]:
            return False
        records.append(record)
    (Path(out) / "trials").mkdir(parents=True, exist_ok=True)
    for k, record in enumerate(records):
        trial = Trial(Path(out), k, settings)
        if not trial.done:
            trial.replay(record["episodes"][:settings["episodes"]])
    return True


def episode_key(config: dict[str, Any]) -> str | None:
    """The key under which run_learning walks a configuration once: every configuration whose window is
    inactive (t2 <= t1) walks the same episode, whatever its window's numbers (the gate is exactly 0 there, and
    episodes are deterministic). None for an active window (a learner's draws of one almost never repeat)."""
    window = config["window"]
    if window["end_s"] > window["start_s"]:
        return None
    return json.dumps({**config, "window": None}, sort_keys=True)


def run_learning(
    out: Path,
    settings: dict[str, Any],
    client,
    progress: Callable[[int, int, float | None], None] | None = None,
    stop_after: int | None = None,
) -> tuple[list[Trial], int]:
    """Run (or resume) every trial to settings["episodes"] on the Dask `client`.

    Draws without a window are walked once per call (`episode_key`): a trial whose draw has no window takes the
    result of that walk (waiting for it while it runs), which is the result its own walk would give, so the
    records are those of walking every episode. progress(done, total, latest_mean_reward) after each recorded
    episode. stop_after: return once this many new episodes are recorded (for tests of resuming). Returns the
    trials and the number of episodes this call recorded."""
    from distributed import as_completed

    from drake_biped.common.executor import episode_task

    out.mkdir(parents=True, exist_ok=True)
    (out / "trials").mkdir(exist_ok=True)
    trials = [Trial(out, k, settings) for k in range(settings["trials"])]
    total = settings["trials"] * settings["episodes"]
    done = sum(t.done for t in trials)
    latest: dict[int, float] = {t.index: t.episodes[-1]["reward"] for t in trials if t.episodes}
    if progress is not None:
        progress(done, total, float(np.mean(list(latest.values()))) if latest else None)
    walked: dict[str, dict[str, Any]] = {}  # episode_key -> the result of its walk
    in_flight: dict[str, Any] = {}  # episode_key -> the future walking it
    waiting: dict[Any, tuple[str | None, list[Trial]]] = {}  # a walk in flight -> its key, the trials taking it
    queue = as_completed()
    new = 0

    def finish(t: Trial, result: dict[str, Any]) -> bool:
        """Record `t`'s episode; whether to stop (stop_after reached)."""
        nonlocal new
        row = t.record(result)
        new += 1
        latest[t.index] = row["reward"]
        if progress is not None:
            progress(sum(x.done for x in trials), total, float(np.mean(list(latest.values()))))
        return stop_after is not None and new >= stop_after

    def advance(t: Trial) -> bool:
        """Give `t` its next episodes: recorded at once while they repeat a finished walk without a window, then
        one walk joined or submitted. Whether to stop."""
        while t.done < settings["episodes"]:
            config = t.next_config()
            key = episode_key(config)
            if key in walked:
                if finish(t, walked[key]):
                    return True
                continue
            future = in_flight.get(key) if key is not None else None
            if future is None:
                future = client.submit(episode_task, config, pure=False)
                waiting[future] = (key, [])
                queue.add(future)
                if key is not None:
                    in_flight[key] = future
            waiting[future][1].append(t)
            return False
        return False

    stop = any(advance(t) for t in trials)
    for future in queue:
        if stop:
            break
        result = future.result()
        key, takers = waiting.pop(future)
        if key is not None:
            walked[key] = result
            del in_flight[key]
        for t in takers:
            if finish(t, result) or advance(t):
                stop = True
                break
    for f in waiting:
        f.cancel()
    return trials, new


def check_rewalk_distance(settings: dict[str, Any], distance_m: float) -> None:
    """ParameterError naming --rewalk-distance unless the re-walks' configuration at `distance_m` is one an
    episode takes (it is walked only after the learning)."""
    try:
        config_of_record(settings["config"]).override(
            {"sim.distance_m": distance_m, "sim.max_time_s": max(settings["config"]["sim"]["max_time_s"],
                                                                 6.0 * distance_m)})
    except ParameterError as exc:
        raise ParameterError(f"--rewalk-distance {distance_m:g}: {exc}") from None


def evaluate(settings: dict[str, Any], trials: list[Trial], client, rewalk_distance_m: float = REWALK_M,
             keep: Path | None = None) -> dict[str, Any]:
    """Table V's measured rows: the gait without a window, and with each trial's final policy mean; and every
    one of them re-walked with the plant step halved and from 0.95 and 1.05 x the initiation speed
    (`drake_biped.common.walks.rewalk`, each walk kept in the folder `keep` when one is given), as "rewalks"."""
    base = config_of_record(settings["config"])
    means = [{"trial": t.index, "t1": float(t.learner.mean[0]), "t2": float(t.learner.mean[1])} for t in trials]
    rewalks = rewalk(base, means, client, distance_m=rewalk_distance_m, keep=keep)
    no_window = _as_measured(rewalks["no_window"]["as_learned"])
    learned = [dict(_as_measured(t["walks"]["as_learned"]), trial=t["trial"], t1=t["t1"], t2=t["t2"])
               for t in rewalks["trials"]]
    walked = [measured_cost(r) for r in learned if not r["fell"] and measured_cost(r)]
    measure = measure_text(rewalks["distance_m"])
    out = {"measure": measure,
           "no_window": no_window, "learned": learned}
    if walked and measured_cost(no_window) and not no_window["fell"]:
        out["learned_mean_cost_of_transport"] = float(np.mean(walked))
        out["learned_std_cost_of_transport"] = float(np.std(walked))
        out["reduction"] = 1.0 - out["learned_mean_cost_of_transport"] / measured_cost(no_window)
    out["learned_walks"] = len(walked)
    out["rewalks"] = rewalks
    out["episode"] = _episode_measure(base, means, client)
    return out


def _as_measured(row: dict[str, Any]) -> dict[str, Any]:
    """A re-walk's row with its long-run C_mt as "cost_of_transport" (the whole walk's kept beside it)."""
    return {**row, "episode_cost_of_transport": row["cost_of_transport"], "cost_of_transport": measured_cost(row)}


def _episode_measure(base: EpisodeConfig, means: list[dict[str, Any]], client) -> dict[str, Any]:
    """The paper's measure beside the long-run one: the gait without a window and each trial's final policy
    mean walked one learning episode's distance (its C_mt over the whole walk, initiation included)."""
    from drake_biped.common.executor import episode_task, map_ordered

    configs = [base.replace(window=TorqueFreeWindow())] + [base.replace(window=window_of((m["t1"], m["t2"])))
                                                          for m in means]
    results = map_ordered(client, episode_task, [c.to_dict() for c in configs])
    costs = [None if r["fell"] else r["cost_of_transport"] for r in results]
    walked = [c for c in costs[1:] if c]
    out = {"distance_m": base.sim.distance_m, "no_window": costs[0], "learned": costs[1:]}
    if walked and costs[0]:
        out["reduction"] = 1.0 - float(np.mean(walked)) / costs[0]
    return out


def learning_record(settings: dict[str, Any], trials: list[Trial], evaluation: dict[str, Any] | None) -> dict:
    """The contents of learning.json (no wall times: a resumed run writes the same file)."""
    return {
        "record_version": RECORD_VERSION,
        "settings": settings,
        "versions": {k: v for k, v in versions().items()},
        "trials": [{"trial": t.index, "learner_seed": trial_seed(settings["seed"], t.index),
                    "episodes": t.episodes, "final_mean": t.learner.mean.tolist()} for t in trials],
        "evaluation": evaluation,
    }


@dataclass(frozen=True)
class LearningSettings:
    """A learning run: `trials` independent learners (`learner`, GARB by default, with `options`) of
    `episodes` episodes each on `config`'s gait, the policy starting at `mean` with `variance` per time
    (the paper's settings by default). beta and schedule are GARB's settings (Learner.SETTINGS): another learner
    refuses them and takes `options`."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    trials: int = LEARNING_TRIALS
    episodes: int = LEARNING_EPISODES
    seed: int = 0
    mean: tuple[float, float] = GARB_MEAN_S
    variance: float = GARB_VARIANCE_S2
    beta: float = GARB_BETA
    schedule: tuple[tuple[int | None, float], ...] = TABLE_II
    learner: str = DEFAULT_LEARNER
    options: dict[str, Any] = field(default_factory=dict)
    force: bool = False  # run more than MAX_EPISODES episodes

    def __post_init__(self) -> None:
        self.record()  # every value checked, the size bounded, before any work

    def record(self) -> dict[str, Any]:
        """The settings as every trial record and learning.json hold them (`make_settings`)."""
        return make_settings(self.config, self.trials, self.episodes, self.seed, mean=tuple(self.mean),
                             variance=self.variance, beta=self.beta, schedule=self.schedule,
                             learner=self.learner, options=self.options, force=self.force)


def run(settings: LearningSettings | dict[str, Any], out: Path, client=None, progress: bool = True,
        workers: int | None = None, scheduler: str | None = None, rewalk_distance_m: float | None = None
        ) -> dict[str, Any]:
    """Run or resume the learning on `client` (a LocalCluster when None), evaluate the final policies, and
    write learning.json, run.json, fig4_reward.png, fig5_cmt.png, fig6_times.png and table_v.md into `out`
    (the re-walks kept walk by walk in `out`/rewalks, so that an interrupted evaluation resumes).
    `settings`: a LearningSettings, or the record dictionary of one. workers/scheduler: what run.json
    records of the cluster. `rewalk_distance_m`: how far the final policy means are re-walked (their long-run
    C_mt is measured from REWALK_M on); None: REWALK_M, or the episodes' own distance when that is under the
    paper's 10 m (a small run). Returns the learning record."""
    from drake_biped.analysis.figures import learning_figures
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import RunProgress

    out = Path(out)
    record_settings = settings.record() if isinstance(settings, LearningSettings) else settings
    if rewalk_distance_m is None:
        distance = record_settings["config"]["sim"]["distance_m"]
        rewalk_distance_m = REWALK_M if distance >= PAPER_EPISODE_M else distance
    check_rewalk_distance(record_settings, rewalk_distance_m)  # before the learning, not after it
    versions()  # the code version this process runs, recorded now (it is cached), not at the run's end
    report = RunProgress(out, workers, scheduler, "learning", "episode", bar=progress, command="learn")
    try:
        with client_or_local(client) as c:
            trials, new = run_learning(out, record_settings, c, report)
            report.log.update(new, force=True)
            evaluation = evaluate(record_settings, trials, c, rewalk_distance_m, keep=out / REWALKS_DIR)
    finally:
        report.close()
    record = learning_record(record_settings, trials, evaluation)
    write_atomic(out / "learning.json", record)
    report.log.update(new, learning=False, finished=True)
    learning_figures(record, out)
    return record


def check_resume(settings: dict[str, Any], out: Path) -> None:
    """Read every trial record a rerun into `out` would resume (ParameterError naming a damaged one or one
    made with other settings), before any cluster is started."""
    for k in range(settings["trials"]):
        Trial(Path(out), k, settings)
