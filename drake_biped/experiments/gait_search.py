"""Search CPG and gait parameters for a gait that walks and in which torque-free windows save energy.

A (1 + lambda) evolution strategy: each generation mutates the parent `offspring` times (log-normal steps
for positive gains, Gaussian steps for angles and phases), scores every child, and keeps the best child
if it scores at least as well as the parent (`--method cmaes`: CMA-ES over the same mutations). This is how
the shipped gaits were found: "steady" (the first default) from a walker of an earlier random search, and
`params.DEFAULT_CPG`/`DEFAULT_GAIT` by the "hold" objective (docs/MODEL.md).

Score of a configuration that does not walk `distance_m` without a window: -9 + 8 * (the fraction of the
distance it walked), so that a search from a gait that falls climbs towards one that walks (the "robust",
"story" and "hold..." objectives score fallers themselves). Of one that walks, by the objective:
OBJECTIVES, one entry per objective with its scoring function and what it scores (`drake-biped
gait-search --help` prints them).

Which parameters mutate: "default" (MUTATIONS, the CPG's u_a, u_r, kappa among them) or "paper"
(PAPER_MUTATIONS: the gains the paper does not print and the CPG phase the first swing starts from, the
CPG and the printed initiation held at what the start configuration has)
or "near_paper" (those and the CPG's u_a, u_r, kappa) or "coast" (MUTATIONS, the knee's hold torque, the
torso's gains and the stance knee).
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

from drake_biped.analysis.long_run import TRANSIENT_M
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
from drake_biped.params import (
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
    config_of_record,
    walked_the_distance,
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

ACCEPTANCE_WINDOWS = ((0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.35, 0.65), (0.2, 0.7))
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
MUTATION_SETS = {"default": MUTATIONS, "paper": PAPER_MUTATIONS, "near_paper": NEAR_PAPER_MUTATIONS,
                 "coast": COAST_MUTATIONS, "paper_motor": PAPER_MOTOR_MUTATIONS}
# The "robust" objective's changes to the walk without a window, and the half step's allowed C_mt change.
ROBUST_CHECKS = ("half_step", "speed_0.95", "speed_1.05", "push_forward", "push_backward")
ROBUST_CMT_CHANGE = 0.02
# The "converged" objective's targets at the walk's own plant step: the step period's spread after the transient,
# how often the swing hip's torque changes sign on a 10 m walk after CONVERGED_AFTER_S (the motor's chatter), and
# the half step's relative C_mt change (the robust objective allows ROBUST_CMT_CHANGE).
CONVERGED_STEP_SD_S, CONVERGED_SIGN_CHANGES, CONVERGED_AFTER_S = 1e-3, 20.0, 3.0
CONVERGED_CMT_CHANGE = 0.005
# Hip off from t1 until the swing foot lands (t2 beyond any step): a gait that coasts to touchdown.
COAST_WINDOWS = ((0.2, 5.0), (0.3, 5.0), (0.4, 5.0), (0.5, 5.0))
# The "hold" objective's windows (t1 across the end of the step, t2 past any step) and how far below the best
# window's reward gain a window still lies within the learner's reach.
HOLD_WINDOWS = tuple((round(0.30 + 0.02 * i, 2), 1.2) for i in range(14))
HOLD_PLATEAU, HOLD_MARGIN_S = 0.05, 0.02
# t1 of the means GARB with the paper's settings ended on: 0.37-0.45 s on hold-g1 (reward peak 0.32 s) and
# 0.41-0.47 s on cand1 (benchmarks/results/learn-*); 0.30-0.53 s on coasting_wide at 0.5 ms.
HOLD_BAND = (0.36, 0.48)
# The "hold-long" objective: windows across HOLD_BAND (hip off from t1 until the foot lands), each walked
# HOLD_LONG_M and judged by its long-run C_mt after the initiation's 10 m (on the contact with a continuous
# limit, GARB's means on the default gait ended at t1 0.37-0.44 s; those past the powered step's end, 0.43 s,
# held in one walk and not in the next).
HOLD_LONG_WINDOWS = ((0.36, 1.2), (0.40, 1.2), (0.44, 1.2), (0.48, 1.2))
HOLD_LONG_M = 40.0
# The "hold-step" objective: windows placed by the gait's own powered step period T (its long walk without a
# window): below it, t1 = T - HOLD_STEP_BELOW_S judged long-run like "hold-long"; past it, t1 = T +
# HOLD_STEP_PAST_S judged by the learner's own 10 m episode from the initiation, whose saving there is what
# draws GARB's means past the step's end (the initiation's first steps run longer than the steady ones, so a
# window that never acts in the steady gait still acts, and saves, in a 10 m episode).
HOLD_STEP_BELOW_S = (0.08, 0.04, 0.015)
HOLD_STEP_PAST_S = (0.015, 0.04)
# The "hold-slow" objective: "hold-step" on a gait whose powered step lasts at least HOLD_SLOW_FLOOR_S. GARB
# starts at t1 = 0.5 s; on a shorter step every window near its start is no window in the steady gait, and the
# only way down is the initiation's lure. Each second short of the floor costs HOLD_SLOW_PENALTY.
HOLD_SLOW_FLOOR_S = 0.55
HOLD_SLOW_PENALTY = 4.0
# The "hold-edge" objective: windows across the top of the band where GARB's means ended on the default and
# u_r 8.0 gaits (t1 0.37-0.44 s), judged long-run like "hold-long". The coasting gait such windows lock into is
# the only attractor up to an edge in t1 that moves with the plant step (on the u_r 8.0 gait t1 0.42 s saves 46 %
# at 1 and at 0.5 ms, t1 0.44 s 35 % at 1 ms and 4 % at 0.5 ms), so the half step is the check that decides.
# Less the larger 10 m saving at HOLD_EDGE_LURE (the learner's start region: a saving there holds GARB's means
# where the steady gait's windows do not act).
HOLD_EDGE_WINDOWS = ((0.40, 1.2), (0.42, 1.2), (0.44, 1.2))
HOLD_EDGE_LURE = ((0.48, 1.2), (0.50, 1.2))
# The "hold-pull" objective: "hold-edge" plus the mean reward gain of fixed draws of the paper's start policy
# (the "expected" objective): what the learner's first episodes meet. On the first gait "hold-edge" found, every
# window up to t1 0.44 s held at half the step, yet two of five GARB trials left for t2 < t1 (no window), where
# equal rewards give no gradient back (docs/RESULTS.md).
# The "hold-lure" objective: the band held one window further (HOLD_LURE_WINDOWS, to t1 0.46 s) and the 10 m
# saving at HOLD_EDGE_LURE rewarded (HOLD_LURE_WEIGHT) rather than subtracted. GARB's means come back from the
# no-window half of its start only through a window near it that saves over 10 m, and then stop just inside the
# edge of that saving (docs/RESULTS.md): the band must hold, at half the step too, up to where they stop.
HOLD_LURE_WINDOWS = ((0.40, 1.2), (0.42, 1.2), (0.44, 1.2), (0.46, 1.2))
HOLD_LURE_WEIGHT = 0.5
# The "hold-sure" objective: "hold-lure" less what its gait still failed on (docs/RESULTS.md). GARB's first
# episodes (step size 0.1) can carry a mean down the diagonal towards t1 0, where windows that fall over 10 m
# (SURE_EARLY_WINDOWS) drive it on into t2 < t1 with a fall's low reward; and the paper's +-PUSH_FORCE_N, pushed
# in steady state as `push-margin` pushes (SURE_PUSH_PHASES phases of the first step after SURE_SETTLE_S of a
# SURE_PUSH_M walk), without a window and with SURE_PUSH_WINDOW from the band. Each costs its penalty times the
# fraction that falls. And the walk without a window at a quarter of the plant step, whose long-run C_mt must stay
# within SURE_STEP_TOLERANCE of the step's (the hold-lure gait's moved by 1.4 % over 110 m): SURE_STEP_PENALTY x
# the excess (1 for a fall).
SURE_EARLY_WINDOWS = ((0.0, 0.3), (0.0, 0.45), (0.0, 0.6), (0.1, 0.5), (0.2, 0.6), (0.3, 0.7))
SURE_PUSH_PHASES, SURE_SETTLE_S, SURE_PUSH_M = 6, 5.0, 12.0
SURE_PUSH_WINDOW = (0.42, 1.2)
SURE_FALL_PENALTY, SURE_PUSH_PENALTY = 1.0, 2.0
SURE_STEP_TOLERANCE, SURE_STEP_PENALTY = 0.01, 10.0
# The "hold-fine" objective: "hold-sure" with its one quarter step replaced by the time-step study's ladder. The
# holding gait agreed at a quarter of the step over 40 m, yet its walk without a window moved by 2.0 % between a
# half and an eighth of the step over 310 m (docs/RESULTS.md): FINE_STEP_M walks without a window at each of
# FINE_STEP_FRACTIONS of the plant step, the gait's clock kept, and SURE_STEP_PENALTY x how far the largest change
# from the finest moves beyond SURE_STEP_TOLERANCE (1 when one falls).
FINE_STEP_FRACTIONS = (1.0, 0.5, 0.25, 0.125)
FINE_STEP_M = 60.0
# The "floquet" score of a walker whose orbit cannot be linearised: below any other walker's, and no
# faller scores more (a faller's -9 + 8 * fraction walked stays below -1).
FLOQUET_UNDEFINED = -1.0


def distance_from_table_iii(cpg) -> float:
    """|ln(u_a / 2)| + |ln(u_r / 2.1)| + |ln(kappa / 1.8)|: how far a CPG is from Table III's, in relative
    terms (alpha and u_eta are not searched)."""
    from drake_biped.paper import TABLE_III

    return sum(abs(math.log(getattr(cpg, k) / TABLE_III[k])) for k in ("u_a", "u_r", "kappa"))
# The paper's learner starts at (0.5, 0.5) with variance 0.04 (Table II): fixed draws of that policy.
POLICY_START, POLICY_VARIANCE, POLICY_DRAWS = (0.5, 0.5), 0.04, 12


# The "landscape" objective's window map (t2 > t1) and push test.
LANDSCAPE_WINDOWS = tuple((t1, t2) for t1 in (0.0, 0.2, 0.4, 0.6, 0.8) for t2 in (0.2, 0.4, 0.6, 0.8, 1.0, 1.2)
                          if t2 > t1)
PUSH_FORCE_N, PUSH_PENALTY = 20.0, 0.25
# The best policy mean's gain counts up to this (the paper's learner needs it large enough to be worth finding,
# and then needs the start's gain above all).
BEST_GAIN_CAP = 0.2


def policy_draws(count: int = POLICY_DRAWS, seed: int = 0) -> list[tuple[float, float]]:
    """`count` fixed draws (t1, t2) of the paper's starting policy, times below 0 taken as 0."""
    rng = random.Random(seed)
    sd = math.sqrt(POLICY_VARIANCE)
    return [(round(max(0.0, rng.gauss(POLICY_START[0], sd)), 6), round(max(0.0, rng.gauss(POLICY_START[1], sd)), 6))
            for _ in range(count)]


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


