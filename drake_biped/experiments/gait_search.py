"""Search CPG and gait parameters for a gait that walks and in which torque-free windows save energy.

A (1 + lambda) evolution strategy: each generation mutates the parent `offspring` times (log-normal steps
for positive gains, Gaussian steps for angles and phases), scores every child, and keeps the best child
if it scores at least as well as the parent (`--method cmaes`: CMA-ES over the same mutations). Each gait file's
`about` names the search that found it.

What a candidate scores: `objectives.OBJECTIVES`, one entry per objective with its scoring function and what it
scores (`drake-biped gait-search --help` prints them).

Which parameters mutate (MUTATION_SETS): "servo" (MUTATIONS, the CPG's u_a, u_r, kappa among them), "paper"
(PAPER_MUTATIONS: the gains the paper does not print and the CPG phase the first swing starts from, the CPG and
the printed initiation held at what the start configuration has), "near_paper" (those and the CPG's u_a, u_r,
kappa), "coast" (MUTATIONS, the knee's hold torque, the torso's gains and the stance knee) or "paper_motor"
(what the paper does not print when the hip is its ODE motor); unless told, the one that fits the gait's hip drive
(`fitting_mutations`). The set a search record names "default" is "servo" (its name until the paper's walker
became the default gait).
Every generation is appended to `search.jsonl`; a rerun resumes from its last line (a damaged log is set aside
as search.jsonl.broken and resumed from its last readable generation before the damage). The children of a
generation are scored in parallel on Dask (`executor`).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import random
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drake_biped.common.options import (
    MAX_CANDIDATES,
    MAX_WALKS,
    add_episode_options,
    add_resumable_run_options,
    check_size,
    cluster,
    count,
    episode_config,
    number,
)
from drake_biped.experiments.objectives import ACCEPTANCE_WINDOWS, OBJECTIVES, POLICY_DRAWS, score
from drake_biped.legacy import config_of_record
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    check_settings,
)
from drake_biped.records import read_kept_lines, write_text_atomic
from drake_biped.versions import versions

# The swing knee's switches and torques, searched alike by every mutation set that moves them.
KNEE_MUTATIONS: dict[tuple[str, str], tuple[str, float, float, float]] = {
    ("gait", "knee_flex_torque"): ("log", 0.1, 0.1, 30.0),
    ("gait", "knee_extend_torque"): ("log", 0.1, 0.1, 30.0),
    ("gait", "knee_flex_max_rad"): ("log", 0.1, 0.05, 2.4),
    ("gait", "knee_flex_until_phase"): ("add", 0.1, 0.0, math.pi),
    ("gait", "knee_extend_phase"): ("add", 0.1, 0.5, 3.1),
    ("gait", "knee_extend_thigh_rad"): ("add", 0.04, -0.9, 0.9),
}

# (section, field): (kind, step at sigma = 0.1, lower bound, upper bound)
MUTATIONS: dict[tuple[str, str], tuple[str, float, float, float]] = {
    ("cpg", "u_a"): ("log", 0.1, 0.05, 20.0),
    ("cpg", "u_r"): ("log", 0.1, 0.5, 30.0),
    ("cpg", "kappa"): ("log", 0.1, 0.0, 9.0),
    ("gait", "hip_kp"): ("log", 0.1, 1.0, 2000.0),
    ("gait", "hip_kd"): ("log", 0.1, 0.1, 200.0),
    ("gait", "placement_gain"): ("log", 0.1, 0.0, 4.9),
    ("gait", "placement_velocity_gain"): ("log", 0.1, 0.0, 4.9),
    **KNEE_MUTATIONS,
    ("gait", "torso_pitch_rad"): ("add", 0.015, -0.45, 0.0),
    ("gait", "touchdown_min_phase"): ("add", 0.1, 0.3, 3.1),
}


# The gains the paper does not print, for a search that holds the CPG (Table III) and the initiation.
PAPER_MUTATIONS: dict[tuple[str, str], tuple[str, float, float, float]] = {
    ("gait", "hip_kp"): ("log", 0.1, 5.0, 2000.0),
    ("gait", "hip_kd"): ("log", 0.1, 0.5, 200.0),
    ("gait", "placement_gain"): ("add", 0.1, -2.0, 4.9),
    ("gait", "placement_velocity_gain"): ("add", 0.05, -2.0, 4.9),
    ("gait", "swing_offset_rad"): ("add", 0.05, -1.0, 1.0),
    ("gait", "torso_kp"): ("log", 0.1, 20.0, 5000.0),
    ("gait", "torso_kd"): ("log", 0.1, 2.0, 500.0),
    ("gait", "torso_pitch_rad"): ("add", 0.015, -0.45, 0.1),
    **KNEE_MUTATIONS,
    ("gait", "stance_knee_torque"): ("log", 0.1, 1.0, 30.0),
    ("gait", "ankle_kp"): ("log", 0.1, 1.0, 400.0),
    ("gait", "ankle_kd"): ("log", 0.1, 0.05, 40.0),
    ("gait", "touchdown_min_phase"): ("add", 0.1, 0.3, 3.1),
    ("initial", "cpg_phase_rad"): ("add", 0.2, 0.0, 3.1),
}
# The same, with the CPG's u_a, u_r and kappa free too: for the walker nearest Table III (objective "nearest").
NEAR_PAPER_MUTATIONS = {
    ("cpg", "u_a"): ("log", 0.1, 0.05, 20.0),
    ("cpg", "u_r"): ("log", 0.1, 0.5, 30.0),
    ("cpg", "kappa"): ("log", 0.1, 0.05, 9.0),
    **PAPER_MUTATIONS,
}
# For a swing that coasts to touchdown: MUTATIONS, the knee's hold torque in its passive middle (which keeps
# the shank from taking the coasting thigh's momentum), the torso's gains and the stance knee.
COAST_MUTATIONS = {
    **MUTATIONS,
    ("gait", "knee_hold_torque"): ("add", 0.3, -2.0, 10.0),
    ("gait", "torso_kp"): ("log", 0.1, 20.0, 5000.0),
    ("gait", "torso_kd"): ("log", 0.1, 2.0, 500.0),
    ("gait", "stance_knee_torque"): ("log", 0.1, 1.0, 30.0),
}
# What the paper does not print when the hip is its ODE motor (GaitParams.hip_drive "motor"): the motor's torque
# limit (up to the model's 40 N*m), the knees' torques and switches, the ankles' gains, the torso's law, the
# touchdown's phase and the first swing's phase; the CPG (Table III) and the printed initiation held. The motor
# is a velocity constraint (stiff by construction): its limit is its one parameter. The servo's gains and the
# swing reference's placement terms do not act under the motor and are not searched.
PAPER_MOTOR_MUTATIONS = {
    ("gait", "motor_limit_nm"): ("log", 0.1, 5.0, 40.0),
    **{k: v for k, v in PAPER_MUTATIONS.items()
       if k[1] not in ("hip_kp", "hip_kd", "placement_gain", "placement_velocity_gain", "swing_offset_rad")},
    ("gait", "knee_hold_torque"): ("add", 0.3, -2.0, 10.0),
}
MUTATION_SETS = {"servo": MUTATIONS, "paper": PAPER_MUTATIONS, "near_paper": NEAR_PAPER_MUTATIONS,
                 "coast": COAST_MUTATIONS, "paper_motor": PAPER_MOTOR_MUTATIONS}


def mutate(config: EpisodeConfig, rng: random.Random, sigma: float = 0.1, mutations=None) -> EpisodeConfig:
    """A child of `config`: every parameter in `mutations` (default MUTATIONS) moved by a random step
    scaled by sigma / 0.1."""
    values = {}
    for (section, name), (kind, step, lo, hi) in (MUTATIONS if mutations is None else mutations).items():
        value = getattr(getattr(config, section), name)
        if kind == "log":
            value = value * math.exp(rng.gauss(0.0, step * sigma / 0.1))
        else:
            value = value + rng.gauss(0.0, step * sigma / 0.1)
        values[f"{section}.{name}"] = min(hi, max(lo, value))
    return config.override(values, sampled=True)


def _child(args) -> tuple[dict, float, dict]:
    parent_dict, seed, sigma, windows, mutations, objective, draws = args
    child = mutate(config_of_record(parent_dict), random.Random(seed), sigma, MUTATION_SETS[mutations])
    value, detail = score(child, windows, objective, draws)
    return child.to_dict(), value, detail


@dataclass(frozen=True)
class GaitSearchSettings:
    """Where the search starts and how it steps (module docstring)."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    generations: int = 50
    offspring: int = 4
    sigma: float = 0.1
    seed: int = 0
    distance_m: float = 6.0
    windows: tuple[tuple[float, float], ...] = ACCEPTANCE_WINDOWS
    mutations: str | None = None  # None: the set that fits the gait's hip drive (`fitting_mutations`)
    objective: str = "windows"
    policy_draws: int = POLICY_DRAWS
    force: bool = False  # more than MAX_CANDIDATES candidates

    def __post_init__(self) -> None:
        if self.mutations is None:
            object.__setattr__(self, "mutations", fitting_mutations(self.config))
        if self.mutations not in MUTATION_SETS:
            raise ParameterError(f"mutations {self.mutations!r} is not one of {sorted(MUTATION_SETS)}")
        if self.objective not in OBJECTIVES:
            raise ParameterError(f"objective {self.objective!r} is not one of {list(OBJECTIVES)}")
        if self.generations < 1 or self.offspring < 1 or self.policy_draws < 1 or not self.sigma > 0 \
                or not self.distance_m > 0:
            raise ParameterError(
                f"generations ({self.generations!r}), offspring ({self.offspring!r}) and policy_draws "
                f"({self.policy_draws!r}) must be >= 1, "
                f"sigma ({self.sigma!r}) and distance_m ({self.distance_m!r}) > 0"
            )
        # A set that moves gains this gait leaves unread searches dimensions that change nothing; refused where
        # another set avoids them. A gain every set moves (the touchdown threshold, unread by the entrained
        # phase) cannot be avoided and is searched as a dimension that changes nothing.
        unread = {("gait", name) for name in self.config.gait.unread()}
        unavoidable = set.intersection(*(unread & set(m) for m in MUTATION_SETS.values()))
        moved = [name for key in MUTATION_SETS[self.mutations] if key in unread - unavoidable for name in key[1:]]
        if moved:
            fits = [k for k, m in MUTATION_SETS.items() if unread & set(m) == unavoidable]
            raise ParameterError(f"mutations {self.mutations!r} move {', '.join(moved)}, which this gait leaves "
                                 f"unread (hip_drive {self.config.gait.hip_drive!r}, phase_reading "
                                 f"{self.config.gait.phase_reading!r}): they would change nothing; "
                                 f"use one of {fits}")
        check_size(f"--generations {self.generations} x --offspring {self.offspring}",
                   self.generations * self.offspring, MAX_CANDIDATES, "candidates", self.force)
        check_size(f"--policy-draws {self.policy_draws}", self.policy_draws, MAX_WALKS, "walks per candidate",
                   self.force)


