"""The gait search's objectives, as data: `OBJECTIVES` maps each name to its scoring function and what it scores
(`drake-biped gait-search --help` prints them), and `score` walks a gait without a window and scores it by one.

An objective reads the walk without a window (`base`), and walks what else it needs through the helpers here
(`_walk`, `_window_rows`, `_push_rows`, `_changed`), which tests replace to score chosen walks. Of a configuration
that does not walk its distance without a window, the objectives that do not score fallers themselves give
-9 + 8 * (the fraction of the distance walked), so that a search from a gait that falls climbs towards one that
walks. The objectives written for gaits the toolkit no longer ships are in git's history (docs/HISTORY.md,
"Retired gaits and objectives")."""

from __future__ import annotations

import math
import random
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from drake_biped.analysis.long_run import TRANSIENT_M
from drake_biped.paper import PUSH_FORCE_N
from drake_biped.params import EpisodeConfig, ParameterError, TorqueFreeWindow, walked_the_distance

__all__ = ["ACCEPTANCE_WINDOWS", "OBJECTIVES", "Objective", "POLICY_DRAWS", "distance_from_table_iii", "policy_draws",
           "score"]

# The "windows" objective's windows (t1, t2), unless a search names its own.
ACCEPTANCE_WINDOWS = ((0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.35, 0.65), (0.2, 0.7))
# The "robust" objective's changes to the walk without a window, and the half step's allowed C_mt change.
ROBUST_CHECKS = ("half_step", "speed_0.95", "speed_1.05", "push_forward", "push_backward")
ROBUST_CMT_CHANGE = 0.02
# The "converged" objective's targets at the walk's own plant step: the step period's spread after the transient,
# how often the swing hip's torque changes sign on a 10 m walk after CONVERGED_AFTER_S (the motor's chatter), and
# the half step's relative C_mt change (the robust objective allows ROBUST_CMT_CHANGE).
CONVERGED_STEP_SD_S, CONVERGED_SIGN_CHANGES, CONVERGED_AFTER_S = 1e-3, 20.0, 3.0
CONVERGED_CMT_CHANGE = 0.005
# The "calibrated" objective's targets, what the paper prints of its walker without the window: its step period
# (the learner starts both times at 0.5 s, "half of the walking cycle": a cycle of the swing hip's control, from
# one step's start to the next, of 1.0 s) and Table V's C_mt without the torque-free period (0.58, read as the
# dimensionless C_mt, as Table V's ASIMO 1.60 and human 0.05 are); each met within CALIBRATION_TOLERANCE of it, and
# scored by its log-ratio to it beyond that, a factor CALIBRATION_REACH away costing the most: a walker far from the
# paper's figures (C_mt 0.18 against 0.58) still sees which of two candidates is nearer.
PAPER_STEP_PERIOD_S = 2.0 * 0.5
CALIBRATION_TOLERANCE = 0.1
CALIBRATION_REACH = 4.0
# The "halving" objective: the windows it walks, as fractions (t1, t2) of the walk's own step period (the hip off
# from early, middle and late in the swing, to the step's end and on through touchdown), and the swing hip's share
# of the positive work below which no window is walked (freeing a hip that does less than a quarter of the work
# cannot halve C_mt unless it changes the whole gait; the screen costs nothing beyond the walk without a window).
HALVING_WINDOWS = ((0.1, 0.5), (0.3, 0.7), (0.5, 0.9), (0.2, 1.0), (0.4, 1.0), (0.6, 1.2))
HALVING_SCREEN_SHARE = 0.25
# The "hold" objective's windows (t1 across the end of the step, t2 past any step) and how far below the best
# window's reward gain a window still lies within the learner's reach.
HOLD_WINDOWS = tuple((round(0.30 + 0.02 * i, 2), 1.2) for i in range(14))
HOLD_PLATEAU, HOLD_MARGIN_S = 0.05, 0.02
# t1 of the means GARB with the paper's settings ended on: 0.37-0.45 s on hold-g1 (reward peak 0.32 s) and
# 0.41-0.47 s on cand1 (benchmarks/results/learn-*); 0.30-0.53 s on coasting_wide at 0.5 ms.
HOLD_BAND = (0.36, 0.48)


def distance_from_table_iii(cpg) -> float:
    """|ln(u_a / 2)| + |ln(u_r / 2.1)| + |ln(kappa / 1.8)|: how far a CPG is from Table III's, in relative
    terms (alpha and u_eta are not searched)."""
    from drake_biped.paper import TABLE_III

    return sum(abs(math.log(getattr(cpg, k) / TABLE_III[k])) for k in ("u_a", "u_r", "kappa"))


# The paper's learner starts at (0.5, 0.5) with variance 0.04 (Table II): fixed draws of that policy.
POLICY_START, POLICY_VARIANCE, POLICY_DRAWS = (0.5, 0.5), 0.04, 12