def _walk(config: EpisodeConfig) -> dict[str, Any]:
    from drake_biped.analysis.reward import reward
    from drake_biped.episode import run_episode

    r = run_episode(config)
    walked = walked_the_distance(r.fell, r.distance_m, config.sim.distance_m)
    # the step period's spread after the initiation's transient, where the walk is long enough to have one
    long = walked and config.sim.distance_m >= 2 * TRANSIENT_M
    return {
        "walked": walked,
        "cost_of_transport": r.cost_of_transport,
        "distance_m": r.distance_m,
        "reward": reward(r.cost_of_transport, r.distance_m, config.sim.distance_m),
        "step_period_std_s": r.long_run()["step_period_std_s"] if long else None,
    }


def _window_rows(config: EpisodeConfig, windows, base: dict[str, Any]) -> list[dict[str, Any]]:
    """`_walk` of `config` with each window (t1, t2), its row tagged with the window; t2 <= t1 is no window
    and takes the baseline's row."""
    rows = []
    for t1, t2 in windows:
        row = dict(base) if t2 <= t1 else _walk(config.replace(window=TorqueFreeWindow(t1, t2)))
        row["window"] = [t1, t2]
        rows.append(row)
    return rows


def _push_rows(config: EpisodeConfig) -> list[dict[str, Any]]:
    """`_walk` of `config` without a window under a forward and a backward push of PUSH_FORCE_N (stability's
    timing), each row tagged with its force."""
    from drake_biped.params import Push

    rows = []
    for sign in (1.0, -1.0):
        row = _walk(config.replace(window=TorqueFreeWindow(), push=Push(sign * PUSH_FORCE_N)))
        row["push_n"] = sign * PUSH_FORCE_N
        rows.append(row)
    return rows


