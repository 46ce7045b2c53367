"""The (1 + lambda) gait search: mutation bounds, monotone parent score, resume."""

import json
import math
import random

import numpy as np
import pytest
from retired_gaits import STEADY
from walkers import fast_config

from drake_biped.experiments import gait_search, objectives
from drake_biped.experiments.gait_search import (
    MUTATIONS,
    PAPER_MUTATIONS,
    GaitSearchSettings,
    _read_log,
    mutate,
    run,
)
from drake_biped.experiments.objectives import policy_draws
from drake_biped.params import PAPER_CPG, EpisodeConfig, ParameterError, SimulationParams


def test_mutation_changes_every_listed_parameter_within_bounds():
    c = fast_config()
    child = mutate(c, random.Random(1), sigma=0.5)
    for (section, name), (_, _, lo, hi) in MUTATIONS.items():
        before, after = getattr(getattr(c, section), name), getattr(getattr(child, section), name)
        assert lo <= after <= hi
        assert after != before
    assert child.initial == c.initial and child.sim == c.sim


def test_search_keeps_the_best_parent_and_resumes(tmp_path, client, capsys):
    start = fast_config(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
    kwargs = dict(offspring=2, sigma=0.3, seed=4, distance_m=0.3, windows=((0.1, 0.2),))
    run(GaitSearchSettings(start, generations=2, **kwargs), tmp_path, client, progress=False)
    records = _read_log(tmp_path / "search.jsonl")
    assert [r["generation"] for r in records] == [0, 1, 2]
    scores = [r["parent_score"] for r in records]
    assert scores == sorted(scores)  # a parent is only replaced by a child at least as good
    for prev, r in zip(records, records[1:]):
        assert r["parent_score"] == max(prev["parent_score"], r["best_child_score"])
    # A kill mid-write leaves a cut line: the resume drops it and goes on from generation 2.
    with open(tmp_path / "search.jsonl", "a") as f:
        f.write('{"generation": 3, "par')
    run(GaitSearchSettings(start, generations=3, **kwargs), tmp_path, client, progress=False)
    records = _read_log(tmp_path / "search.jsonl")
    assert [r["generation"] for r in records] == [0, 1, 2, 3]
    best = EpisodeConfig.from_dict(json.loads((tmp_path / "best_config.json").read_text()))
    assert best.to_dict() == records[-1]["parent"]
    assert (tmp_path / "search.jsonl.broken").is_file()
    # A damaged generation in the middle: the log is set aside with a warning, and the search resumes after the
    # generation before it, to the same generations.
    lines = (tmp_path / "search.jsonl").read_text().splitlines()
    damaged = "\n".join([lines[0], lines[1][:40], *lines[2:]]) + "\n"
    (tmp_path / "search.jsonl").write_text(damaged)
    capsys.readouterr()
    run(GaitSearchSettings(start, generations=3, **kwargs), tmp_path, client, progress=False)
    assert "search.jsonl has 1 line(s) that do not read as a gait-search generation (line 2" in capsys.readouterr().err
    assert (tmp_path / "search.jsonl.broken-2").read_text() == damaged
    assert _read_log(tmp_path / "search.jsonl") == records


def test_paper_mutations_hold_the_cpg_and_the_initiation():
    from drake_biped.params import InitialConditions
    from drake_biped.resources import load_gait

    # the retired `steady`'s gains lie inside every mutation's bounds, so each one moves
    c = load_gait(STEADY).replace(cpg=PAPER_CPG, initial=InitialConditions(cpg_phase_rad=1.0))
    child = mutate(c, random.Random(3), sigma=0.5, mutations=PAPER_MUTATIONS)
    assert child.cpg == PAPER_CPG
    assert (child.initial.hip_angle_rad, child.initial.speed_mps) == (c.initial.hip_angle_rad, c.initial.speed_mps)
    for (section, name), (_, _, lo, hi) in PAPER_MUTATIONS.items():
        assert section in ("gait", "initial") and name not in ("hip_angle_rad", "speed_mps")
        assert lo <= getattr(getattr(child, section), name) <= hi
        assert getattr(getattr(child, section), name) != getattr(getattr(c, section), name)


def test_policy_draws_are_the_paper_start_policy():
    draws = policy_draws(4000, seed=1)
    t = [d for d in draws if min(d) > 0.0]  # the clipping at 0 touches about 1 % of the draws
    assert len(t) > 0.97 * len(draws)
    for k in (0, 1):
        xs = [d[k] for d in t]
        mean = sum(xs) / len(xs)
        sd = math.sqrt(sum((x - mean) ** 2 for x in xs) / len(xs))
        assert mean == pytest.approx(0.5, abs=0.02) and sd == pytest.approx(0.2, abs=0.01)
    assert policy_draws() == policy_draws()  # fixed: the same windows score every candidate


def test_a_walker_outscores_any_fall_and_a_longer_fall_a_shorter(monkeypatch):
    walks = {}

    def fake_walk(config):
        d = walks[config.window.start_s, config.window.end_s]
        return {"walked": d >= config.sim.distance_m, "cost_of_transport": 0.2, "distance_m": d,
                "reward": min(d / config.sim.distance_m, 1.0) / 0.2}

    monkeypatch.setattr(objectives, "_walk", fake_walk)
    config = fast_config(sim=SimulationParams(distance_m=6.0))
    scores = []
    for d in (0.5, 3.0, 6.0):
        walks[0.0, 0.0] = d
        scores.append(objectives.score(config, windows=(), objective="walk")[0])
    assert scores[0] < scores[1] < -1.0 < scores[2] == 0.0


def test_policy_objective_is_the_expected_gain_of_the_draws(monkeypatch):
    """Windows that all walk at half the cost double the reward of the drawn windows; draws with t2 <= t1
    are no window: the score is mean gain + half the best gain."""

    def fake_walk(config):
        cmt = 0.1 if config.window.active else 0.2
        return {"walked": True, "cost_of_transport": cmt, "distance_m": 6.0, "reward": 1.0 / cmt}

    monkeypatch.setattr(objectives, "_walk", fake_walk)
    value, detail = objectives.score(fast_config(sim=SimulationParams(distance_m=6.0)), objective="policy")
    draws = policy_draws()
    windowed = sum(1 for t1, t2 in draws if t2 > t1)
    assert 0 < windowed < len(draws)
    assert value == pytest.approx(windowed / len(draws) + 0.5)
    assert [r["window"] for r in detail["windows"]] == [list(d) for d in draws]
    more = policy_draws(32)
    assert more[:len(draws)] == draws  # more draws extend the same fixed sequence
    value, detail = objectives.score(fast_config(sim=SimulationParams(distance_m=6.0)), objective="policy",
                                      draws=32)
    assert [r["window"] for r in detail["windows"]] == [list(d) for d in more]
    assert value == pytest.approx(sum(1 for t1, t2 in more if t2 > t1) / 32 + 0.5)
    value, _ = objectives.score(fast_config(sim=SimulationParams(distance_m=6.0)), objective="expected", draws=32)
    assert value == pytest.approx(sum(1 for t1, t2 in more if t2 > t1) / 32)  # the mean gain alone


def test_unknown_search_settings_are_refused():
    with pytest.raises(ParameterError, match="mutations"):
        GaitSearchSettings(mutations="everything")
    with pytest.raises(ParameterError, match="objective"):
        GaitSearchSettings(objective="speed")
    with pytest.raises(ParameterError, match="policy_draws"):
        GaitSearchSettings(policy_draws=0)


@pytest.mark.slow
def test_cmaes_search_resumes_to_the_uninterrupted_result(tmp_path, client):
    start = fast_config(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
    kwargs = dict(offspring=4, sigma=0.3, seed=2, distance_m=0.3, windows=((0.1, 0.2),))
    whole, parts = tmp_path / "whole", tmp_path / "parts"
    gait_search.run_cmaes(GaitSearchSettings(start, generations=3, **kwargs), whole, client, progress=False)
    gait_search.run_cmaes(GaitSearchSettings(start, generations=2, **kwargs), parts, client, progress=False)
    gait_search.run_cmaes(GaitSearchSettings(start, generations=3, **kwargs), parts, client, progress=False)
    a, b = _read_log(whole / "search.jsonl"), _read_log(parts / "search.jsonl")
    assert [r["generation"] for r in b] == [0, 1, 2, 3]
    assert [r.get("child_scores") for r in a] == [r.get("child_scores") for r in b]
    assert [r["parent"] for r in a] == [r["parent"] for r in b]
    scores = [r["parent_score"] for r in a]
    assert scores == sorted(scores)
    assert scores[-1] == max([a[0]["parent_score"]] + [max(r["child_scores"]) for r in a[1:]])
    best = json.loads((whole / "best_config.json").read_text())
    assert best == a[-1]["parent"]


def test_decode_maps_zero_to_the_start_and_stays_in_bounds():
    start = fast_config(cpg=PAPER_CPG)
    assert gait_search.decode(start, PAPER_MUTATIONS, [0.0] * len(PAPER_MUTATIONS)).gait == start.gait
    far = gait_search.decode(start, PAPER_MUTATIONS, [1000.0] * len(PAPER_MUTATIONS))
    for (section, name), (_, _, _, hi) in PAPER_MUTATIONS.items():
        assert getattr(getattr(far, section), name) == hi
    assert far.cpg == PAPER_CPG


def test_nearest_objective_prefers_the_walker_nearest_table_iii(monkeypatch):
    monkeypatch.setattr(objectives, "_walk", lambda config: {"walked": True, "cost_of_transport": 0.2,
                                                              "distance_m": 6.0, "reward": 5.0})
    near = fast_config(cpg=PAPER_CPG.__class__(u_a=2.2, u_r=2.1, kappa=1.8))
    far = fast_config()  # the default gait's CPG: u_r 4.6
    assert objectives.score(fast_config(cpg=PAPER_CPG), objective="nearest")[0] == 0.0
    d = math.log(1.1)
    assert objectives.score(near, objective="nearest")[0] == pytest.approx(-d / (1 + d) / 3)
    assert objectives.score(far, objective="nearest")[0] < objectives.score(near, objective="nearest")[0]


def test_nearest_objective_ranks_a_walker_that_survives_the_pushes_first(monkeypatch):
    # A walker that reaches the distance only undisturbed (a lucky walk near a cliff in the parameters) falls
    # to a push; any walker beats every fall, and surviving both pushes beats any nearness.
    def fake(walks_pushed):
        def walk(config):
            pushed = config.push is not None and config.push.force_n != 0.0
            walked = walks_pushed or not pushed
            return {"walked": walked, "cost_of_transport": 0.2, "distance_m": 6.0 if walked else 5.9,
                    "reward": 5.0}
        return walk

    exact = fast_config(cpg=PAPER_CPG).override({"sim.distance_m": 6.0})
    far = fast_config().override({"sim.distance_m": 6.0, "u_r": 30.0, "u_a": 0.05})
    monkeypatch.setattr(objectives, "_walk", fake(walks_pushed=False))
    lucky, detail = objectives.score(exact, objective="nearest")
    assert [p["push_n"] for p in detail["pushes"]] == [objectives.PUSH_FORCE_N, -objectives.PUSH_FORCE_N]
    monkeypatch.setattr(objectives, "_walk", fake(walks_pushed=True))
    robust_far = objectives.score(far, objective="nearest")[0]
    monkeypatch.setattr(objectives, "_walk", lambda config: {"walked": False, "cost_of_transport": 0.3,
                                                              "distance_m": 5.9, "reward": 3.0})
    fall = objectives.score(exact, objective="nearest")[0]
    assert lucky == pytest.approx(-2.0 / 3.0)
    assert fall < -1.0 < lucky < robust_far < 0.0


def _fake_story_walk(half_step_cmt=0.2, fall_at_fast_start=False):
    """A stand-in walk: no window costs 0.2; a window halves it at the 1 ms step but saves only 25 % at half
    the step and 10 % from 0.95 x the initiation speed; the walk from 1.05 x the speed falls when asked."""
    def walk(config):
        step, speed = config.sim.time_step_s, config.initial.speed_mps
        fast, slow = speed > 1.01 * 0.175, speed < 0.99 * 0.175
        if fall_at_fast_start and fast:
            return {"walked": False, "cost_of_transport": 0.2, "distance_m": 2.5, "reward": 0.25 / 0.2}
        if not config.window.active:
            cmt = half_step_cmt if step < 0.001 else 0.2
        elif step < 0.001:
            cmt = 0.15
        else:
            cmt = 0.18 if slow else 0.1
        return {"walked": True, "cost_of_transport": cmt, "distance_m": 10.0, "reward": 1.0 / cmt}
    return walk


def test_robust_objective_counts_the_distance_walked_and_the_half_steps_cmt_change(monkeypatch):
    """All checks walk: 0, less 1/6 when the half step changes C_mt by 5 % (capped excess 1); a check that
    falls at a quarter of the distance takes (1/4 - 1)/6 from the mean fraction walked."""
    config = fast_config(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    monkeypatch.setattr(objectives, "_walk", _fake_story_walk())
    assert objectives.score(config, objective="robust")[0] == 0.0
    monkeypatch.setattr(objectives, "_walk", _fake_story_walk(half_step_cmt=0.21))
    value, detail = objectives.score(config, objective="robust")
    assert detail["half_step_cmt_change"] == pytest.approx(0.05)
    assert value == pytest.approx(-1.0 / 6.0)
    monkeypatch.setattr(objectives, "_walk", _fake_story_walk(fall_at_fast_start=True))
    assert objectives.score(config, objective="robust")[0] == pytest.approx((0.25 - 1.0) / 6.0)


def test_story_objective_judges_each_draw_where_it_saves_least(monkeypatch):
    """The robust checks hold: each drawn window's gain is its gain at half the step (1/3, not 1), and the best
    draw's is its gain from 0.95 x the initiation speed (1/9); a gait that fails a robust check scores below -2."""
    config = fast_config(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    monkeypatch.setattr(objectives, "_walk", _fake_story_walk())
    value, detail = objectives.score(config, objective="story")
    windowed = sum(1 for t1, t2 in policy_draws() if t2 > t1)
    d = objectives.distance_from_table_iii(config.cpg)
    assert detail["gains"] == pytest.approx([1.0 / 3.0 if t2 > t1 else 0.0 for t1, t2 in policy_draws()])
    assert detail["best_draw"]["gain"] == pytest.approx(1.0 / 9.0)
    assert value == pytest.approx(windowed / 12 / 3.0 + 0.5 / 9.0 - 0.01 * d / (1.0 + d))
    monkeypatch.setattr(objectives, "_walk", _fake_story_walk(fall_at_fast_start=True))
    value, _ = objectives.score(config, objective="story")
    assert value == pytest.approx((0.25 - 1.0) / 6.0 - 2.0)


def _fake_edge_walk(edge_saving, edge_half_step_saving, edge_t1=0.46, fall_off=0.0):
    """A stand-in walk: no window costs 0.2; a window with t1 < `edge_t1` saves 45 % less `fall_off` per second of
    t1 past 0.30 s in every walk, one with t1 >= `edge_t1` (past the powered step's end) saves `edge_saving`, and
    `edge_half_step_saving` at half the plant step."""
    def saving(t1, half_step):
        if t1 < edge_t1 - 1e-9:
            return 0.45 - fall_off * (t1 - 0.30)
        return edge_half_step_saving if half_step else edge_saving

    def walk(config):
        cmt = 0.2 * (1.0 - saving(config.window.start_s, config.sim.time_step_s < 0.001)) \
            if config.window.active else 0.2
        return {"walked": True, "cost_of_transport": cmt, "distance_m": 10.0, "reward": 1.0 / cmt}
    return walk, saving


@pytest.mark.parametrize("edge, half, edge_t1, fall_off, reach, least", [
    (0.5, 0.1, 0.46, 0.0, (0.34, 0.56), 0.1),  # the edge saves most as it is: the learner goes there
    (0.4, 0.4, 0.46, 0.0, (0.30, 0.50), 0.4),  # earlier windows save most; the edge next to them holds
    (0.4, 0.1, 0.46, 0.0, (0.30, 0.50), 0.1),  # ... and does not: a trial that ends 0.02 s late loses the saving
    # The reward peaks at 0.30-0.32 s; 500 episodes from 0.5 s may stop anywhere in 0.36-0.48 s, next to the edge.
    (0.4, 0.1, 0.50, 0.5, (0.30, 0.50), 0.1),
    (0.4, 0.4, 0.50, 0.5, (0.30, 0.50), 0.36),
])
def test_hold_objective_judges_every_window_within_the_learners_reach(monkeypatch, edge, half, edge_t1, fall_off,
                                                                       reach, least):
    """The learner's reach is the windows within 0.05 of the best reward gain in any of the four walks, those with
    t1 in 0.36-0.48 s, and those 0.02 s from either; the score is the smallest saving there, in any walk, plus a
    tenth of the mean smallest gain."""
    config = fast_config(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    walk, saving = _fake_edge_walk(edge, half, edge_t1, fall_off)
    monkeypatch.setattr(objectives, "_walk", walk)
    value, detail = objectives.score(config, objective="hold")
    t1s = [t1 for t1, _ in objectives.HOLD_WINDOWS]
    assert [t1 for t1, _ in detail["reach"]] == [t1 for t1 in t1s if reach[0] - 1e-9 <= t1 <= reach[1] + 1e-9]
    assert detail["least_saving"] == pytest.approx(least)
    gains = [1 / (1 - min(saving(t1, False), saving(t1, True))) - 1 for t1 in t1s]
    d = objectives.distance_from_table_iii(config.cpg)
    assert value == pytest.approx(least + 0.1 * sum(gains) / len(gains) - 0.01 * d / (1.0 + d))


@pytest.mark.parametrize("method", ["es", "cmaes"])
def test_a_search_stops_once_the_objective_maximum_is_reached(tmp_path, client, method):
    # "walk" scores every walker 0, its maximum: a start that walks leaves nothing to search for.
    start = fast_config(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
    settings = GaitSearchSettings(start, generations=5, offspring=4, sigma=0.3, seed=2, distance_m=0.3,
                                  objective="walk")
    search = gait_search.run_cmaes if method == "cmaes" else run
    result = search(settings, tmp_path, client, progress=False)
    assert objectives.OBJECTIVES["walk"].maximum == result["score"] == 0.0
    assert [r["generation"] for r in _read_log(tmp_path / "search.jsonl")] == [0]
    # A start that falls is searched: the maximum stops nothing it has not reached.
    falling = start.override({"cpg.u_r": 0.6, "cpg.u_a": 0.1})
    search(GaitSearchSettings(falling, generations=1, offspring=2, sigma=0.3, seed=2, distance_m=0.3,
                              objective="walk"), tmp_path / "falls", client, progress=False)
    assert [r["generation"] for r in _read_log(tmp_path / "falls" / "search.jsonl")][:2] == [0, 1]


def test_a_search_over_gains_its_gait_leaves_unread_is_refused_naming_them_and_the_sets_that_fit():
    """The servo's gains do not act under the hip motor (GaitParams.unread), nor the motor's limit under the
    servo: a mutation set that moves them is refused before any work, with the sets that fit."""
    from drake_biped.params import ParameterError
    from drake_biped.resources import load_gait

    with pytest.raises(ParameterError, match=r"'paper' move hip_kp.*unread \(hip_drive 'motor', phase_reading "
                                             r"'reset'\).*\['paper_motor'\]"):
        GaitSearchSettings(config=load_gait("paper"), mutations="paper")
    with pytest.raises(ParameterError, match="'paper_motor' move motor_limit_nm"):
        GaitSearchSettings(config=load_gait("fast_servo"), mutations="paper_motor")
    # unless told, the set that fits the gait's hip drive
    assert GaitSearchSettings().mutations == "paper_motor"
    assert GaitSearchSettings(config=load_gait("fast_servo")).mutations == "servo"
    GaitSearchSettings(config=load_gait("paper"), mutations="paper_motor")  # every gain it moves is read
    # the entrained phase leaves the touchdown threshold unread, which every set moves: it cannot be avoided, so
    # the readings searched from entrained starts still run (benchmarks/results/paper-walker/start-*-entrained)
    entrained = load_gait("paper").override({"gait.phase_reading": "entrained"})
    assert "touchdown_min_phase" in entrained.gait.unread()
    GaitSearchSettings(config=entrained, mutations="paper_motor")
    with pytest.raises(ParameterError, match=r"move hip_kp.*\['paper_motor'\]"):
        GaitSearchSettings(config=entrained, mutations="paper")
    servo = load_gait("paper_entrained")  # the servo, entrained: the motor's limit is avoidable, the threshold not
    with pytest.raises(ParameterError, match=r"'paper_motor' move motor_limit_nm, which.*'coast'"):
        GaitSearchSettings(config=servo, mutations="paper_motor")
    GaitSearchSettings(config=servo, mutations="paper")


def test_converged_objective_scores_the_spread_and_the_chatter_at_the_walks_own_step(monkeypatch):
    """Fake walks: while a robust check fails, the robust score - 2; once all hold, -(s + c + m) / 3 with s the
    step period's sd over 1 ms less 1, c the swing hip's sign changes a second over 20 less 1 and m the half step's
    C_mt change over 0.5 % less 1, each capped at 1: 0.5 ms, 10 a second and 0.2 % score 0; 2 ms, 30 a second and
    0.75 % -(1 + 0.5 + 0.5) / 3. The spread is the larger of the walk's at its step and at half of it: regular at
    its step, 1.5 ms at half of it (a period-doubled orbit there) scores -0.5 / 3."""
    import types

    from drake_biped import episode

    def recorded(changes_per_s):
        t = np.arange(0.0, 10.0, 1e-3)
        act = np.zeros((len(t), 6))
        act[:, 0] = np.where(np.sin(np.pi * changes_per_s * t + 0.1) >= 0.0, 1.0, -1.0)  # the left hip swings
        return types.SimpleNamespace(fell=False, duration_s=10.0, trajectory={
            "time": t, "actuation": act, "stance_right": np.ones(len(t)),
            "actuator_names": np.array([f"{leg}_{j}_motor" for leg in ("left", "right") for j in ("hip", "knee", "ankle")])})

    config = fast_config(sim=SimulationParams(distance_m=100.0))
    for robust, spread, half, changes, moved, expected in ((0.0, 5e-4, 4e-4, 10.0, 0.002, 0.0),
                                                           (0.0, 2e-3, 5e-4, 30.0, -0.0075, -2.0 / 3.0),
                                                           (0.0, 5e-4, 1.5e-3, 10.0, 0.002, -0.5 / 3.0),
                                                           (-0.3, 5e-4, 4e-4, 10.0, 0.002, -2.3)):
        base = {"walked": True, "cost_of_transport": 0.2, "distance_m": 100.0, "reward": 5.0,
                "step_period_std_s": spread}
        monkeypatch.setattr(objectives, "_walk", lambda c, base=base: base)
        checks = {"half_step": {"step_period_std_s": half}}
        monkeypatch.setattr(objectives, "_robust_score", lambda c, b, r=robust, m=moved, k=checks: (
            r, {"checks": k, "half_step_cmt_change": m}))
        monkeypatch.setattr(episode, "run_episode", lambda c, record_trajectory=False, n=changes: recorded(n))
        value, detail = objectives.score(config, objective="converged")
        assert value == pytest.approx(expected, abs=0.01), (robust, spread, half, changes, moved, detail)
    assert objectives.OBJECTIVES["converged"].maximum == 0.0


def test_calibrated_objective_asks_the_papers_step_and_cmt_once_converged(monkeypatch):
    """Fake walks: a converged walker (its "converged" score 0) scores 0 when its long-run step period is within
    a factor 1.1 of 1.0 s and its long-run C_mt within 1.1 of Table V's 0.58; beyond, each costs its log-ratio
    less ln 1.1, over ln 4, capped at 1, over 5 (1.3 s steps (ln 1.3 - ln 1.1) / ln 4 / 5 = 0.0241; C_mt 0.213,
    0.1308), so that of two walkers far from 0.58 the nearer scores higher (0.18 above 0.15), and a factor 4
    past costs the whole 1/5; a walker whose converged score is v < 0 keeps 3 v / 5; one whose robust checks
    fail ranks below every one that holds."""
    config = fast_config(sim=SimulationParams(distance_m=100.0))
    cases = ((0.0, 1.05, 0.60, 0.0), (0.0, 1.3, 0.60, -0.024100810), (0.0, 1.3, 0.213, -0.154870405),
             (0.0, 0.95, 0.55, 0.0), (-0.5, 1.0, 0.58, -0.3), (0.0, 1.15, 0.58, -0.006413034),
             (0.0, 1.0, 0.15, -0.181358688), (0.0, 1.0, 0.18, -0.155055247), (0.0, 0.25, 0.1, -0.386249648))
    for converged, period, cost, expected in cases:
        base = {"walked": True, "cost_of_transport": cost, "distance_m": 100.0, "reward": 1 / cost,
                "step_period_std_s": 1e-3, "step_period_mean_s": period, "long_run_cost_of_transport": cost}
        monkeypatch.setattr(objectives, "_walk", lambda c, base=base: base)
        monkeypatch.setattr(objectives, "_converged_score",
                            lambda c, b, v=converged: (v, {"converged": {}, "checks": {}}))
        value, detail = objectives.score(config, objective="calibrated")
        assert value == pytest.approx(expected, abs=1e-8), (period, cost, detail)
    monkeypatch.setattr(objectives, "_converged_score", lambda c, b: (-2.1, {"checks": {}}))
    assert objectives.score(config, objective="calibrated")[0] < -1.0
    assert objectives.OBJECTIVES["calibrated"].maximum == 0.0


def test_halving_objective_walks_windows_placed_by_the_step_only_where_the_swing_hip_works(monkeypatch):
    """Fake walks with 0.8 s steps: a walker whose swing hip does 20 % of the work walks no window and scores
    0.2 - 1; one doing 60 % walks HALVING_WINDOWS at fractions of its own 0.8 s step, and scores the best
    long-run saving (a window ending at touchdown halves C_mt) plus 0.01 per window that walks; a window that
    falls is no saving."""
    config = fast_config(sim=SimulationParams(distance_m=100.0))
    walked = []

    def walk(c, share):
        w = c.window
        if w.active:
            walked.append((w.start_s, w.end_s))
        cost = 0.4
        if w.active and abs(w.end_s - 0.8) < 1e-9:
            cost = 0.2
        falls = w.active and w.end_s > 0.9
        return {"walked": not falls, "cost_of_transport": cost, "distance_m": 50.0 if falls else 100.0,
                "reward": 1 / cost, "step_period_std_s": 1e-3, "step_period_mean_s": 0.8,
                "long_run_cost_of_transport": cost, "swing_hip_share": share}

    monkeypatch.setattr(objectives, "_robust_score", lambda c, b: (0.0, {"checks": {}}))
    monkeypatch.setattr(objectives, "_walk", lambda c: walk(c, 0.2))
    value, detail = objectives.score(config, objective="halving")
    assert value == pytest.approx(0.2 - 1.0) and walked == [] and detail["swing_hip_share"] == 0.2
    monkeypatch.setattr(objectives, "_walk", lambda c: walk(c, 0.6))
    value, detail = objectives.score(config, objective="halving")
    expected = [(round(a * 0.8, 4), round(b * 0.8, 4)) for a, b in objectives.HALVING_WINDOWS]
    assert walked == expected
    assert detail["best_saving"] == pytest.approx(0.5)
    assert value == pytest.approx(0.5 + 0.01 * (len(expected) - 1))  # the window to 1.2 x the step falls
    monkeypatch.setattr(objectives, "_robust_score", lambda c, b: (-0.4, {"checks": {}}))
    assert objectives.score(config, objective="halving")[0] == pytest.approx(-2.4)


def test_an_objectives_walk_row_says_how_the_walk_ended():
    """A search's record tells a walk that ended on its distance from one stopped by the time limit (or a fall, or
    a failed contact solve: EpisodeResult.termination), each as the episode itself said."""
    from drake_biped.experiments import objectives
    from drake_biped.resources import load_gait

    short = load_gait("paper").override({"sim.distance_m": 0.3, "sim.max_time_s": 4.0})
    walked = objectives._walk(short)
    assert walked["walked"] and walked["termination"] == "distance"
    stopped = objectives._walk(short.override({"sim.max_time_s": 0.2}))
    assert not stopped["walked"] and stopped["termination"] == "time limit"