def _search_start(settings: GaitSearchSettings) -> EpisodeConfig:
    """The start configuration, walking the search's distance (with time enough for it)."""
    sim = settings.config.sim
    return settings.config.replace(sim=dataclasses.replace(
        sim, distance_m=settings.distance_m, max_time_s=max(sim.max_time_s, 6.0 * settings.distance_m)))


def _score_start(c, settings: GaitSearchSettings, start: EpisodeConfig, windows, log: Path, **extra) -> float:
    """Generation 0: score the start on the cluster and log it with the search's settings; its score."""
    from drake_biped.common.executor import DrakeGuarded

    value, detail = c.submit(DrakeGuarded(score), start, windows, settings.objective, settings.policy_draws,
                             pure=False).result()
    _append(log, {"generation": 0, "parent": start.to_dict(), "parent_score": value, "detail": detail,
                  "seed": settings.seed, "sigma": settings.sigma, "mutations": settings.mutations,
                  "objective": settings.objective, "objective_about": OBJECTIVES[settings.objective].about,
                  "policy_draws": settings.policy_draws, **extra, "versions": versions()})
    return value


def _generations(settings: GaitSearchSettings, first: int, desc: str, progress: bool, best: Callable[[], float]):
    """The generations still to run, counted on a progress bar when asked: yields (generation, note), note(text)
    showing text beside the bar; none once the best score `best()` has reached the objective's maximum."""
    maximum = OBJECTIVES[settings.objective].maximum
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=settings.generations, initial=min(first - 1, settings.generations), desc=desc, unit="gen")

    def note(text: str) -> None:
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(text)

    try:
        for gen in range(first, settings.generations + 1):
            if maximum is not None and best() >= maximum:
                if bar is not None:
                    bar.set_postfix_str(f"the objective's maximum ({maximum:g}) reached: stopped")
                return
            yield gen, note
    finally:
        if bar is not None:
            bar.close()