def _orbit_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """(1 - rho) / (1 + rho) of the period-1 orbit's spectral radius rho (in (-1, 1], positive once the orbit
    attracts), mapped into (-1, 0) when Newton left a residual above 1e-3, and FLOQUET_UNDEFINED when the
    orbit cannot be linearised (a perturbed step falls)."""
    from drake_biped.analysis.floquet import StepFailed
    from drake_biped.common.floquet_runs import orbit_radius

    try:
        orbit = orbit_radius(config)
    except (StepFailed, ParameterError) as exc:
        return FLOQUET_UNDEFINED, {"baseline": base, "windows": [], "orbit": {"error": str(exc)}}
    rho = orbit["spectral_radius"]
    value = (1.0 - rho) / (1.0 + rho)
    if orbit["fixed_point_residual"] > 1e-3:
        value = 0.5 * (value - 1.0)
    return value, {"baseline": base, "windows": [], "orbit": orbit}


def _landscape_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "landscape" objective (module docstring) and what it measured."""
    import numpy as np

    from drake_biped.analysis.landscape import WindowRewards, landscape

    rows = _window_rows(config, LANDSCAPE_WINDOWS, base)
    rewards = WindowRewards(np.array([r["window"] for r in rows]), np.array([r["reward"] for r in rows]),
                            base["reward"])
    land = landscape(rewards, [POLICY_VARIANCE], t2_range=(0.0, 1.2), step=0.05, samples=1000,
                     starts=(POLICY_START,))["variances"][0]
    start_gain, best_gain = land["starts"][0]["gain"], land["best_gain"]
    pushes = _push_rows(config)
    failed = sum(not p["walked"] for p in pushes)
    value = start_gain + 0.5 * min(max(0.0, best_gain), BEST_GAIN_CAP) - PUSH_PENALTY * failed
    return value, {"baseline": base, "windows": rows, "pushes": pushes,
                   "landscape": {"start_gain": start_gain, "best_gain": best_gain, "best_mean": land["best_mean"]}}


def _changed(config: EpisodeConfig) -> dict[str, EpisodeConfig]:
    """`config` with the plant step halved and from 0.95 and 1.05 x the initiation speed."""
    speed = config.initial.speed_mps
    return {"half_step": config.override({"sim.time_step_s": 0.5 * config.sim.time_step_s}),
            "speed_0.95": config.override({"initial.speed_mps": 0.95 * speed}),
            "speed_1.05": config.override({"initial.speed_mps": 1.05 * speed})}


def _robust_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "robust" objective (module docstring) and what it measured; `base` may be a fall."""
    rows = {name: _walk(c) for name, c in _changed(config.replace(window=TorqueFreeWindow())).items()}
    forward, backward = _push_rows(config)
    rows["push_forward"], rows["push_backward"] = forward, backward
    distance = config.sim.distance_m
    fractions = [min(1.0, max(0.0, r["distance_m"]) / distance) for r in (base, *rows.values())]
    change = None
    excess = 1.0
    if base["walked"] and rows["half_step"]["walked"]:
        change = rows["half_step"]["cost_of_transport"] / base["cost_of_transport"] - 1.0
        excess = min(1.0, max(0.0, abs(change) - ROBUST_CMT_CHANGE) / ROBUST_CMT_CHANGE)
    value = (sum(fractions) / len(fractions) - 1.0) - excess / (len(ROBUST_CHECKS) + 1)
    return value, {"baseline": base, "windows": [], "checks": rows, "half_step_cmt_change": change}