def policy_draws(count: int = POLICY_DRAWS, seed: int = 0) -> list[tuple[float, float]]:
    """`count` fixed draws (t1, t2) of the paper's starting policy, times below 0 taken as 0."""
    rng = random.Random(seed)
    sd = math.sqrt(POLICY_VARIANCE)
    return [(round(max(0.0, rng.gauss(POLICY_START[0], sd)), 6), round(max(0.0, rng.gauss(POLICY_START[1], sd)), 6))
            for _ in range(count)]


def _walk(config: EpisodeConfig) -> dict[str, Any]:
    from drake_biped.analysis.reward import reward
    from drake_biped.episode import run_episode

    r = run_episode(config)
    walked = walked_the_distance(r.fell, r.distance_m, config.sim.distance_m)
    # the long-run figures after the initiation's transient, where the walk is long enough to have them
    long = r.long_run() if walked and config.sim.distance_m >= 2 * TRANSIENT_M else {}
    positive = {role: w["positive_j"] for role, w in (r.work_by_role or {}).items()}
    total = sum(positive.values())
    return {
        "walked": walked,
        # how it ended: "distance", or a fall's reason ("simulation failed: ..." where the contact solve failed)
        "termination": r.termination,
        "cost_of_transport": r.cost_of_transport,
        "distance_m": r.distance_m,
        "reward": reward(r.cost_of_transport, r.distance_m, config.sim.distance_m),
        "step_period_std_s": long.get("step_period_std_s"),
        "step_period_mean_s": long.get("step_period_mean_s"),
        "long_run_cost_of_transport": long.get("cost_of_transport"),
        # the swing hip's share of the motors' positive work over the whole walk (its initiation a few per cent
        # of a 100 m walk's)
        "swing_hip_share": positive.get("swing_hip", 0.0) / total if total > 0.0 else None,
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
    # the steps' spread at the walk's step and at half of it: a walk regular at its step only (a period-doubled
    # orbit at half the step, the touchdowns' grid phase) is not converged
    half = detail["checks"].get("half_step", {}).get("step_period_std_s")
    spread = max(base["step_period_std_s"], half if half is not None else math.inf)
    changes = swing_hip_sign_changes_per_s(short.trajectory, CONVERGED_AFTER_S)
    moved = abs(detail["half_step_cmt_change"])

    def excess(value: float, target: float) -> float:
        return min(1.0, max(0.0, value / target - 1.0))

    value = -(excess(spread, CONVERGED_STEP_SD_S) + excess(changes, CONVERGED_SIGN_CHANGES)
              + excess(moved, CONVERGED_CMT_CHANGE)) / 3.0
    detail["converged"] = {"step_period_std_s": spread, "step_period_std_s_at_step": base["step_period_std_s"],
                           "step_period_std_s_at_half_step": half, "sign_changes_per_s": changes,
                           "half_step_cmt_change": moved}
    return value, detail


def _excess(value: float, target: float, tolerance: float = CALIBRATION_TOLERANCE,
            reach: float = CALIBRATION_REACH) -> float:
    """How far `value` lies from `target` beyond a factor 1 + `tolerance` either way: |ln(value / target)| less
    ln(1 + tolerance), in units of ln(`reach`), capped at 1 (0 inside the tolerance, 1 from `reach` times or
    1 / `reach` times the target on)."""
    return min(1.0, max(0.0, (abs(math.log(value / target)) - math.log1p(tolerance)) / math.log(reach)))


def _calibrated_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "calibrated" objective (module docstring) and what it measured; `base` may be a fall."""
    value, detail = _converged_score(config, base)
    if "converged" not in detail:  # a robust check failed, or the walk was too short to judge
        return value - 1.0, detail
    period, cost = base["step_period_mean_s"], base["long_run_cost_of_transport"]
    from drake_biped.paper import TABLE_V

    target = TABLE_V["CPG without torque-free period"]
    p = _excess(period, PAPER_STEP_PERIOD_S)
    c = _excess(cost, target)
    detail["calibration"] = {"step_period_mean_s": period, "long_run_cost_of_transport": cost,
                             "step_period_excess": p, "cost_excess": c, "converged_score": value}
    return (3.0 * value - p - c) / 5.0, detail


def _halving_score(config: EpisodeConfig, base: dict[str, Any]) -> tuple[float, dict[str, Any]]:
    """The "halving" objective (module docstring) and what it measured; `base` may be a fall."""
    robust, detail = _robust_score(config, base)
    if robust < 0.0 or base.get("long_run_cost_of_transport") is None:
        return robust - 2.0, detail
    share = base["swing_hip_share"] or 0.0
    detail["swing_hip_share"] = share
    if share < HALVING_SCREEN_SHARE:
        return share - 1.0, detail
    period = base["step_period_mean_s"]
    windows = [(round(a * period, 4), round(b * period, 4)) for a, b in HALVING_WINDOWS]
    rows = _window_rows(config, windows, base)
    for row in rows:
        row["saving"] = _saving(row, base, "long_run_cost_of_transport") if row["walked"] else None
    savings = [r["saving"] for r in rows if r["saving"] is not None]
    best = max(savings) if savings else -0.5
    return max(-0.5, best) + 0.01 * len(savings), {**detail, "windows": rows, "best_saving": best}


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


def _saving(row: dict[str, Any], base: dict[str, Any], key: str = "cost_of_transport") -> float:
    """C_mt saving of a walk with a window against `base` without one, by the C_mt `key` names (the whole walk's,
    or "long_run_cost_of_transport"); -1 when either falls or has none."""
    if not (row["walked"] and base["walked"]) or not row.get(key) or not base.get(key):
        return -1.0
    return 1.0 - row[key] / base[key]


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
    "robust": Objective(_of_base(_robust_score), True, "How far the walk without a window is from holding when the simulation is refined or the start is nudged, scored for fallers too: (mean(f) - 1) - e / (len(ROBUST_CHECKS) + 1), f the fraction of the distance walked by the walk itself and under each of ROBUST_CHECKS (the plant step halved, the initiation speed x 0.95 and x 1.05, the +-PUSH_FORCE_N pushes), e the excess of the half step's relative C_mt change over ROBUST_CMT_CHANGE, in units of it, capped at 1 (1 when the half step falls); in [-7/6, 0], 0 once all hold.", 0.0),
    "converged": Objective(_of_base(_converged_score), True, 'The "robust" objective first (while a check fails, its score - 2), then how far the walk is from converged at its own plant step: -(s + c + m) / 3, s the excess of the step period\'s sd (the walk without a window, after the first 10 m; the larger of the walk\'s at its step and at half of it) over CONVERGED_STEP_SD_S, c that of the swing hip\'s sign changes per second (a 10 m walk after CONVERGED_AFTER_S) over CONVERGED_SIGN_CHANGES and m that of the half step\'s relative C_mt change over CONVERGED_CMT_CHANGE, each in units of its target and capped at 1; in [-1, 0] once all hold, 0 when all three are met.', 0.0),
    "calibrated": Objective(_of_base(_calibrated_score), True, 'The "converged" objective, then how far the walk without a window is from what the paper prints of its walker: (3 v - p - c) / 5, v the "converged" score, p how far the long-run step period lies from PAPER_STEP_PERIOD_S (the learner\'s start, 0.5 s, is "half of the walking cycle") and c how far the long-run C_mt lies from Table V\'s 0.58 without the window, each as its log-ratio beyond ln(1 + CALIBRATION_TOLERANCE), in units of ln(CALIBRATION_REACH), capped at 1; while a robust check fails, the "converged" score - 1; in [-1, 0] once all robust checks hold, 0 when the converged targets and both of the paper\'s figures are met.', 0.0),
    "halving": Objective(_of_base(_halving_score), True, 'The "robust" objective first (while a check fails, its score - 2), then the largest long-run C_mt saving among windows placed by the walk\'s own step period (HALVING_WINDOWS, fractions of it, walked over the search\'s distance), +0.01 for each window that walks (-0.5 when none saves more or none walks); a walker whose swing hip does less than HALVING_SCREEN_SHARE of the positive work without the window walks no window and scores its share - 1 (below any walker whose windows were walked).'),
    "story": Objective(_of_draws(_story_score), True, 'The "robust" objective first, then what the paper\'s learner would find, judged where it holds: while a robust check fails, the "robust" score - 2 (below every walker that holds); once all hold, the "policy" objective with every draw\'s reward gain taken as the smaller of its gains at the step and at half the step (each against no window at that step), the best draw\'s gain as the smallest of that and its gains from the initiation speed x 0.95 and x 1.05 (against no window from the same speed), minus 0.01 d / (1 + d), d the CPG\'s distance from Table III (a tie-breaker towards the paper); from -1.01 up.'),
    "hold": Objective(_of_base(_hold_score), True, 'The "robust" objective first, then whether every window the paper\'s learner may end on holds: the hip off from t1 until the swing foot lands (HOLD_WINDOWS: t1 across the end of the step; the learned windows\' t2 lie past the step\'s end, so the saving is a curve in t1), each walked as it is, at half the plant step and from 0.95 and 1.05 x the initiation speed, against no window under the same change. A window whose t1 lies past the powered step\'s end acts only when a step runs long, and once it acts the step runs long: two gaits, chosen by the walk\'s details, that save much in one walk and little in the next. The learner\'s reach is every window whose best reward gain over the four walks is within HOLD_PLATEAU of the best window\'s (GARB\'s reward is flat there, and a walk that falls into the long step pays it more), every window in HOLD_BAND (where the means of GARB with the paper\'s settings ended on the gaits it has been run on, whatever their reward\'s peak: 500 episodes from t1 0.5 s stop short of a peak further away), and every window within HOLD_MARGIN_S of one of those in t1 (the trials of one GARB run end that far apart on a flat reward); the score is the smallest C_mt saving over that reach and its four walks (-1 for a fall; >= 0.35 where every window GARB may end on holds), plus 0.1 x the mean over HOLD_WINDOWS of each window\'s smallest reward gain (a wider slope that holds), minus 0.01 d / (1 + d) as in "story".'),
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