def run(settings: GaitSearchSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """Evolve from settings.config on `client` (a LocalCluster when None); write `search.jsonl` (one line
    per generation) and `best_config.json` (use it with --params); return the best and its score."""
    check_settings(settings, GaitSearchSettings, "gait_search.run")
    from drake_biped.common.executor import client_or_local, map_ordered

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    log = out / "search.jsonl"
    start, seed, sigma = _search_start(settings), settings.seed, settings.sigma
    windows = [tuple(w) for w in settings.windows]
    records = _read_log(log)
    _check_log(records, settings, "es", log)
    with client_or_local(client) as c:
        if records:
            last = records[-1]
            parent, parent_score, first = last["parent"], last["parent_score"], last["generation"] + 1
        else:
            parent, parent_score, first = start.to_dict(), _score_start(c, settings, start, windows, log), 1
        for gen, note in _generations(settings, first, "search", progress,
                                      lambda: parent_score):  # noqa: B023 (the best so far, read each generation)
            jobs = [(parent, seed * 1_000_003 + gen * 101 + k, sigma, windows, settings.mutations,
                     settings.objective, settings.policy_draws) for k in range(settings.offspring)]
            children = map_ordered(c, _child, jobs)
            best_dict, best_score, best_detail = max(children, key=lambda ch: ch[1])
            if best_score >= parent_score:
                parent, parent_score = best_dict, best_score
            _append(log, {"generation": gen, "parent": parent, "parent_score": parent_score,
                          "best_child_score": best_score, "child_scores": [ch[1] for ch in children],
                          "best_child_detail": best_detail})
            note(f"score {parent_score:+.3f}")
    write_text_atomic(out / "best_config.json", json.dumps(parent, indent=2) + "\n")
    return {"parent": parent, "score": parent_score}


def _coordinates(start: EpisodeConfig, mutations) -> list[tuple[str, str, str, float, float, float, float]]:
    """(section, name, kind, start value, step, lo, hi) of every searched parameter."""
    out = []
    for (section, name), (kind, step, lo, hi) in mutations.items():
        value = getattr(getattr(start, section), name)
        if kind == "log" and value <= 0.0:
            value = max(lo, 1e-3)
        out.append((section, name, kind, min(hi, max(lo, value)), step, lo, hi))
    return out


def decode(start: EpisodeConfig, mutations, x, sigma: float = 0.1) -> EpisodeConfig:
    """The configuration at CMA-ES coordinates x (0: the start): a parameter moves by x times its mutation
    step scaled by sigma / 0.1, in log for positive gains, within its bounds."""
    values = {}
    for xi, (section, name, kind, value, step, lo, hi) in zip(x, _coordinates(start, mutations)):
        value = value * math.exp(step * sigma / 0.1 * xi) if kind == "log" else value + step * sigma / 0.1 * xi
        values[f"{section}.{name}"] = min(hi, max(lo, float(value)))
    return start.override(values, sampled=True)


def _scored(args) -> tuple[float, dict]:
    config_dict, windows, objective, draws = args
    return score(config_of_record(config_dict), windows, objective, draws)


def run_cmaes(settings: GaitSearchSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The same search by CMA-ES (pycma) in the coordinates of `decode`, `offspring` candidates a
    generation (at least 4), unit initial step: `search.jsonl` (generation 0 scores the start; then one line
    per generation with every candidate's score, the best so far as `parent`) and `best_config.json`. The sampling is seeded from
    (seed, generation), so a rerun resumes by replaying the logged generations into a new strategy (no
    episode is run again) and repeats an uninterrupted search exactly."""
    import cma
    import numpy as np

    from drake_biped.common.executor import client_or_local, map_ordered

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    log = out / "search.jsonl"
    mutations = MUTATION_SETS[settings.mutations]
    start = _search_start(settings)
    windows = [tuple(w) for w in settings.windows]
    es = cma.CMAEvolutionStrategy(np.zeros(len(mutations)), 1.0, {
        "popsize": max(4, settings.offspring), "seed": settings.seed + 1, "verbose": -9, "bounds": [-6.0, 6.0]})

    def ask(gen: int):
        np.random.seed((settings.seed * 1_000_003 + gen) % 2**32)
        return es.ask()

    records = _read_log(log)
    _check_log(records, settings, "cmaes", log)
    for r in records[1:]:
        es.tell(ask(r["generation"]), [-v for v in r["child_scores"]])
    with client_or_local(client) as c:
        if records:
            best, best_score, first = records[-1]["parent"], records[-1]["parent_score"], records[-1]["generation"] + 1
        else:  # generation 0: the start itself, the best so far until a candidate beats it
            best, first = start.to_dict(), 1
            best_score = _score_start(c, settings, start, windows, log, method="cmaes")
        for gen, note in _generations(settings, first, "cma-es", progress,
                                      lambda: best_score):  # noqa: B023 (the best so far, read each generation)
            xs = ask(gen)
            configs = [decode(start, mutations, x, settings.sigma).to_dict() for x in xs]
            results = map_ordered(c, _scored, [(cfg, windows, settings.objective, settings.policy_draws)
                                                  for cfg in configs])
            scores = [r[0] for r in results]
            es.tell(xs, [-v for v in scores])
            k = int(np.argmax(scores))
            if scores[k] > best_score:
                best, best_score = configs[k], scores[k]
            _append(log, {"generation": gen, "parent": best, "parent_score": best_score,
                          "best_child_score": scores[k], "child_scores": scores, "best_child_detail": results[k][1],
                          "mean": [float(v) for v in es.mean], "step": float(es.sigma)})
            note(f"best {best_score:+.3f}")
    write_text_atomic(out / "best_config.json", json.dumps(best, indent=2) + "\n")
    return {"parent": best, "score": best_score}


def _read_log(path: Path) -> list[dict]:
    """The finished generations. Each builds on the one before: a line that does not read (a write cut short
    by a kill, or damage) sets the log aside as search.jsonl.broken, with a warning, and the search resumes
    after the last generation before it, as a search killed there would (records.read_kept_lines)."""
    return read_kept_lines(path, "a gait-search generation", in_order=True)


def _check_log(records: list[dict], settings: GaitSearchSettings, method: str, path: Path) -> None:
    """ParameterError naming the file unless its records are a search's (each line a generation with its
    parent and score) made with these settings (the objective, mutations, step, seed and method its first line
    records): a search is resumed as it began, never continued under another objective."""
    for i, r in enumerate(records):
        missing = [k for k in ("generation", "parent", "parent_score") if not isinstance(r, dict) or k not in r]
        if missing:
            raise ParameterError(f"{path}, line {i + 1}: not a gait-search log (no {missing[0]!r}); give another "
                                 "--out")
    first = records[0] if records else {}
    if first.get("generation") != 0:
        return
    wanted = {"objective": settings.objective, "mutations": settings.mutations, "sigma": settings.sigma,
              "seed": settings.seed, "policy_draws": settings.policy_draws, "method": method}
    recorded = {k: first.get(k, "es" if k == "method" else None) for k in wanted}
    if recorded["mutations"] == "default":  # the servo's set, by its former name
        recorded["mutations"] = "servo"
    differs = [f"{k} {recorded[k]!r} there, {wanted[k]!r} here" for k in wanted
               if recorded[k] is not None and recorded[k] != wanted[k]]
    about = first.get("objective_about")  # what the objective scored when the search began (absent before kept)
    if not differs and about is not None and about != OBJECTIVES[settings.objective].about:
        raise ParameterError(f"{path} is a search begun when the objective {settings.objective!r} scored otherwise: "
                             "it cannot be resumed under today's; give another --out")
    if differs:
        raise ParameterError(f"{path} is a search begun with other settings ({'; '.join(differs)}): rerun it with "
                             "its own settings to resume, or give another --out")


def _append(path: Path, record: dict) -> None:
    with open(path, "a") as f:
        f.write(json.dumps(record) + "\n")
        f.flush()


COMMAND = "gait-search"
# Rerunning the command on the same --out resumes it from its records, and these counts may be given larger to extend the run (never smaller).
RESUMABLE = True
GROWABLE = ("generations",)
PARSER = dict(help="evolve gait parameters for walking and torque-free savings",
              epilog="objectives: " + "  ".join(f"'{name}': {o.about}" for name, o in OBJECTIVES.items()))



def fitting_mutations(config: EpisodeConfig) -> str:
    """The mutation set a search of `config` takes unless told: "paper_motor" under the hip motor (the paper's
    walker: what the paper does not print, the servo's gains unread), "servo" under the servo."""
    return "paper_motor" if config.gait.hip_drive == "motor" else "servo"

def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped gait-search`'s options."""
    add_episode_options(p)
    p.add_argument("--generations", type=count, default=50, help="generations")
    p.add_argument("--offspring", type=count, default=4, help="children per generation")
    p.add_argument("--sigma", type=number("positive"), default=0.1, help="mutation scale")
    p.add_argument("--mutations", choices=list(MUTATION_SETS), default=None,
                   help="what mutates: 'servo' (CPG u_a, u_r, kappa and the servo's gains), 'paper' (only what "
                   "the paper does not print: the CPG and the initiation held), 'near_paper' (those "
                   "and u_a, u_r, kappa), 'coast' (servo, the knee's hold torque, the torso's "
                   "gains and the stance knee) or 'paper_motor' (what the paper does not print when the hip is "
                   "its ODE motor: the motor's limit, the knees, ankles, torso and touchdown phase); default: "
                   "'paper_motor' for a gait driven by the hip motor (the paper's walker), 'servo' for a servo's")
    p.add_argument("--method", choices=["es", "cmaes"], default="es",
                   help="'es': the (1 + offspring) evolution strategy; 'cmaes': CMA-ES (pycma), "
                   "offspring candidates a generation")
    p.add_argument("--objective", default="windows", choices=list(OBJECTIVES),
                   help="what a walker scores (each objective's definition below)")
    p.add_argument("--policy-draws", type=count, default=POLICY_DRAWS,
                   help="draws of the paper's start policy the 'policy', 'expected' and 'story' objectives walk "
                   "(default 12; a draw with t2 <= t1 is no window and costs no episode)")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> GaitSearchSettings:
    """The search's settings from the command's options."""
    config = episode_config(args)
    return GaitSearchSettings(
        config, generations=args.generations, offspring=args.offspring, sigma=args.sigma, seed=config.seed,
        distance_m=config.sim.distance_m if args.distance is not None else 6.0, mutations=args.mutations,
        objective=args.objective, policy_draws=args.policy_draws, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    settings = settings_from_args(args)
    search = run_cmaes if args.method == "cmaes" else run
    with cluster(args) as client:
        result = search(settings, Path(args.out), client)
    maximum = OBJECTIVES[settings.objective].maximum
    reached = ""
    if maximum is not None and result["score"] >= maximum:
        first = next(r["generation"] for r in _read_log(Path(args.out) / "search.jsonl") if r["parent_score"] >= maximum)
        reached = f" (the objective's maximum, reached in generation {first}: the search stops there)"
    print(f"best score {result['score']:+.3f}{reached}; parameters in {args.out}/best_config.json (use --params)")
    return 0