def _converged_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "converged" objective (module docstring) and what it measured; `base` may be a fall."""
    from drake_biped.analysis.series import swing_hip_sign_changes_per_s
    from drake_biped.episode import run_episode

    robust, detail = _robust_score(config, base)
    if robust < 0.0 or base.get("step_period_std_s") is None:
        return robust - 2.0, detail
    short = run_episode(config.replace(window=TorqueFreeWindow()).override({"sim.distance_m": 10.0}),
                        record_trajectory=True)
    if short.fell or short.duration_s <= CONVERGED_AFTER_S + 1.0:
        return -2.0, detail
    spread = base["step_period_std_s"]
    changes = swing_hip_sign_changes_per_s(short.trajectory, CONVERGED_AFTER_S)
    moved = abs(detail["half_step_cmt_change"])

    def excess(value: float, target: float) -> float:
        return min(1.0, max(0.0, value / target - 1.0))

    value = -(excess(spread, CONVERGED_STEP_SD_S) + excess(changes, CONVERGED_SIGN_CHANGES)
              + excess(moved, CONVERGED_CMT_CHANGE)) / 3.0
    detail["converged"] = {"step_period_std_s": spread, "sign_changes_per_s": changes, "half_step_cmt_change": moved}
    return value, detail


def _story_score(config: EpisodeConfig, base: dict[str, Any], draws: int) -> tuple[float, dict[str, Any]]:
    """The "story" objective (module docstring) and what it measured; `base` may be a fall."""
    robust, detail = _robust_score(config, base)
    if robust < 0.0:
        return robust - 2.0, detail
    checks = detail["checks"]
    windows = policy_draws(draws)
    half = config.override({"sim.time_step_s": 0.5 * config.sim.time_step_s})
    rows = _window_rows(config, windows, base)
    half_rows = _window_rows(half, windows, checks["half_step"])
    gains = [min(r["reward"] / base["reward"], h["reward"] / checks["half_step"]["reward"]) - 1.0
             for r, h in zip(rows, half_rows)]
    k = max(range(len(gains)), key=gains.__getitem__)
    best = {"window": list(windows[k]), "gain": gains[k]}
    if windows[k][1] > windows[k][0]:
        for factor in ("0.95", "1.05"):
            row = _walk(config.override({"initial.speed_mps": float(factor) * config.initial.speed_mps})
                        .replace(window=TorqueFreeWindow(*windows[k])))
            best[f"speed_{factor}"] = row
            best["gain"] = min(best["gain"], row["reward"] / checks[f"speed_{factor}"]["reward"] - 1.0)
    d = distance_from_table_iii(config.cpg)
    value = sum(gains) / len(gains) + 0.5 * max(0.0, best["gain"]) - 0.01 * d / (1.0 + d)
    return value, {**detail, "windows": rows, "half_step_windows": half_rows, "gains": gains, "best_draw": best,
                   "distance_from_table_iii": d}


def _saving(row: dict[str, Any], base: dict[str, Any]) -> float:
    """C_mt saving of a walk with a window against `base` without one; -1 when either falls."""
    if not (row["walked"] and base["walked"]):
        return -1.0
    return 1.0 - row["cost_of_transport"] / base["cost_of_transport"]


def _hold_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold" objective (module docstring) and what it measured; `base` may be a fall."""
    robust, detail = _robust_score(config, base)
    if robust < 0.0:
        return robust - 2.0, detail
    bases = {"as_is": base, **{k: detail["checks"][k] for k in ("half_step", "speed_0.95", "speed_1.05")}}
    changed = {"as_is": config, **_changed(config)}
    windows = []
    for t1, t2 in HOLD_WINDOWS:
        walks = {name: _walk(c.replace(window=TorqueFreeWindow(t1, t2))) for name, c in changed.items()}
        gains = {name: w["reward"] / bases[name]["reward"] - 1.0 for name, w in walks.items()}
        windows.append({"window": [t1, t2], "walks": walks, "gains": gains,
                        "savings": {name: _saving(w, bases[name]) for name, w in walks.items()}})
    top = max(max(w["gains"].values()) for w in windows)
    plateau = [w["window"][0] for w in windows if max(w["gains"].values()) >= top - HOLD_PLATEAU
               or HOLD_BAND[0] - 1e-9 <= w["window"][0] <= HOLD_BAND[1] + 1e-9]
    reach = [w for w in windows if any(abs(w["window"][0] - t1) <= HOLD_MARGIN_S + 1e-9 for t1 in plateau)]
    least = min(min(w["savings"].values()) for w in reach)
    d = distance_from_table_iii(config.cpg)
    slope = sum(min(w["gains"].values()) for w in windows) / len(windows)
    value = least + 0.1 * slope - 0.01 * d / (1.0 + d)
    return value, {**detail, "windows": windows, "reach": [w["window"] for w in reach], "least_saving": least,
                   "distance_from_table_iii": d}


def _long_walk(config: EpisodeConfig, distance_m: float = HOLD_LONG_M) -> dict[str, Any]:
    """A `distance_m` walk of `config`: whether it walked, and its long-run C_mt after the first 10 m."""
    from drake_biped.episode import run_episode

    r = run_episode(config.override({"sim.distance_m": distance_m,
                                     "sim.max_time_s": max(config.sim.max_time_s, 6.0 * distance_m)}))
    walked = walked_the_distance(r.fell, r.distance_m, distance_m)
    long_run = r.long_run(batches=4)
    return {"walked": walked, "distance_m": r.distance_m, "cost_of_transport": long_run["cost_of_transport"]
            if walked else None, "step_period_s": long_run["step_period_mean_s"],
            "step_period_std_s": long_run["step_period_std_s"]}


def _long_windows(config: EpisodeConfig, base: dict[str, Any], windows_of) -> tuple[float | None, dict[str, Any]]:
    """What "hold-long" and "hold-step" share: the "robust" objective first, then HOLD_LONG_M walks without a
    window as it is, at half the plant step and from 0.95 / 1.05 x the initiation speed, and the same walks with
    each window of `windows_of(bases)`, each saving against no window under the same change. (score, detail)
    when a check fails first; else (None, detail with "long_bases", "windows" and "savings")."""
    robust, detail = _robust_score(config, base)
    if robust < 0.0:
        return robust - 2.0, detail
    changed = {"as_is": config, **_changed(config)}
    bases = {name: _long_walk(c.replace(window=TorqueFreeWindow())) for name, c in changed.items()}
    if not all(b["walked"] for b in bases.values()):
        walked = sum(b["walked"] for b in bases.values())
        return -1.5 + 0.1 * walked, {**detail, "long_bases": bases}
    windows = []
    for t1, t2 in windows_of(bases):
        walks = {name: _long_walk(c.replace(window=TorqueFreeWindow(t1, t2))) for name, c in changed.items()}
        windows.append({"window": [t1, t2], "walks": walks,
                        "savings": {name: _saving(w, bases[name]) for name, w in walks.items()}})
    savings = [v for w in windows for v in w["savings"].values()]
    return None, {**detail, "long_bases": bases, "windows": windows, "savings": savings}


