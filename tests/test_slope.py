"""Slope adaptation: the learner restarted from a learned policy, the summaries, and the slope story on a
short setting (2 m level, then 2 m up 0.02 rad)."""

import json

import numpy as np
import pytest
from retired_gaits import STEADY

from drake_biped.cli import main
from drake_biped.experiments.slope import (
    moving_average,
    period,
    run_slope,
    slope_ground,
    start_from_learning,
    start_from_window,
    trial_summary,
)
from drake_biped.learners.garb import GarbLearner
from drake_biped.params import ParameterError, SimulationParams
from drake_biped.resources import load_gait


def test_a_restarted_learner_keeps_the_policy_and_starts_the_schedule_again():
    learner = GarbLearner((0.3, 0.6), 0.01, seed=1)
    for r in (4.0, 5.0, 3.0):
        learner.update(learner.sample(), r)
    new = learner.restarted(seed=5)
    np.testing.assert_array_equal(new.mean, learner.mean)
    np.testing.assert_array_equal(new.trace, learner.trace)
    assert (new.variance, new.beta, new.episodes) == (learner.variance, learner.beta, 0)
    # Episode 1 of the new run: the baseline becomes its reward, so the mean does not move.
    t = np.array([0.25, 0.55])
    new.update(t, 2.0)
    assert new.baseline == 2.0
    np.testing.assert_array_equal(new.mean, learner.mean)
    # Episode 2: alpha_p = 0.1 (Table II's first band), not the old run's rate.
    z = (t - learner.mean) + 0.8 * learner.trace
    t2 = np.array([0.2, 0.5])
    z = (t2 - new.mean) + 0.8 * z
    expected = new.mean + 0.1 * (3.0 - 2.5) * z
    new.update(t2, 3.0)
    np.testing.assert_allclose(new.mean, expected)


def test_period_and_moving_average():
    assert period(0.2, 0.5) == pytest.approx(0.3)
    assert period(0.5, 0.2) == 0.0  # t2 <= t1: no torque-free period
    assert period(-0.1, 0.2) == pytest.approx(0.2)  # times below 0 act as 0
    np.testing.assert_allclose(moving_average([1, 2, 3, 4], 2), [1, 1.5, 2.5, 3.5])
    np.testing.assert_allclose(moving_average(np.arange(30.0))[-1], np.arange(10.0, 30.0).mean())


def test_trial_summary_finds_when_the_average_reaches_the_distance():
    episodes = [{"t1": 0.1, "t2": 0.5, "mean_t1": 0.1, "mean_t2": 0.5, "distance_m": 2.0, "fell": True}] * 5
    episodes += [{"t1": 0.3, "t2": 0.2, "mean_t1": 0.3, "mean_t2": 0.25, "distance_m": 10.0, "fell": False}] * 25
    s = trial_summary(episodes, 10.0)
    assert s["first_full_average_episode"] == 25  # the first 20-episode window without the 5 falls
    assert s["period_first_s"] == pytest.approx((5 * 0.4 + 15 * 0.0) / 20)
    assert (s["period_last_s"], s["mean_period_end_s"], s["climb_share_last"]) == (0.0, 0.0, 1.0)
    assert s["distance_first_m"] == pytest.approx((5 * 2 + 15 * 10) / 20)


def _learning_dir(tmp_path):
    learned = [{"trial": 0, "t1": 0.5, "t2": 0.3, "cost_of_transport": 0.221, "fell": False},
               {"trial": 1, "t1": 0.14, "t2": 0.30, "cost_of_transport": 0.144, "fell": False}]
    (tmp_path / "trials").mkdir()
    path = tmp_path / "learning.json"
    path.write_text(json.dumps({"evaluation": {"learned": learned}}))
    learner = GarbLearner((0.14, 0.30), 0.01, seed=2)
    learner.update(np.array([0.1, 0.3]), 5.0)
    (tmp_path / "trials" / "trial_1.json").write_text(json.dumps({"learner": learner.state()}))
    return path, learner


def test_start_from_learning_takes_the_best_trials_learner_state(tmp_path):
    path, learner = _learning_dir(tmp_path)
    state, source = start_from_learning(path)
    assert state == json.loads(json.dumps(learner.state()))
    assert (source["trial"], source["level_episodes"]) == (1, 1)
    (tmp_path / "trials" / "trial_1.json").unlink()
    with pytest.raises(ParameterError, match="trial 1's learner state"):
        start_from_learning(path)


@pytest.mark.parametrize("argv, match", [
    (["slope", "--episodes", "2"], "required: --slope"),
    (["slope", "--slope", "-0.02"], "must be > 0"),
    (["slope", "--slope", "0.02", "--policy", "x.json", "--t1", "0.1", "--t2", "0.3"], "either --policy"),
    (["slope", "--slope", "0.02", "--policy", "none.json"], "no such file"),
    # a walk that ends on the level never meets the slope: no climb verdict can be made of it
    (["slope", "--slope", "0.02", "--level-length", "10", "--distance", "4"], "--distance 4 --level-length 10"),
])
def test_slope_refuses_bad_options(tmp_path, capsys, argv, match):
    with pytest.raises(SystemExit):
        main([*argv, "--out", str(tmp_path / "s")])
    assert match in capsys.readouterr().err


