"""What a reproduction runs (`drake-biped reproduce`): each shipped gait's story, the choices it makes where the
paper prints nothing (STORIES), and how much of each experiment a run does (QUICK, FULL)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from drake_biped.params import ParameterError

__all__ = ["DEFAULT_STORY", "FULL", "QUICK", "STEPS", "STORIES", "T1_SWEEP_HALF_SPAN_S", "Profile", "Story", "steps_of", "story_of"]

T1_SWEEP_HALF_SPAN_S = 0.08  # a story's bifurcation over t1 spans the learned t1 +- this, where it names no span


@dataclass(frozen=True)
class Story:
    """What a reproduction chooses on one shipped gait where the paper prints nothing: the gait (a shipped
    gait's name), the start (t1, t2 in s) and variance of the exploration matched to it (`learn_variant`), and
    the span of t1 (s) its dynamics step sweeps, the learned t2 kept (None: the learned t1 +-
    T1_SWEEP_HALF_SPAN_S, ending before t2), and the second window its time-step study refines beside the
    learned one. `why`: the reasons, for the report; `cost`: the wall time of its episodes against
    fast_servo's, for the time a run announces."""

    gait: str
    variant_start: tuple[float, float]
    variant_variance: float
    t1_sweep: tuple[float, float] | None = None
    why: str = ""
    cost: float = 1.0
    study_window: tuple[float, float] = (0.3, 0.6)

    def t1_values(self, window: tuple[float, float], num: int) -> tuple[float, ...]:
        """The values of t1 the dynamics step sweeps around the learned `window`."""
        import numpy as np

        if self.t1_sweep is not None:
            lo, hi = self.t1_sweep
        else:
            t1, t2 = window
            lo, hi = max(0.0, t1 - T1_SWEEP_HALF_SPAN_S), min(t1 + T1_SWEEP_HALF_SPAN_S, t2 - 0.02)
        return tuple(float(v) for v in np.round(np.linspace(lo, hi, num), 4))


STORIES = {
    "fast_servo": Story("fast_servo", (0.4, 0.4), 0.01, (0.30, 0.46),
                        why="our own faster gait (0.42 s steps): the variant starts where its windows begin (0.4, 0.4 s) "
                         "with a quarter of the paper's variance; t1 swept over 0.30-0.46 s around its learned 0.37 s"),
    "paper": Story("paper", (0.1, 0.2), 0.01,
                   why="the paper's walker (Table III's CPG, 0.90 s steps): its window map's cheapest window frees "
                       "the hip from 0.1 to 0.2 s, so the variant starts there with a quarter of the paper's "
                       "variance; t1 swept around the story's window (the learned one, else the map's cheapest); its "
                       "time-step study refines, beside it, the map's window late in the step (0.5-0.6 s)",
                   cost=3.5,  # 0.90 s steps at 0.71 m/s, at 0.5 ms: 3.4 x the plant steps per metre
                   study_window=(0.5, 0.6)),
}


# The story (its gait's name) a reproduction tells unless told: the paper's walker, EpisodeConfig(), whose full
# run ships (drake_biped/results/full_run.json).
DEFAULT_STORY = "paper"


def story_of(gait: str) -> Story:
    """The story of the gait named `gait` (STORIES)."""
    if gait not in STORIES:
        raise ParameterError(f"--gait {gait!r}: a reproduction is written for {sorted(STORIES)}")
    return STORIES[gait]


@dataclass(frozen=True)
class Profile:
    """How much of each experiment to run."""

    name: str
    distance_m: float  # level-ground episodes (the slopes always walk 10 m: 2 m level, 8 m up)
    grid_points: int  # per Table IV range
    grid_initiation_points: int
    learn: tuple[int, int]  # trials, episodes
    learn_variant: tuple[int, int]
    window_step_s: float
    stability_trials: int
    jacobian: bool
    margin_force_step_n: float  # the push-margin grid's spacing (N)
    slope: tuple[int, int]  # trials, episodes per slope
    slope_grid_full: bool  # the whole 2.0 deg grid (SLOPE_2DEG_*), or its 2 x 2 corner of lean and u_a
    time_steps: tuple[float, ...]
    time_step_distance_m: float
    expected_minutes: float  # on 2 cores
    compare: tuple[int, int] = (1, 6)  # trials, episodes per learner in the side-by-side comparison
    floquet_epsilons: tuple[float, ...] = ()  # the Floquet sweep's perturbations (empty: its default)
    floquet_newton_iterations: int = 6  # Newton's iterations towards each orbit (FloquetSettings' default)
    floquet_gaits: tuple[str, ...] = ("none", "learned")  # whose orbits: no window, the learned window
    steps: tuple[str, ...] = ()  # the steps run, in Reproduction.STEPS' order (empty: all of them)
    rewalk_distance_m: float = 10.0  # learned windows re-walked this far (110: a long-run mean after 10 m)
    # The dynamics step: values of t1 in the bifurcation over it, slopes in each slope sweep, starts per axis of
    # the basins' slice; and its walks' lengths (m): the attractors, the sweeps over t1 and the Table III walker,
    # the slopes (2 m level included), the basins
    dynamics: tuple[int, int, int] = (9, 12, 5)
    dynamics_walks_m: tuple[float, float, float, float] = (110.0, 60.0, 32.0, 30.0)

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


# The quick run: the walk, the cheap verdicts (Table III walked 10 m, or falling in a few steps on the default
# gait), the shipped full run's learned windows walked again, a few learning episodes and one Floquet orbit
# (4.3 min on 2 workers on the paper's walker; its minutes below are fast_servo's, Story.cost scales them).
# What it is too small to judge, its report leaves to the full run (analysis.reproduce_report.quick_rows).
QUICK = Profile("quick", 10.0, 2, 1, (2, 2), (2, 6), 0.2, 2, False, 25.0, (2, 25), False, (0.0005, 0.001), 10.0,
                1.3, floquet_epsilons=(1e-7, 3e-7, 1e-6), floquet_newton_iterations=5, floquet_gaits=("none",),
                steps=("walk", "table_iii", "paper_gait", "full_run", "learn", "energy", "floquet"))
# The full run: about 117 min on 2 workers from scratch on fast_servo (benchmarks/results/reproduce-full/,
# each step's summary.json; the paper's walker takes Story.cost times as long), its largest parts the learners'
# comparison (25 min), GARB's two learning runs (18 and 14 min), the push margins (21 min) and the Table IV grid
# (9 min).
FULL = Profile("full", 10.0, 3, 3, (5, 500), (5, 300), 0.1, 8, True, 5.0, (2, 100), True,
               (0.002, 0.001, 0.0005, 0.00025, 0.000125), 110.0, 120.0, compare=(5, 300), rewalk_distance_m=110.0)


# A reproduction's steps (`Reproduction`'s methods of these names): the paper's claims first; the learners side by
# side, beyond the paper and the costliest step, last.
STEPS = ("walk", "grid", "table_iii", "paper_gait", "full_run", "window_map", "learn", "learn_variant", "energy",
         "time_step", "stability", "push_margin", "floquet", "dynamics", "grid_slope2deg", "slope",
         "slope2deg", "compare_learners")


def steps_of(profile: Profile, gait: str = DEFAULT_STORY) -> tuple[str, ...]:
    """The steps a profile runs on `gait`, in order: its own list, or every step but the quick run's own two
    (the grid runs Table III; a full run has no full run to check). The shipped full run is checked only on
    the gait it was measured on."""
    from drake_biped.analysis.reproduce_report import full_run_gait_name
    from drake_biped.resources import full_run_digest

    chosen = profile.steps or tuple(s for s in STEPS if s not in ("table_iii", "full_run"))
    if "full_run" in chosen and full_run_gait_name(full_run_digest()) != gait:
        chosen = tuple(s for s in chosen if s != "full_run")
    return tuple(s for s in STEPS if s in chosen)