def _hold_long_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold-long" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    early, detail = _long_windows(config, base, lambda bases: HOLD_LONG_WINDOWS)
    if early is not None:
        return early, detail
    savings = detail.pop("savings")
    least = min(savings)
    d = distance_from_table_iii(config.cpg)
    value = least + 0.1 * sum(savings) / len(savings) - 0.01 * d / (1.0 + d)
    return value, {**detail, "least_saving": least, "distance_from_table_iii": d}


def _hold_step_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold-step" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    early, detail = _long_windows(config, base, lambda bases: [
        (round(bases["as_is"]["step_period_s"] - below, 4), 1.2) for below in HOLD_STEP_BELOW_S])
    if early is not None:
        return early, detail
    savings = detail.pop("savings")
    period = detail["long_bases"]["as_is"]["step_period_s"]
    past = [{"window": [round(period + s, 4), 1.2],
             **_walk(config.replace(window=TorqueFreeWindow(round(period + s, 4), 1.2)))} for s in HOLD_STEP_PAST_S]
    lure = max([0.0, *(_saving(row, base) for row in past if row["walked"])])
    least = min(savings)
    d = distance_from_table_iii(config.cpg)
    value = least - lure + 0.1 * sum(savings) / len(savings) - 0.01 * d / (1.0 + d)
    return value, {**detail, "past_step": past, "least_saving": least, "past_step_saving": lure,
                   "step_period_s": period, "distance_from_table_iii": d}


def _hold_slow_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold-slow" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    value, detail = _hold_step_score(config, base)
    if "step_period_s" not in detail:
        return value, detail
    short = max(0.0, HOLD_SLOW_FLOOR_S - detail["step_period_s"])
    return value - HOLD_SLOW_PENALTY * short, {**detail, "short_of_floor_s": short}


def _band_and_lure(config: EpisodeConfig, base: dict[str, Any], windows, lure_weight: float
                   ) -> tuple[float, dict[str, Any]]:
    """What "hold-edge" and "hold-lure" share: `windows` judged as in "hold-long", and the larger 10 m saving at
    HOLD_EDGE_LURE counted with `lure_weight`: least saving + lure_weight x lure + 0.1 x the mean saving - 0.01 d /
    (1 + d), with what it measured; `base` may be a fall."""
    early, detail = _long_windows(config, base, lambda bases: windows)
    if early is not None:
        return early, detail
    savings = detail.pop("savings")
    lured = [{"window": list(w), **_walk(config.replace(window=TorqueFreeWindow(*w)))} for w in HOLD_EDGE_LURE]
    lure = max([0.0, *(_saving(row, base) for row in lured if row["walked"])])
    least = min(savings)
    d = distance_from_table_iii(config.cpg)
    value = least + lure_weight * lure + 0.1 * sum(savings) / len(savings) - 0.01 * d / (1.0 + d)
    return value, {**detail, "lure_windows": lured, "least_saving": least, "lure_saving": lure,
                   "step_period_s": detail["long_bases"]["as_is"]["step_period_s"], "distance_from_table_iii": d}


def _hold_edge_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold-edge" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    return _band_and_lure(config, base, HOLD_EDGE_WINDOWS, -1.0)


def _hold_lure_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "hold-lure" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    return _band_and_lure(config, base, HOLD_LURE_WINDOWS, HOLD_LURE_WEIGHT)


def _touchdowns(config: EpisodeConfig) -> tuple[bool, list[float]]:
    """Whether `config` walks its distance, and its touchdown times (s)."""
    from drake_biped.episode import run_episode

    r = run_episode(config)
    return walked_the_distance(r.fell, r.distance_m, config.sim.distance_m), [s.touchdown_time_s for s in r.steps]


def _steady_push_rows(config: EpisodeConfig, window: tuple[float, float]) -> list[dict[str, Any]]:
    """`_walk` of a SURE_PUSH_M walk of `config` with `window` ((0, 0): none) under a forward and a backward push
    of PUSH_FORCE_N at each of SURE_PUSH_PHASES phases of its first step from SURE_SETTLE_S on (`push-margin`'s
    pushes), each row tagged with its force and start; every push counts as a fall when the walk does not walk
    unpushed or has no step after SURE_SETTLE_S."""
    from drake_biped.common.walks import steady_step
    from drake_biped.paper import PUSH_DURATION_S
    from drake_biped.params import Push

    walk = config.override({"sim.distance_m": SURE_PUSH_M, "sim.max_time_s": max(config.sim.max_time_s,
                                                                                  6.0 * SURE_PUSH_M)})
    walk = walk.replace(window=TorqueFreeWindow(*window), push=None)
    walked, times = _touchdowns(walk)
    step = steady_step({"steps": [{"touchdown_time_s": t} for t in times]}, SURE_SETTLE_S) if walked else None
    rows = []
    for sign in (1.0, -1.0):
        for j in range(SURE_PUSH_PHASES):
            if step is None:
                rows.append({"walked": False, "push_n": sign * PUSH_FORCE_N, "start_s": None})
                continue
            start = step[0] + (j / SURE_PUSH_PHASES) * (step[1] - step[0])
            row = _walk(walk.replace(push=Push(sign * PUSH_FORCE_N, start, PUSH_DURATION_S)))
            rows.append({**row, "push_n": sign * PUSH_FORCE_N, "start_s": start})
    return rows