@pytest.mark.slow
def test_slope_story_on_a_short_setting(tmp_path):
    """2 m level, then 2 m up 0.02 rad. `steady` does not climb. The climbing gait found by the
    grid search climbs without a torque-free period and falls with the 0.2-0.4 s period that saves energy
    on level ground; a rerun recomputes nothing."""
    from drake_biped.common.executor import dask_client

    sim = SimulationParams(distance_m=4.0, max_time_s=20.0)
    climbing = load_gait("climbing").replace(sim=sim)
    ground = slope_ground(0.02, 2.0)
    state, source = start_from_window(0.2, 0.4, 1e-4)  # a tiny variance: samples stay at the period
    with dask_client(workers=2) as client:
        record = run_slope(tmp_path / "climbing", climbing, ground, state, source, 1, 2, 0, client)
        steady = run_slope(tmp_path / "steady", load_gait(STEADY).replace(sim=sim), ground, state, source, 1, 1, 0,
                           client)
        mtimes = {p: p.stat().st_mtime_ns for p in (tmp_path / "climbing").rglob("*.json")}
        again = run_slope(tmp_path / "climbing", climbing, ground, state, source, 1, 2, 0, client)
    checks = record["checks"]
    assert checks["no_window"]["climbs"] and checks["no_window"]["distance_m"] >= 4.0
    assert not checks["start_window"]["climbs"] and 2.0 < checks["start_window"]["distance_m"] < 4.0
    assert record["verdicts"]["learned_period_fails_to_climb"] and record["verdicts"]["no_period_climbs"]
    # ... in each of its four walks: as learned, at half the plant step, from 0.95 and 1.05 x the speed.
    assert record["rewalks"]["no_window"]["all_climb"] and record["rewalks"]["start_window"]["none_climbs"]
    assert (tmp_path / "climbing" / "checks" / "no_window.half_step.json").is_file()
    assert not steady["checks"]["no_window"]["climbs"]  # the gait climbing was searched from falls on the slope
    assert len(record["episodes"][0]["episodes"]) == 2
    assert again["checks"] == record["checks"] and again["trials"] == record["trials"]
    for p in ("checks/no_window.json", "checks/start_window.json", "trials/trial_0.json"):
        assert (tmp_path / "climbing" / p).stat().st_mtime_ns == mtimes[tmp_path / "climbing" / p]
    for name in ("fig8_period.png", "fig9_distance.png", "report.md"):
        assert (tmp_path / "climbing" / name).stat().st_size > 0
    assert "| the learned torque-free period fails to climb |" in (tmp_path / "climbing" / "report.md").read_text()


def test_moving_average_skips_missing_values():
    np.testing.assert_allclose(moving_average([np.nan, 1.0, np.nan, 3.0], 2), [np.nan, 1.0, 1.0, 3.0])


def test_a_run_shorter_than_the_moving_average_has_no_first_full_average():
    """With fewer episodes than the 20-episode average, no average is full: none is reported, and the table
    says why, not "episode 1"."""
    from drake_biped.experiments.slope import _first_full, trial_summary

    episodes = [{"distance_m": 10.0, "fell": False, "t1": 0.3, "t2": 0.6, "mean_t1": 0.3, "mean_t2": 0.6}] * 2
    s = trial_summary(episodes, 10.0)
    assert s["first_full_average_episode"] is None
    assert _first_full(None, 2) == "— (fewer than 20 episodes)"


def _walk(distance_m, fell, target_m=10.0, level_m=2.0):
    return {"distance_m": distance_m, "fell": fell, "fall_reason": "hip_low" if fell else "", "duration_s": 9.0,
            "cost_of_transport": None if fell else 0.3, "mean_speed_mps": 0.5,
            "config": {"sim": {"distance_m": target_m}, "ground": {"slope_rad": 0.02, "level_length_m": level_m}}}


def test_a_walk_that_never_reaches_the_slope_is_judged_neither_climbing_nor_failing_to():
    from drake_biped.analysis.rewalks import CHANGES
    from drake_biped.experiments.slope import _rewalks, climbs, report_markdown, verdicts

    assert not climbs(_walk(4.0, False, target_m=4.0, level_m=10.0))  # walked its distance, all of it level
    assert climbs(_walk(10.0, False))
    on_the_level = {c: _walk(1.5, True) for c in CHANGES}  # every walk of the window falls before the slope
    up = {c: _walk(10.0, False) for c in CHANGES}
    rewalks = {"start_window": _rewalks(on_the_level), "no_window": _rewalks(up)}
    assert rewalks["start_window"]["none_climbs"] and not rewalks["start_window"]["all_reached_slope"]
    v = verdicts(rewalks, [], start_period=0.5)
    assert not v["learned_period_fails_to_climb"] and v["no_period_climbs"]
    record = {"ground": {"slope_rad": 0.02, "level_length_m": 2.0}, "verdicts": v, "rewalks": rewalks, "trials": [],
              "start": {"mean": [0.2, 0.7], "period_s": 0.5, "variance": 0.04},
              "checks": {"start_window": rewalks["start_window"]["half_step"] | {"climbs": False,
                                                                                   "reached_slope": False},
                         "no_window": rewalks["no_window"]["half_step"]}}
    text = report_markdown(record)
    assert "falls on the level (never reached the slope) (hip_low): 1.50 m" in text
    assert "| the learned torque-free period fails to climb |" in text and "| no |" in text


def test_a_slope_run_that_ends_before_the_slope_is_refused_through_the_api():
    from drake_biped.experiments.slope import SlopeSettings

    config = load_gait("climbing").replace(sim=SimulationParams(distance_m=2.0, max_time_s=20.0))
    with pytest.raises(ParameterError, match="--distance 2 --level-length 2"):
        SlopeSettings(config, 0.02, 2.0)
    SlopeSettings(config, 0.02, 1.5)  # 0.5 m up: a climb can be judged
