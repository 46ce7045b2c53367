"""The (1 + lambda) gait search: mutation bounds, monotone parent score, resume."""

import json
import math
import random

import numpy as np
import pytest

from drake_biped.experiments import gait_search
from drake_biped.experiments.gait_search import (
    MUTATIONS,
    PAPER_MUTATIONS,
    GaitSearchSettings,
    _read_log,
    mutate,
    policy_draws,
    run,
)
from drake_biped.params import PAPER_CPG, EpisodeConfig, ParameterError, SimulationParams


def test_mutation_changes_every_listed_parameter_within_bounds():
    c = EpisodeConfig()
    child = mutate(c, random.Random(1), sigma=0.5)
    for (section, name), (_, _, lo, hi) in MUTATIONS.items():
        before, after = getattr(getattr(c, section), name), getattr(getattr(child, section), name)
        assert lo <= after <= hi
        assert after != before
    assert child.initial == c.initial and child.sim == c.sim


def test_search_keeps_the_best_parent_and_resumes(tmp_path, client, capsys):
    start = EpisodeConfig(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
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

    # steady's gains lie inside every mutation's bounds, so each one moves
    c = load_gait("steady").replace(cpg=PAPER_CPG, initial=InitialConditions(cpg_phase_rad=1.0))
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

    monkeypatch.setattr(gait_search, "_walk", fake_walk)
    config = EpisodeConfig(sim=SimulationParams(distance_m=6.0))
    scores = []
    for d in (0.5, 3.0, 6.0):
        walks[0.0, 0.0] = d
        scores.append(gait_search.score(config, windows=(), objective="walk")[0])
    assert scores[0] < scores[1] < -1.0 < scores[2] == 0.0


def test_policy_objective_is_the_expected_gain_of_the_draws(monkeypatch):
    """Windows that all walk at half the cost double the reward of the drawn windows; draws with t2 <= t1
    are no window: the score is mean gain + half the best gain."""

    def fake_walk(config):
        cmt = 0.1 if config.window.active else 0.2
        return {"walked": True, "cost_of_transport": cmt, "distance_m": 6.0, "reward": 1.0 / cmt}

    monkeypatch.setattr(gait_search, "_walk", fake_walk)
    value, detail = gait_search.score(EpisodeConfig(sim=SimulationParams(distance_m=6.0)), objective="policy")
    draws = policy_draws()
    windowed = sum(1 for t1, t2 in draws if t2 > t1)
    assert 0 < windowed < len(draws)
    assert value == pytest.approx(windowed / len(draws) + 0.5)
    assert [r["window"] for r in detail["windows"]] == [list(d) for d in draws]
    more = policy_draws(32)
    assert more[:len(draws)] == draws  # more draws extend the same fixed sequence
    value, detail = gait_search.score(EpisodeConfig(sim=SimulationParams(distance_m=6.0)), objective="policy",
                                      draws=32)
    assert [r["window"] for r in detail["windows"]] == [list(d) for d in more]
    assert value == pytest.approx(sum(1 for t1, t2 in more if t2 > t1) / 32 + 0.5)
    value, _ = gait_search.score(EpisodeConfig(sim=SimulationParams(distance_m=6.0)), objective="expected", draws=32)
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
    start = EpisodeConfig(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
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
    start = EpisodeConfig(cpg=PAPER_CPG)
    assert gait_search.decode(start, PAPER_MUTATIONS, [0.0] * len(PAPER_MUTATIONS)).gait == start.gait
    far = gait_search.decode(start, PAPER_MUTATIONS, [1000.0] * len(PAPER_MUTATIONS))
    for (section, name), (_, _, _, hi) in PAPER_MUTATIONS.items():
        assert getattr(getattr(far, section), name) == hi
    assert far.cpg == PAPER_CPG


def test_nearest_objective_prefers_the_walker_nearest_table_iii(monkeypatch):
    monkeypatch.setattr(gait_search, "_walk", lambda config: {"walked": True, "cost_of_transport": 0.2,
                                                              "distance_m": 6.0, "reward": 5.0})
    near = EpisodeConfig(cpg=PAPER_CPG.__class__(u_a=2.2, u_r=2.1, kappa=1.8))
    far = EpisodeConfig()  # the default gait's CPG: u_r 4.6
    assert gait_search.score(EpisodeConfig(cpg=PAPER_CPG), objective="nearest")[0] == 0.0
    d = math.log(1.1)
    assert gait_search.score(near, objective="nearest")[0] == pytest.approx(-d / (1 + d) / 3)
    assert gait_search.score(far, objective="nearest")[0] < gait_search.score(near, objective="nearest")[0]


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

    exact = EpisodeConfig(cpg=PAPER_CPG).override({"sim.distance_m": 6.0})
    far = EpisodeConfig().override({"sim.distance_m": 6.0, "u_r": 30.0, "u_a": 0.05})
    monkeypatch.setattr(gait_search, "_walk", fake(walks_pushed=False))
    lucky, detail = gait_search.score(exact, objective="nearest")
    assert [p["push_n"] for p in detail["pushes"]] == [gait_search.PUSH_FORCE_N, -gait_search.PUSH_FORCE_N]
    monkeypatch.setattr(gait_search, "_walk", fake(walks_pushed=True))
    robust_far = gait_search.score(far, objective="nearest")[0]
    monkeypatch.setattr(gait_search, "_walk", lambda config: {"walked": False, "cost_of_transport": 0.3,
                                                              "distance_m": 5.9, "reward": 3.0})
    fall = gait_search.score(exact, objective="nearest")[0]
    assert lucky == pytest.approx(-2.0 / 3.0)
    assert fall < -1.0 < lucky < robust_far < 0.0


def test_coast_objective_scores_windows_that_run_to_touchdown(monkeypatch):
    seen = []

    def fake_walk(config):
        seen.append((config.window.start_s, config.window.end_s))
        walked = not config.window.active or config.window.start_s >= 0.3  # coasting from 0.2 s falls
        cmt = 0.1 if config.window.active else 0.2
        return {"walked": walked, "cost_of_transport": cmt, "distance_m": 6.0 if walked else 3.0,
                "reward": (1.0 if walked else 0.5) / cmt}

    monkeypatch.setattr(gait_search, "_walk", fake_walk)
    value, _ = gait_search.score(EpisodeConfig(sim=SimulationParams(distance_m=6.0)), objective="coast")
    assert seen[1:] == list(gait_search.COAST_WINDOWS) and all(t2 >= 5.0 for _, t2 in seen[1:])
    assert value == pytest.approx((0.0 + 1.0 + 1.0 + 1.0) / 4 + 0.5 * 1.0)


def test_floquet_objective_rewards_an_attracting_orbit(monkeypatch):
    """(1 - rho) / (1 + rho): positive once the orbit attracts, below every converged orbit's for a Newton
    that did not converge, and a walker whose orbit cannot be linearised between every walker and every
    faller."""
    from drake_biped.analysis.floquet import StepFailed
    from drake_biped.common import floquet_runs as floquet

    monkeypatch.setattr(gait_search, "_walk", lambda config: {"walked": True, "cost_of_transport": 0.2,
                                                              "distance_m": 6.0, "reward": 5.0})
    orbits = iter([{"spectral_radius": 0.5, "fixed_point_residual": 1e-9},
                   {"spectral_radius": 2.0, "fixed_point_residual": 1e-9},
                   {"spectral_radius": 0.5, "fixed_point_residual": 1e-2}])
    monkeypatch.setattr(floquet, "orbit_radius", lambda config: next(orbits))
    config = EpisodeConfig(sim=SimulationParams(distance_m=6.0))
    values = [gait_search.score(config, objective="floquet")[0] for _ in range(3)]
    assert values == pytest.approx([1.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0])
    assert values[2] < 0.0 < values[0]

    def falls(config):
        raise StepFailed("a perturbed step fell")

    monkeypatch.setattr(floquet, "orbit_radius", falls)
    value, detail = gait_search.score(config, objective="floquet")
    assert value == gait_search.FLOQUET_UNDEFINED and "fell" in detail["orbit"]["error"]
    assert -9.0 + 8.0 * 0.999 < value < min(values)


def test_landscape_objective_is_the_start_policys_gain_and_counts_failed_pushes(monkeypatch):
    """Every window halves the cost: the paper's start policy N((0.5, 0.5), 0.04 I) draws a window (t2 > t1)
    half the time, so it expects +50 %; a policy mean far above the diagonal draws one always (+100 %); a
    gait that falls to the backward push loses PUSH_PENALTY."""
    seen = []

    def fake_walk(config):
        push = config.push.force_n if config.push is not None else 0.0
        seen.append((config.window.start_s, config.window.end_s, push))
        walked = push >= 0.0
        cmt = 0.1 if config.window.active else 0.2
        return {"walked": walked, "cost_of_transport": cmt, "distance_m": 6.0, "reward": 1.0 / cmt}

    monkeypatch.setattr(gait_search, "_walk", fake_walk)
    value, detail = gait_search.score(EpisodeConfig(sim=SimulationParams(distance_m=6.0)), objective="landscape")
    windows = [(t1, t2) for t1, t2, push in seen if push == 0.0 and t2 > t1]
    assert windows == list(gait_search.LANDSCAPE_WINDOWS) and all(0 <= t1 <= 0.8 and t2 <= 1.2 for t1, t2 in windows)
    assert sorted(push for *_, push in seen if push) == [-gait_search.PUSH_FORCE_N, gait_search.PUSH_FORCE_N]
    assert detail["landscape"]["start_gain"] == pytest.approx(0.5, abs=0.05)
    assert detail["landscape"]["best_gain"] == pytest.approx(1.0, abs=0.02)
    assert value == pytest.approx(detail["landscape"]["start_gain"] + 0.5 * gait_search.BEST_GAIN_CAP
                                  - gait_search.PUSH_PENALTY)


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
    config = EpisodeConfig(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    monkeypatch.setattr(gait_search, "_walk", _fake_story_walk())
    assert gait_search.score(config, objective="robust")[0] == 0.0
    monkeypatch.setattr(gait_search, "_walk", _fake_story_walk(half_step_cmt=0.21))
    value, detail = gait_search.score(config, objective="robust")
    assert detail["half_step_cmt_change"] == pytest.approx(0.05)
    assert value == pytest.approx(-1.0 / 6.0)
    monkeypatch.setattr(gait_search, "_walk", _fake_story_walk(fall_at_fast_start=True))
    assert gait_search.score(config, objective="robust")[0] == pytest.approx((0.25 - 1.0) / 6.0)


def test_story_objective_judges_each_draw_where_it_saves_least(monkeypatch):
    """The robust checks hold: each drawn window's gain is its gain at half the step (1/3, not 1), and the best
    draw's is its gain from 0.95 x the initiation speed (1/9); a gait that fails a robust check scores below -2."""
    config = EpisodeConfig(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    monkeypatch.setattr(gait_search, "_walk", _fake_story_walk())
    value, detail = gait_search.score(config, objective="story")
    windowed = sum(1 for t1, t2 in policy_draws() if t2 > t1)
    d = gait_search.distance_from_table_iii(config.cpg)
    assert detail["gains"] == pytest.approx([1.0 / 3.0 if t2 > t1 else 0.0 for t1, t2 in policy_draws()])
    assert detail["best_draw"]["gain"] == pytest.approx(1.0 / 9.0)
    assert value == pytest.approx(windowed / 12 / 3.0 + 0.5 / 9.0 - 0.01 * d / (1.0 + d))
    monkeypatch.setattr(gait_search, "_walk", _fake_story_walk(fall_at_fast_start=True))
    value, _ = gait_search.score(config, objective="story")
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
    config = EpisodeConfig(sim=SimulationParams(distance_m=10.0, time_step_s=0.001))
    walk, saving = _fake_edge_walk(edge, half, edge_t1, fall_off)
    monkeypatch.setattr(gait_search, "_walk", walk)
    value, detail = gait_search.score(config, objective="hold")
    t1s = [t1 for t1, _ in gait_search.HOLD_WINDOWS]
    assert [t1 for t1, _ in detail["reach"]] == [t1 for t1 in t1s if reach[0] - 1e-9 <= t1 <= reach[1] + 1e-9]
    assert detail["least_saving"] == pytest.approx(least)
    gains = [1 / (1 - min(saving(t1, False), saving(t1, True))) - 1 for t1 in t1s]
    d = gait_search.distance_from_table_iii(config.cpg)
    assert value == pytest.approx(least + 0.1 * sum(gains) / len(gains) - 0.01 * d / (1.0 + d))


def test_hold_step_places_windows_by_the_gaits_step_and_subtracts_the_lure(monkeypatch):
    """Fake walks: a 0.42 s powered step, every window below it saving 40 % long-run under every change, and a
    10 m episode past the step saving 25 % (t1 0.435) and 10 % (t1 0.46): score = 0.40 - 0.25 + 0.1 x 0.40."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    monkeypatch.setattr(gait_search, "_robust_score", lambda config, b: (0.0, {"checks": {}}))
    seen = []

    def long_walk(config):
        if config.window.end_s <= config.window.start_s:
            return {"walked": True, "cost_of_transport": 0.6, "step_period_s": 0.42}
        seen.append(round(config.window.start_s, 4))
        return {"walked": True, "cost_of_transport": 0.36, "step_period_s": 0.5}

    def walk(config):
        saving = {0.435: 0.25, 0.46: 0.10}[round(config.window.start_s, 3)]
        return {"walked": True, "cost_of_transport": 0.5 * (1 - saving), "distance_m": 10.0}

    monkeypatch.setattr(gait_search, "_long_walk", long_walk)
    monkeypatch.setattr(gait_search, "_walk", walk)
    config = EpisodeConfig().replace(cpg=PAPER_CPG)
    value, detail = gait_search.OBJECTIVES["hold-step"].score(config, base, (), 0)
    assert sorted(set(seen)) == [0.34, 0.38, 0.405]  # T - 0.08, T - 0.04, T - 0.015, each under 4 changes
    assert len(seen) == 12
    assert detail["past_step_saving"] == pytest.approx(0.25) and detail["least_saving"] == pytest.approx(0.4)
    assert value == pytest.approx(0.40 - 0.25 + 0.04)  # Table III's CPG: no distance term


def test_hold_slow_takes_the_hold_step_score_less_the_penalty_for_a_short_step(monkeypatch):
    """The same fake walks as above: a 0.42 s step is 0.13 s short of the 0.55 s floor; a 0.6 s step is not."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    monkeypatch.setattr(gait_search, "_robust_score", lambda config, b: (0.0, {"checks": {}}))
    config = EpisodeConfig().replace(cpg=PAPER_CPG)
    for period, short in ((0.42, 0.13), (0.6, 0.0)):
        def long_walk(c, period=period):
            if c.window.end_s <= c.window.start_s:
                return {"walked": True, "cost_of_transport": 0.6, "step_period_s": period}
            return {"walked": True, "cost_of_transport": 0.36, "step_period_s": period}

        monkeypatch.setattr(gait_search, "_long_walk", long_walk)
        monkeypatch.setattr(gait_search, "_walk", lambda c: {"walked": True, "cost_of_transport": 0.45,
                                                             "distance_m": 10.0})
        step, _ = gait_search.OBJECTIVES["hold-step"].score(config, base, (), 0)
        value, detail = gait_search.OBJECTIVES["hold-slow"].score(config, base, (), 0)
        assert step == pytest.approx(0.40 - 0.10 + 0.04)
        assert detail["short_of_floor_s"] == pytest.approx(short)
        assert value == pytest.approx(step - gait_search.HOLD_SLOW_PENALTY * short)


def _fake_band_walks(monkeypatch, weak_t1: float, weak_saving: float) -> list[tuple[float, bool]]:
    """Fake walks for "hold-edge" and "hold-lure": every band window saves 40 % long-run under every change except
    t1 `weak_t1` at half the plant step (`weak_saving`); 10 m episodes at t1 0.48 / 0.50 s save 20 % / 30 %. The
    (t1, at half the step) of each long walk with a window, as walked."""
    monkeypatch.setattr(gait_search, "_robust_score", lambda config, b: (0.0, {"checks": {}}))
    seen = []

    def long_walk(config):
        if config.window.end_s <= config.window.start_s:
            return {"walked": True, "cost_of_transport": 0.6, "step_period_s": 0.46}
        half = config.sim.time_step_s < EpisodeConfig().sim.time_step_s
        seen.append((round(config.window.start_s, 3), half))
        saving = weak_saving if half and round(config.window.start_s, 3) == weak_t1 else 0.40
        return {"walked": True, "cost_of_transport": 0.6 * (1 - saving), "step_period_s": 0.5}

    def walk(config):
        saving = {0.48: 0.20, 0.5: 0.30}[round(config.window.start_s, 3)]
        return {"walked": True, "cost_of_transport": 0.5 * (1 - saving), "distance_m": 10.0}

    monkeypatch.setattr(gait_search, "_long_walk", long_walk)
    monkeypatch.setattr(gait_search, "_walk", walk)
    return seen


def test_hold_edge_scores_the_least_long_run_saving_at_the_band_top_less_the_start_lure(monkeypatch):
    """Fake walks: every fixed window saves 40 % long-run except t1 0.44 s at half the plant step (5 %, the edge
    moved by the step), and 10 m episodes at t1 0.48 / 0.50 s save 20 % / 30 %: score = 0.05 - 0.30 + 0.1 x mean."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    seen = _fake_band_walks(monkeypatch, 0.44, 0.05)
    config = EpisodeConfig().replace(cpg=PAPER_CPG)
    value, detail = gait_search.OBJECTIVES["hold-edge"].score(config, base, (), 0)
    assert sorted({t1 for t1, _ in seen}) == [0.40, 0.42, 0.44] and len(seen) == 12
    assert sum(half for _, half in seen) == 3  # each window once at half the step
    assert detail["least_saving"] == pytest.approx(0.05) and detail["lure_saving"] == pytest.approx(0.30)
    mean = (11 * 0.40 + 0.05) / 12
    assert value == pytest.approx(0.05 - 0.30 + 0.1 * mean)  # Table III's CPG: no distance term


def test_hold_pull_adds_the_start_policys_mean_gain_to_hold_edge(monkeypatch):
    """Fake walks: hold-edge scores 0.2; of four start draws one falls (gain -1), one saves 50 % (reward x 2), two
    are no window (gain 0): score = 0.2 + (-1 + 1 + 0 + 0) / 4."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    monkeypatch.setattr(gait_search, "_hold_edge_score",
                        lambda config, b: (0.2, {"lure_saving": 0.1, "least_saving": 0.35}))
    rows = [{"reward": 0.0}, {"reward": 4.0}, {"reward": 2.0}, {"reward": 2.0}]
    monkeypatch.setattr(gait_search, "_window_rows", lambda config, windows, b: rows[:len(windows)])
    value, detail = gait_search.OBJECTIVES["hold-pull"].score(EpisodeConfig(), base, (), 4)
    assert detail["start_gain"] == pytest.approx(0.0)
    assert value == pytest.approx(0.2)
    rows[0] = {"reward": 2.0}  # the faller walks as no window would: the start's mean gain is 1 / 4
    value, detail = gait_search.OBJECTIVES["hold-pull"].score(EpisodeConfig(), base, (), 4)
    assert value == pytest.approx(0.2 + 0.25) and detail["least_saving"] == pytest.approx(0.35)


def test_hold_lure_rewards_the_10m_saving_past_the_band_and_holds_the_band_to_046(monkeypatch):
    """Fake walks: windows t1 0.40-0.46 s save 40 % long-run under every change except t1 0.46 s at half the plant
    step (30 %); 10 m episodes at t1 0.48 / 0.50 s save 20 % / 30 %: score = 0.30 + 0.5 x 0.30 + 0.1 x mean."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    seen = _fake_band_walks(monkeypatch, 0.46, 0.30)
    config = EpisodeConfig().replace(cpg=PAPER_CPG)
    value, detail = gait_search.OBJECTIVES["hold-lure"].score(config, base, (), 0)
    assert sorted({t1 for t1, _ in seen}) == [0.40, 0.42, 0.44, 0.46] and len(seen) == 16
    assert detail["least_saving"] == pytest.approx(0.30) and detail["lure_saving"] == pytest.approx(0.30)
    mean = (15 * 0.40 + 0.30) / 16
    assert value == pytest.approx(0.30 + gait_search.HOLD_LURE_WEIGHT * 0.30 + 0.1 * mean)


def test_hold_sure_takes_off_early_window_falls_steady_push_falls_and_the_quarter_steps_drift(monkeypatch):
    """Fake walks: "hold-lure" scores 0.5; of the early windows only (0, 0.6) falls; steps last 0.5 s, and without
    a window the forward push falls at the last two of six phases of the first step after 5 s, every other push
    walks; at a quarter of the plant step the walk without a window costs 3 % more: score = 0.5 - 1 x 1/6 -
    2 x 2/24 - 10 x (0.03 - 0.01)."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    long_bases = {"as_is": {"walked": True, "cost_of_transport": 0.4}}
    monkeypatch.setattr(gait_search, "_hold_lure_score",
                        lambda config, b: (0.5, {"lure_saving": 0.3, "long_bases": long_bases}))
    quarters = []

    def long_walk(config):
        quarters.append((config.sim.time_step_s, config.window.end_s))
        return {"walked": True, "cost_of_transport": 0.4 * 1.03}

    monkeypatch.setattr(gait_search, "_long_walk", long_walk)
    monkeypatch.setattr(gait_search, "_touchdowns", lambda config: (True, [0.5 * k for k in range(1, 30)]))
    pushed = []

    def walk(config):
        window = (config.window.start_s, config.window.end_s)
        if config.push is None:
            return {"walked": window != (0.0, 0.6), "cost_of_transport": 0.3, "distance_m": 10.0}
        assert config.sim.distance_m == gait_search.SURE_PUSH_M
        phase = round((config.push.start_s - 5.0) / 0.5 * gait_search.SURE_PUSH_PHASES)
        pushed.append((window, config.push.force_n, phase))
        falls = window == (0.0, 0.0) and config.push.force_n > 0 and phase >= 4
        return {"walked": not falls, "cost_of_transport": 0.3, "distance_m": 12.0}

    monkeypatch.setattr(gait_search, "_walk", walk)
    value, detail = gait_search.OBJECTIVES["hold-sure"].score(EpisodeConfig(), base, (), 0)
    assert len(pushed) == 24 and {p for _, _, p in pushed} == set(range(6))
    assert {f for _, f, _ in pushed} == {gait_search.PUSH_FORCE_N, -gait_search.PUSH_FORCE_N}
    assert detail["early_falls"] == pytest.approx(1 / 6) and detail["push_falls"] == pytest.approx(2 / 24)
    assert quarters == [(0.25 * EpisodeConfig().sim.time_step_s, 0.0)]  # no window, a quarter of the step
    assert detail["quarter_step_change"] == pytest.approx(0.03)
    drift = gait_search.SURE_STEP_PENALTY * (0.03 - gait_search.SURE_STEP_TOLERANCE)
    assert value == pytest.approx(0.5 - gait_search.SURE_FALL_PENALTY / 6 - gait_search.SURE_PUSH_PENALTY * 2 / 24
                                  - drift)
    monkeypatch.setattr(gait_search, "_touchdowns", lambda config: (False, [0.5, 1.0]))  # falls unpushed
    value, detail = gait_search.OBJECTIVES["hold-sure"].score(EpisodeConfig(), base, (), 0)
    assert detail["push_falls"] == 1.0 and value == pytest.approx(0.5 - 1 / 6 - gait_search.SURE_PUSH_PENALTY - drift)


def test_hold_fine_judges_the_walk_without_a_window_on_the_time_step_studys_ladder(monkeypatch):
    """Fake walks: "hold-lure" scores 0.5, every early window and push walks; without a window the long-run C_mt
    is 0.40 at the plant step, 0.388 at half of it (-3 % from the finest), 0.402 at a quarter and 0.40 at an
    eighth: score = 0.5 - 10 x (0.03 - 0.01). When the eighth-step walk falls, the check costs 1."""
    base = {"walked": True, "cost_of_transport": 0.5, "distance_m": 10.0, "reward": 2.0}
    monkeypatch.setattr(gait_search, "_hold_lure_score",
                        lambda config, b: (0.5, {"lure_saving": 0.3, "long_bases": {}}))
    monkeypatch.setattr(gait_search, "_touchdowns", lambda config: (True, [0.5 * k for k in range(1, 30)]))
    monkeypatch.setattr(gait_search, "_walk", lambda config: {"walked": True, "cost_of_transport": 0.3,
                                                              "distance_m": 10.0})
    step = EpisodeConfig().sim.time_step_s
    cost = {1.0: 0.40, 0.5: 0.388, 0.25: 0.402, 0.125: 0.40}
    ladder = []

    def long_walk(config, distance_m):
        fraction = round(config.sim.time_step_s / step, 4)
        ladder.append((fraction, config.sim.update_period_s, config.window.end_s, distance_m))
        return {"walked": fraction in cost, "cost_of_transport": cost.get(fraction)}

    monkeypatch.setattr(gait_search, "_long_walk", long_walk)
    value, detail = gait_search.OBJECTIVES["hold-fine"].score(EpisodeConfig(), base, (), 0)
    # the paper's clock: each rung refines the controller with the plant
    assert ladder == [(f, f * step, 0.0, gait_search.FINE_STEP_M) for f in gait_search.FINE_STEP_FRACTIONS]
    assert detail["step_ladder_changes"] == pytest.approx([0.0, -0.03, 0.005])
    assert value == pytest.approx(0.5 - gait_search.SURE_STEP_PENALTY * (0.03 - gait_search.SURE_STEP_TOLERANCE))
    del cost[0.125]
    value, detail = gait_search.OBJECTIVES["hold-fine"].score(EpisodeConfig(), base, (), 0)
    assert detail["step_ladder_changes"] is None and value == pytest.approx(0.5 - 1.0)


@pytest.mark.parametrize("method", ["es", "cmaes"])
def test_a_search_stops_once_the_objective_maximum_is_reached(tmp_path, client, method):
    # "walk" scores every walker 0, its maximum: a start that walks leaves nothing to search for.
    start = EpisodeConfig(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
    settings = GaitSearchSettings(start, generations=5, offspring=4, sigma=0.3, seed=2, distance_m=0.3,
                                  objective="walk")
    search = gait_search.run_cmaes if method == "cmaes" else run
    result = search(settings, tmp_path, client, progress=False)
    assert gait_search.OBJECTIVES["walk"].maximum == result["score"] == 0.0
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
        GaitSearchSettings(mutations="paper_motor")
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
    0.75 % -(1 + 0.5 + 0.5) / 3."""
    import types

    from drake_biped import episode

    def recorded(changes_per_s):
        t = np.arange(0.0, 10.0, 1e-3)
        act = np.zeros((len(t), 6))
        act[:, 0] = np.where(np.sin(np.pi * changes_per_s * t + 0.1) >= 0.0, 1.0, -1.0)  # the left hip swings
        return types.SimpleNamespace(fell=False, duration_s=10.0, trajectory={
            "time": t, "actuation": act, "stance_right": np.ones(len(t)),
            "actuator_names": np.array([f"{leg}_{j}_motor" for leg in ("left", "right") for j in ("hip", "knee", "ankle")])})

    config = EpisodeConfig(sim=SimulationParams(distance_m=100.0))
    for robust, spread, changes, moved, expected in ((0.0, 5e-4, 10.0, 0.002, 0.0),
                                                     (0.0, 2e-3, 30.0, -0.0075, -2.0 / 3.0),
                                                     (-0.3, 5e-4, 10.0, 0.002, -2.3)):
        base = {"walked": True, "cost_of_transport": 0.2, "distance_m": 100.0, "reward": 5.0,
                "step_period_std_s": spread}
        monkeypatch.setattr(gait_search, "_walk", lambda c, base=base: base)
        monkeypatch.setattr(gait_search, "_robust_score",
                            lambda c, b, r=robust, m=moved: (r, {"checks": {}, "half_step_cmt_change": m}))
        monkeypatch.setattr(episode, "run_episode", lambda c, record_trajectory=False, n=changes: recorded(n))
        value, detail = gait_search.score(config, objective="converged")
        assert value == pytest.approx(expected, abs=0.01), (robust, spread, changes, moved, detail)
    assert gait_search.OBJECTIVES["converged"].maximum == 0.0