def _quarter_step(config: EpisodeConfig, detail: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """"hold-sure"'s step check: the penalty for the walk without a window at a quarter of the plant step, and
    what it measured (`detail`: the "hold-lure" score's, whose long walk at the step it compares with)."""
    quarter = _long_walk(config.override({"sim.time_step_s": 0.25 * config.sim.time_step_s}
                                         ).replace(window=TorqueFreeWindow()))
    if not quarter["walked"]:
        return 1.0, {"quarter_step": quarter, "quarter_step_change": None}
    change = quarter["cost_of_transport"] / detail["long_bases"]["as_is"]["cost_of_transport"] - 1.0
    return (SURE_STEP_PENALTY * max(0.0, abs(change) - SURE_STEP_TOLERANCE),
            {"quarter_step": quarter, "quarter_step_change": change})


def _step_ladder(config: EpisodeConfig, detail: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """"hold-fine"'s step check: the penalty for the walks without a window at FINE_STEP_FRACTIONS of the plant
    step (FINE_STEP_M each, the gait's clock kept: refined with the plant by default), and what they measured."""
    walks = [{"time_step_s": f * config.sim.time_step_s,
              **_long_walk(config.override({"sim.time_step_s": f * config.sim.time_step_s}
                                           ).replace(window=TorqueFreeWindow()), FINE_STEP_M)}
             for f in FINE_STEP_FRACTIONS]
    if not all(w["walked"] for w in walks):
        return 1.0, {"step_ladder": walks, "step_ladder_changes": None}
    finest = walks[-1]["cost_of_transport"]
    changes = [w["cost_of_transport"] / finest - 1.0 for w in walks[:-1]]
    worst = max(abs(c) for c in changes)
    return (SURE_STEP_PENALTY * max(0.0, worst - SURE_STEP_TOLERANCE),
            {"step_ladder": walks, "step_ladder_changes": changes})


def _hold_sure_score(config: EpisodeConfig, base: dict[str, Any], step_check=_quarter_step
                     ) -> tuple[float, dict[str, Any]]:
    """The "hold-sure" objective (OBJECTIVES) and what it measured, "hold-fine" with `_step_ladder` as
    `step_check`; `base` may be a fall."""
    value, detail = _hold_lure_score(config, base)
    if "lure_saving" not in detail:
        return value, detail
    early = [{"window": list(w), **_walk(config.replace(window=TorqueFreeWindow(*w)))} for w in SURE_EARLY_WINDOWS]
    pushes = {"without": _steady_push_rows(config, (0.0, 0.0)), "with": _steady_push_rows(config, SURE_PUSH_WINDOW)}
    early_falls = sum(not row["walked"] for row in early) / len(early)
    rows = [row for condition in pushes.values() for row in condition]
    push_falls = sum(not row["walked"] for row in rows) / len(rows)
    step_cost, steps = step_check(config, detail)
    value -= SURE_FALL_PENALTY * early_falls + SURE_PUSH_PENALTY * push_falls + step_cost
    return value, {**detail, "early_windows": early, "steady_pushes": pushes, "early_falls": early_falls,
                   "push_falls": push_falls, **steps}


def _hold_pull_score(config: EpisodeConfig, base: dict[str, Any], draws: int) -> tuple[float, dict[str, Any]]:
    """The "hold-pull" objective (OBJECTIVES) and what it measured; `base` may be a fall."""
    value, detail = _hold_edge_score(config, base)
    if "lure_saving" not in detail:
        return value, detail
    pull, start = _gain_score(config, base, policy_draws(draws), 0.0)
    return value + pull, {**detail, "start_draws": start["windows"], "start_gain": pull}


Score = Callable[[EpisodeConfig, dict[str, Any], Any, int], tuple[float, dict[str, Any]]]


@dataclass(frozen=True)
class Objective:
    """A search objective: `score(config, base, windows, draws)` (base: the walk without a window) and what it
    scores. `scores_fallers`: it scores a configuration that falls itself (else the fraction walked does)."""

    score: Score
    scores_fallers: bool
    about: str
    # The objective's largest value, where it has one: a search that reaches it stops (no candidate can beat it).
    maximum: float | None = None


def _windows_score(config, base, windows, draws):
    rows = _window_rows(config, windows, base)
    savings = [1.0 - r["cost_of_transport"] / base["cost_of_transport"] for r in rows if r["walked"]]
    value = (max(savings) if savings else -0.3) + 0.03 * len(savings)
    return value, {"baseline": base, "windows": rows}


def _gain_score(config, base, windows, best_share: float):
    rows = _window_rows(config, windows, base)
    gains = [r["reward"] / base["reward"] - 1.0 for r in rows]
    return sum(gains) / len(gains) + best_share * max(0.0, max(gains)), {"baseline": base, "windows": rows}


def _walk_score(config, base, windows, draws):
    return 0.0, {"baseline": base, "windows": []}


def _policy_score(config, base, windows, draws):
    return _gain_score(config, base, policy_draws(draws), 0.5)


def _expected_score(config, base, windows, draws):
    return _gain_score(config, base, policy_draws(draws), 0.0)


def _coast_score(config, base, windows, draws):
    return _gain_score(config, base, COAST_WINDOWS, 0.5)


def _nearest_score(config, base, windows, draws):
    d = distance_from_table_iii(config.cpg)
    pushes = _push_rows(config)
    failed = sum(not p["walked"] for p in pushes)
    return -(d / (1.0 + d) + failed) / 3.0, {"baseline": base, "windows": [], "pushes": pushes,
                                            "distance_from_table_iii": d}


def _of_base(score_fn, *extra):
    """An objective that reads the gait and its walk without a window alone."""
    return lambda config, base, windows, draws: score_fn(config, base, *extra)


def _of_draws(score_fn):
    """An objective that reads the gait, its walk without a window and the start policy's draws."""
    return lambda config, base, windows, draws: score_fn(config, base, draws)


# Every objective a search can score by: its function and what it scores (the module docstring, the command's
# help and the search's records read the names and the texts from here).
OBJECTIVES: dict[str, Objective] = {
    "windows": Objective(_windows_score, False, 'The largest fractional C_mt saving among the scored windows that also walk (-0.3 if none walks), plus 0.03 for every window that walks.'),
    "walk": Objective(_walk_score, False, '0 (the search stops once a walker is found; use it to find one).', 0.0),
    "policy": Objective(_policy_score, False, "What the paper's learner climbs from its start: the expected reward of the policy N((0.5, 0.5), 0.04 I) over POLICY_DRAWS (or `policy_draws`) fixed draws, relative to no window (a draw with t2 <= t1 is no window and takes its reward), plus half the largest gain of a single drawn window."),
    "expected": Objective(_expected_score, False, "The expected reward's gain alone, over the same draws (one drawn window that saves much cannot carry a gait whose other draws fall)."),
    "nearest": Objective(_nearest_score, False, '-(d / (1 + d) + f) / 3, d the CPG\'s distance from Table III (`distance_from_table_iii`) and f how many of the +-PUSH_FORCE_N pushes (stability\'s, without a window) the gait does not walk through, to find the walker whose CPG is nearest the paper\'s (with the "near_paper" mutations); in (-1, 0], so any walker, however far, beats every fall, and one that survives both pushes beats every one that does not (a walk that reaches the distance by luck, near a cliff in the parameters, falls to a push).'),
    "coast": Objective(_coast_score, False, 'The same score over COAST_WINDOWS, the hip off from t1 = 0.2 ... 0.5 s until the swing foot lands (a gait that coasts to touchdown turns the cliff of windows that end late into a plateau).'),
    "floquet": Objective(_of_base(_orbit_score), False, "(1 - rho) / (1 + rho), rho the spectral radius of the gait's period-1 orbit (`common.floquet_runs.orbit_radius`: Newton and one central-difference Jacobian on the mid-stance step map): positive once the orbit attracts; (score - 1) / 2 when Newton leaves a residual above 1e-3; FLOQUET_UNDEFINED (-1) when a perturbed step falls."),
    "landscape": Objective(_of_base(_landscape_score), False, "The same from a coarse window map (LANDSCAPE_WINDOWS, 0.2 s apart up to t1 0.8 s, t2 1.2 s) through `analysis.landscape`: the expected reward's gain at (0.5, 0.5) with variance 0.04, plus half the best policy mean's gain up to BEST_GAIN_CAP, minus PUSH_PENALTY for each of the +-PUSH_FORCE_N pushes (stability's, without a window) the gait does not walk through."),
    "robust": Objective(_of_base(_robust_score), True, "How far the walk without a window is from holding when the simulation is refined or the start is nudged, scored for fallers too: (mean(f) - 1) - e / (len(ROBUST_CHECKS) + 1), f the fraction of the distance walked by the walk itself and under each of ROBUST_CHECKS (the plant step halved, the initiation speed x 0.95 and x 1.05, the +-PUSH_FORCE_N pushes), e the excess of the half step's relative C_mt change over ROBUST_CMT_CHANGE, in units of it, capped at 1 (1 when the half step falls); in [-7/6, 0], 0 once all hold.", 0.0),
    "converged": Objective(_of_base(_converged_score), True, 'The "robust" objective first (while a check fails, its score - 2), then how far the walk is from converged at its own plant step: -(s + c + m) / 3, s the excess of the step period\'s sd (the walk without a window, after the first 10 m) over CONVERGED_STEP_SD_S, c that of the swing hip\'s sign changes per second (a 10 m walk after CONVERGED_AFTER_S) over CONVERGED_SIGN_CHANGES and m that of the half step\'s relative C_mt change over CONVERGED_CMT_CHANGE, each in units of its target and capped at 1; in [-1, 0] once all hold, 0 when all three are met.', 0.0),
    "story": Objective(_of_draws(_story_score), True, 'The "robust" objective first, then what the paper\'s learner would find, judged where it holds: while a robust check fails, the "robust" score - 2 (below every walker that holds); once all hold, the "policy" objective with every draw\'s reward gain taken as the smaller of its gains at the step and at half the step (each against no window at that step), the best draw\'s gain as the smallest of that and its gains from the initiation speed x 0.95 and x 1.05 (against no window from the same speed), minus 0.01 d / (1 + d), d the CPG\'s distance from Table III (a tie-breaker towards the paper); from -1.01 up.'),
    "hold": Objective(_of_base(_hold_score), True, 'The "robust" objective first, then whether every window the paper\'s learner may end on holds: the hip off from t1 until the swing foot lands (HOLD_WINDOWS: t1 across the end of the step; the learned windows\' t2 lie past the step\'s end, so the saving is a curve in t1), each walked as it is, at half the plant step and from 0.95 and 1.05 x the initiation speed, against no window under the same change. A window whose t1 lies past the powered step\'s end acts only when a step runs long, and once it acts the step runs long: two gaits, chosen by the walk\'s details, that save much in one walk and little in the next. The learner\'s reach is every window whose best reward gain over the four walks is within HOLD_PLATEAU of the best window\'s (GARB\'s reward is flat there, and a walk that falls into the long step pays it more), every window in HOLD_BAND (where the means of GARB with the paper\'s settings ended on the gaits it has been run on, whatever their reward\'s peak: 500 episodes from t1 0.5 s stop short of a peak further away), and every window within HOLD_MARGIN_S of one of those in t1 (the trials of one GARB run end that far apart on a flat reward); the score is the smallest C_mt saving over that reach and its four walks (-1 for a fall; >= 0.35 where every window GARB may end on holds), plus 0.1 x the mean over HOLD_WINDOWS of each window\'s smallest reward gain (a wider slope that holds), minus 0.01 d / (1 + d) as in "story".'),
    "hold-long": Objective(_of_base(_hold_long_score), True, 'The "robust" objective first, then HOLD_LONG_WINDOWS (t1 across HOLD_BAND, the hip off until the foot lands), each walked HOLD_LONG_M as it is, at half the plant step and from 0.95 and 1.05 x the initiation speed, against no window under the same change, every walk judged by its long-run C_mt after the first 10 m: the smallest saving (-1 for a fall) plus 0.1 x the mean saving, minus 0.01 d / (1 + d).'),
    "hold-step": Objective(_of_base(_hold_step_score), True, 'The "robust" objective first, then windows placed by the gait\'s own powered step period T (its long walk without a window): t1 = T - HOLD_STEP_BELOW_S (the hip off until the foot lands) judged as in "hold-long", minus the largest saving of a 10 m episode from the initiation with t1 = T + HOLD_STEP_PAST_S (a window that saves there only while the initiation\'s long first steps last draws GARB past the step\'s end): least saving - that lure + 0.1 x the mean saving - 0.01 d / (1 + d).'),
    "hold-slow": Objective(_of_base(_hold_slow_score), True, 'The "hold-step" score minus HOLD_SLOW_PENALTY x how far the powered step T falls short of HOLD_SLOW_FLOOR_S (GARB starts at t1 = 0.5 s: on a shorter step the windows near its start never act in the steady gait).'),
    "hold-edge": Objective(_of_base(_hold_edge_score), True, 'The "robust" objective first, then HOLD_EDGE_WINDOWS (t1 0.40, 0.42, 0.44 s, where GARB\'s means ended, the hip off until the foot lands) judged as in "hold-long", minus the larger 10 m saving from the initiation at HOLD_EDGE_LURE (t1 0.48 and 0.50 s, the learner\'s start region): least saving - that lure + 0.1 x the mean saving - 0.01 d / (1 + d).'),
    "hold-lure": Objective(_of_base(_hold_lure_score), True, 'The "robust" objective first, then HOLD_LURE_WINDOWS (t1 0.40 to 0.46 s, the hip off until the foot lands) judged as in "hold-long", plus HOLD_LURE_WEIGHT x the larger 10 m saving from the initiation at HOLD_EDGE_LURE (t1 0.48 and 0.50 s: what brings GARB\'s means back from the no-window half of its start): least saving + 0.5 x that lure + 0.1 x the mean saving - 0.01 d / (1 + d).'),
    "hold-sure": Objective(_of_base(_hold_sure_score), True, 'The "hold-lure" score less SURE_FALL_PENALTY x the fraction of SURE_EARLY_WINDOWS (early windows, where GARB\'s first large steps can carry a mean) that fall over the 10 m episode, and less SURE_PUSH_PENALTY x the fraction of the +-PUSH_FORCE_N pushes in steady state (SURE_PUSH_PHASES phases of the first step after SURE_SETTLE_S of a SURE_PUSH_M walk, as `push-margin` pushes; without a window and with SURE_PUSH_WINDOW) that fall, and less SURE_STEP_PENALTY x how far the long-run C_mt of the walk without a window at a quarter of the plant step moves beyond SURE_STEP_TOLERANCE from the step\'s (1 when it falls).'),
    "hold-fine": Objective(_of_base(_hold_sure_score, _step_ladder), True, 'The "hold-sure" score with its step check made the time-step study\'s: SURE_STEP_PENALTY x how far the largest change of the long-run C_mt without a window, walked FINE_STEP_M at each of FINE_STEP_FRACTIONS of the plant step (the controller refined with it under the paper\'s clock), from the finest moves beyond SURE_STEP_TOLERANCE (1 when one falls).'),
    "hold-pull": Objective(_of_draws(_hold_pull_score), True, 'The "hold-edge" score plus the mean reward gain over --policy-draws fixed draws of the paper\'s start policy ((0.5, 0.5), variance 0.04; the "expected" objective): where the learner\'s first episodes fall or save.'),
}


def score(config: EpisodeConfig, windows=ACCEPTANCE_WINDOWS, objective: str = "windows",
          draws: int = POLICY_DRAWS) -> tuple[float, dict[str, Any]]:
    """The search objective `objective` (OBJECTIVES) and what it measured; `draws`: how many draws of the start
    policy the "policy", "expected" and "story" objectives walk."""
    if objective not in OBJECTIVES:
        raise ParameterError(f"objective {objective!r} is not one of {list(OBJECTIVES)}")
    spec = OBJECTIVES[objective]
    base = _walk(config.replace(window=TorqueFreeWindow()))
    if not spec.scores_fallers and not base["walked"]:
        return -9.0 + 8.0 * min(1.0, max(0.0, base["distance_m"]) / config.sim.distance_m), \
            {"baseline": base, "windows": []}
    return spec.score(config, base, windows, draws)


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
    mutations: str = "default"
    objective: str = "windows"
    policy_draws: int = POLICY_DRAWS
    force: bool = False  # more than MAX_CANDIDATES candidates

    def __post_init__(self) -> None:
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
                  "objective": settings.objective, "policy_draws": settings.policy_draws, **extra, "versions": versions()})
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
    differs = [f"{k} {recorded[k]!r} there, {wanted[k]!r} here" for k in wanted
               if recorded[k] is not None and recorded[k] != wanted[k]]
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


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped gait-search`'s options."""
    add_episode_options(p)
    p.add_argument("--generations", type=count, default=50, help="generations")
    p.add_argument("--offspring", type=count, default=4, help="children per generation")
    p.add_argument("--sigma", type=number("positive"), default=0.1, help="mutation scale")
    p.add_argument("--mutations", choices=list(MUTATION_SETS), default="default",
                   help="what mutates: 'default' (CPG u_a, u_r, kappa and the gains), 'paper' (only what "
                   "the paper does not print: the CPG and the initiation held), 'near_paper' (those "
                   "and u_a, u_r, kappa), 'coast' (default, the knee's hold torque, the torso's "
                   "gains and the stance knee) or 'paper_motor' (what the paper does not print when the hip is "
                   "its ODE motor: the motor's limit, the knees, ankles, torso and touchdown phase)")
    p.add_argument("--method", choices=["es", "cmaes"], default="es",
                   help="'es': the (1 + offspring) evolution strategy; 'cmaes': CMA-ES (pycma), "
                   "offspring candidates a generation")
    p.add_argument("--objective", default="windows", choices=list(OBJECTIVES),
                   help="what a walker scores (each objective's definition below)")
    p.add_argument("--policy-draws", type=count, default=12,
                   help="draws of the paper's start policy the 'policy', 'expected', 'story' and 'hold-pull' objectives walk "
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
