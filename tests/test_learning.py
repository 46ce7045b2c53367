"""The learning run: its reward rule, its records, and a run interrupted and resumed."""

import json
import math

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.cli import main
from drake_biped.common.executor import dask_client
from drake_biped.common.learning_runs import Trial, make_settings, reward, run_learning, trial_seed
from drake_biped.common.walks import window_of
from drake_biped.params import EpisodeConfig, ParameterError, SimulationParams


def test_reward_is_inverse_cost_of_transport_scaled_by_the_distance_covered():
    assert reward(0.25, 10.0, 10.0) == pytest.approx(4.0)
    assert reward(0.25, 12.0, 10.0) == pytest.approx(4.0)  # overshoot of the last step: capped
    assert reward(0.25, 5.0, 10.0) == pytest.approx(2.0)  # a fall half-way
    # A fall after 0.3 m with little work has a small C_mt but must not out-earn a complete walk.
    assert reward(0.10, 0.3, 10.0) < reward(0.25, 10.0, 10.0)
    assert reward(None, 3.0, 10.0) == 0.0
    assert reward(0.2, 0.0, 10.0) == 0.0
    assert reward(0.2, -0.1, 10.0) == 0.0


def test_sampled_times_map_to_a_window():
    w = window_of(np.array([-0.1, 0.4]))
    assert (w.start_s, w.end_s) == (0.0, 0.4)
    assert not window_of(np.array([0.6, 0.3])).active  # t2 <= t1: no torque-free period


def test_trials_get_distinct_reproducible_seeds():
    assert trial_seed(0, 0) == trial_seed(0, 0)
    assert len({trial_seed(0, k) for k in range(5)} | {trial_seed(1, 0)}) == 6


def _settings(episodes=4, trials=2):
    config = fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0))
    return make_settings(config, trials, episodes, seed=3)


def _episodes(out):
    return [json.loads(p.read_text())["episodes"] for p in sorted((out / "trials").glob("trial_*.json"))]


def test_interrupted_run_resumes_to_the_uninterrupted_result(tmp_path):
    settings = _settings()
    with dask_client(workers=1) as client:
        whole, n_whole = run_learning(tmp_path / "whole", settings, client)
        _, n_first = run_learning(tmp_path / "cut", settings, client, stop_after=3)
        cut = _episodes(tmp_path / "cut")
        resumed, n_rest = run_learning(tmp_path / "cut", settings, client)
    assert n_whole == 8 and n_first == 3 and n_rest == 5
    assert sum(len(e) for e in cut) == 3
    assert _episodes(tmp_path / "cut") == _episodes(tmp_path / "whole")
    for a, b in zip(whole, resumed):
        assert a.learner.state() == b.learner.state()
    # The policy moved, and every episode's record holds what the figures need.
    first = _episodes(tmp_path / "whole")[0]
    assert [e["episode"] for e in first] == [1, 2, 3, 4]
    assert (first[-1]["mean_t1"], first[-1]["mean_t2"]) != (0.5, 0.5)
    assert {"t1", "t2", "reward", "cost_of_transport", "distance_m", "fell"} <= set(first[0])


class _CountingClient:
    """A client that keeps the configuration of every episode submitted to it."""

    def __init__(self, client):
        self.client, self.submitted = client, []

    def submit(self, fn, config, **options):
        self.submitted.append(config)
        return self.client.submit(fn, config, **options)


def test_draws_without_a_window_are_walked_once_and_give_each_trial_that_walks_result(tmp_path, client,
                                                                                   monkeypatch):
    """Every draw with t2 <= t1 walks the same episode: one walk serves them all, and the trials' records are
    those of walking every draw, to the byte."""
    from drake_biped.common import learning_runs as learning

    settings = _settings(episodes=6, trials=2)
    once = _CountingClient(client)
    run_learning(tmp_path / "once", settings, once)
    monkeypatch.setattr(learning, "episode_key", lambda config: None)
    every = _CountingClient(client)
    run_learning(tmp_path / "every", settings, every)
    for k in range(2):
        path = f"trials/trial_{k}.json"
        assert (tmp_path / "once" / path).read_bytes() == (tmp_path / "every" / path).read_bytes()
    draws = [e for trial in _episodes(tmp_path / "once") for e in trial]
    without = sum(not window_of((e["t1"], e["t2"])).active for e in draws)
    assert without >= 2  # the seed draws several: a check that can fail
    assert len(every.submitted) == 12 and len(once.submitted) == 12 - without + 1
    assert sum(not EpisodeConfig.from_dict(c).window.active for c in once.submitted) == 1


def test_a_shorter_run_is_replayed_from_a_longer_ones_records(tmp_path, client):
    """The records of a 1 x 3 run, replayed from a 1 x 5 run of the same settings, are the 1 x 3 run's own
    to the byte; other settings, or a record the learner cannot have drawn, give none."""
    from drake_biped.common.learning_runs import replay_run

    short, long_ = _settings(episodes=3, trials=1), _settings(episodes=5, trials=1)
    run_learning(tmp_path / "short", short, client)
    run_learning(tmp_path / "long", long_, client)
    assert replay_run(tmp_path / "long", tmp_path / "replayed", short)
    assert (tmp_path / "replayed" / "trials" / "trial_0.json").read_bytes() == \
        (tmp_path / "short" / "trials" / "trial_0.json").read_bytes()
    assert not replay_run(tmp_path / "long", tmp_path / "other", {**short, "seed": 4})
    assert not replay_run(tmp_path / "long", tmp_path / "more", _settings(episodes=6, trials=1))
    assert not (tmp_path / "other").exists() and not (tmp_path / "more").exists()
    forged = json.loads((tmp_path / "long" / "trials" / "trial_0.json").read_text())
    forged["episodes"][1]["t1"] += 0.01
    (tmp_path / "long" / "trials" / "trial_0.json").write_text(json.dumps(forged))
    with pytest.raises(ParameterError, match="episode 2: the learner draws"):
        replay_run(tmp_path / "long", tmp_path / "forged", short)


@pytest.mark.slow
@pytest.mark.parametrize("learner", ["cmaes", "pgpe"])
def test_every_learner_resumes_to_the_uninterrupted_result(tmp_path, learner):
    """Cut inside a CMA-ES generation (6 samples) and inside a PGPE pair: the same records as GARB's, and
    the resumed run ends identical to the uninterrupted one."""
    config = fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0))
    settings = make_settings(config, 1, 7, seed=3, learner=learner)
    with dask_client(workers=1) as client:
        whole, _ = run_learning(tmp_path / "whole", settings, client)
        run_learning(tmp_path / "cut", settings, client, stop_after=3)
        resumed, n_rest = run_learning(tmp_path / "cut", settings, client)
    assert n_rest == 4
    assert _episodes(tmp_path / "cut") == _episodes(tmp_path / "whole")
    assert whole[0].learner.state() == resumed[0].learner.state()
    rows = _episodes(tmp_path / "whole")[0]
    assert {"t1", "t2", "mean_t1", "mean_t2", "reward", "cost_of_transport", "distance_m", "fell"} <= set(rows[0])
    assert (rows[-1]["mean_t1"], rows[-1]["mean_t2"]) != (0.5, 0.5)  # a generation / pairs were told


def test_an_unknown_learner_is_refused_before_anything_runs():
    with pytest.raises(ParameterError, match="--learner 'sgd'"):
        make_settings(fast_config(), 1, 1, seed=0, learner="sgd")


def test_resuming_with_other_settings_is_refused(tmp_path):
    settings = _settings()
    (tmp_path / "trials").mkdir()
    trial = Trial(tmp_path, 0, settings)
    trial.next_config()
    trial.record({"cost_of_transport": 0.2, "distance_m": 0.6, "fell": False, "fall_reason": "",
                  "duration_s": 1.0, "steps": []})
    other = dict(settings, seed=4)
    with pytest.raises(ParameterError, match="other settings"):
        Trial(tmp_path, 0, other)


def test_figures_are_redrawn_from_the_records_alone(tmp_path):
    episodes = [{"episode": i + 1, "t1": 0.2, "t2": 0.5, "mean_t1": 0.5 - 0.001 * i, "mean_t2": 0.5,
                 "reward": 4.0 + 0.01 * i, "baseline": 4.0, "cost_of_transport": 0.25, "distance_m": 10.0,
                 "fell": i % 7 == 0, "fall_reason": "", "duration_s": 15.0, "steps": 18} for i in range(30)]
    record = {
        "settings": _settings(episodes=30),
        "trials": [{"trial": k, "episodes": episodes} for k in range(2)],
        "evaluation": {"no_window": {"cost_of_transport": 0.221, "fell": False},
                       "learned": [{"trial": 0, "t1": 0.15, "t2": 0.55, "cost_of_transport": 0.140, "fell": False},
                                   {"trial": 1, "t1": 0.20, "t2": 0.50, "cost_of_transport": 0.160, "fell": False}],
                       "learned_mean_cost_of_transport": 0.150, "learned_std_cost_of_transport": 0.010,
                       "learned_walks": 2, "reduction": 1 - 0.150 / 0.221},
    }
    (tmp_path / "learning.json").write_text(json.dumps(record))
    assert main(["figures", str(tmp_path)]) == 0
    for name in ("fig4_reward.png", "fig5_cmt.png", "fig6_times.png", "table_v.md"):
        assert (tmp_path / name).stat().st_size > 0
    table = (tmp_path / "table_v.md").read_text()
    assert "| paper | 1.60 | 0.58 | 0.29 | 0.05 |" in table
    assert "0.221" in table and "0.1500 ± 0.0100" in table and "C_mt change: paper -50 %, ours -32.1 %" in table


def test_figures_without_a_record_is_a_clear_error(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["figures", str(tmp_path)])
    assert "figures DIR: no such file" in capsys.readouterr().err


@pytest.mark.parametrize("argv, match", [
    (["--trials", "0"], "--trials"), (["--episodes", "x"], "--episodes"),
    (["--scheduler", "localhost"], "scheduler"), (["--initial-mean", "0.4"], "--initial-mean"),
    (["--initial-mean", "0.4", "-1"], "--initial-mean"), (["--variance", "0"], "--variance"), (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "workers"),
])
def test_learn_refuses_bad_options(tmp_path, capsys, argv, match):
    with pytest.raises(SystemExit):
        main(["learn", "--out", str(tmp_path), *argv])
    assert match in capsys.readouterr().err


def test_run_log_keeps_every_session_and_their_totals(tmp_path):
    from drake_biped.common.progress import SessionLog

    path = tmp_path / "run.json"
    first = SessionLog(path, workers=2, scheduler=None, every_s=0.0)
    first.update(5)  # a session that is then killed: its numbers are already on disk
    second = SessionLog(path, workers=1, scheduler=None)
    second.update(3, force=True)
    second.update(3, learning=False, finished=True)
    run = json.loads(path.read_text())
    assert [s["episodes"] for s in run["sessions"]] == [5, 3]
    assert [s["finished"] for s in run["sessions"]] == [False, True]
    assert [s["workers"] for s in run["sessions"]] == [2, 1]
    assert run["episodes"] == 8
    assert run["learning_wall_s"] == pytest.approx(sum(s["learning_wall_s"] for s in run["sessions"]))


@pytest.mark.slow
def test_compare_learners_puts_the_runs_beside_the_best_window(tmp_path, client):
    from drake_biped.experiments import compare_learners, window_map

    config = fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0))
    window_map.run(window_map.WindowMapSettings(config, t1_max_s=0.1, t2_max_s=0.3, t1_step_s=0.1, t2_step_s=0.1), tmp_path / "map", client,
                   progress=False)
    from drake_biped.common import learning_runs as learning

    longer = learning.run(learning.LearningSettings(config, trials=1, episodes=5), tmp_path / "learn", client,
                          progress=False)
    settings = compare_learners.CompareSettings(config, str(tmp_path / "map"), learners=("garb", "cmaes"),
                                                trials=1, episodes=3, reuse={"garb": str(tmp_path / "learn")})
    record = compare_learners.run(settings, tmp_path / "cmp", client, progress=False)
    assert set(record["learners"]) == {"garb", "cmaes"}
    # GARB's run is the longer run's first three episodes, replayed; CMA-ES has none to reuse and walks.
    assert record["learners"]["garb"]["replayed_from"] == str(tmp_path / "learn")
    assert record["learners"]["cmaes"]["replayed_from"] is None
    garb = json.loads((tmp_path / "cmp" / "garb" / "learning.json").read_text())
    assert garb["trials"][0]["episodes"] == longer["trials"][0]["episodes"][:3]
    for name, row in record["learners"].items():
        learned = json.loads((tmp_path / "cmp" / name / "learning.json").read_text())
        assert row["episodes"] == 3 and row["trials"] == 1
        mean = learned["trials"][0]["final_mean"]
        best = record["best_window"]
        assert row["mean_distance_to_best_s"] == pytest.approx(math.dist(mean, (best["t1"], best["t2"])))
    assert (tmp_path / "cmp" / "compare.png").stat().st_size > 10_000
    assert "| cmaes |" in (tmp_path / "cmp" / "compare.md").read_text()
    other = compare_learners.CompareSettings(config.override({"sim.distance_m": 0.7}), str(tmp_path / "map"))
    with pytest.raises(ParameterError, match="made for another gait"):
        other.read_map()


@pytest.mark.parametrize("content, named", [
    ("[" * 50_000 + "]" * 50_000, "nested too deeply"),
    (b"\xff\xfe", "not UTF-8 text"),
    ("{not json", "not valid JSON"),
])
def test_a_damaged_trial_record_is_named_with_what_to_do(tmp_path, content, named):
    """A trial record nested 50,000 deep raised a bare RecursionError, one not UTF-8 a UnicodeDecodeError
    without the remedy: each is one ParameterError naming the file, what is wrong and what to do."""
    (tmp_path / "trials").mkdir()
    path = tmp_path / "trials" / "trial_0.json"
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(ParameterError) as info:
        Trial(tmp_path, 0, _settings())
    message = str(info.value)
    assert str(path) in message and named in message and "delete it to run trial 0 again" in message
    assert path.read_bytes() == (content if isinstance(content, bytes) else content.encode())  # never overwritten


def test_each_learner_records_its_own_settings():
    garb = make_settings(fast_config(), 1, 1, seed=0)["learner"]
    assert set(garb) == {"mean", "variance", "beta", "schedule"}  # GARB's record, as it always was
    cmaes = make_settings(fast_config(), 1, 1, seed=0, learner="cmaes")["learner"]
    assert set(cmaes) == {"mean", "variance", "name", "options"}  # no GARB settings in another learner's
    with pytest.raises(ParameterError, match="beta and schedule are the settings of GARB's learning rate; "
                                             "learner 'pgpe' takes none"):
        make_settings(fast_config(), 1, 1, seed=0, learner="pgpe", beta=0.5)


def test_a_record_that_gave_another_learner_garbs_settings_still_resumes():
    from drake_biped.common.learning_runs import _fixed

    new = make_settings(fast_config(), 1, 1, seed=0, learner="cmaes")
    old = {**new, "learner": {**new["learner"], "beta": 0.8, "schedule": [[None, 0.01]]}}
    assert _fixed(old) == _fixed(new)
    garb = make_settings(fast_config(), 1, 1, seed=0)
    assert _fixed({**garb, "learner": {**garb["learner"], "beta": 0.5}}) != _fixed(garb)  # GARB's own count


def test_a_variance_wider_than_a_windows_declared_times_is_refused(tmp_path, capsys):
    """A standard deviation of 1000 s draws windows that no episode can walk: what it learns says nothing."""
    with pytest.raises(SystemExit) as stop:
        main(["learn", "--variance", "1e6", "--out", str(tmp_path / "l")])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--variance 1e+06" in err and "0-10 s" in err
    make_settings(fast_config(), 1, 1, 0, variance=100.0)  # a standard deviation of the whole span is taken


def test_one_trial_has_no_spread_to_print(tmp_path):
    """`learn --trials 1`: Table V and the re-walks say "(1 trial)", never "± 0" over one trial."""
    from drake_biped.analysis.figures import table_v
    from drake_biped.analysis.rewalks import headline

    record = {"settings": _settings(episodes=1, trials=1), "trials": [],
              "evaluation": {"no_window": {"cost_of_transport": 0.221, "fell": False},
                             "learned": [{"trial": 0, "t1": 0.15, "t2": 0.55, "cost_of_transport": 0.140,
                                          "fell": False}],
                             "learned_mean_cost_of_transport": 0.140, "learned_std_cost_of_transport": 0.0,
                             "learned_walks": 1, "reduction": 1 - 0.140 / 0.221}}
    table = table_v(record)
    assert "0.1400 (1 trial)" in table and "±" not in table
    one = {"trials": [{"mean_saving": 0.3}], "mean_saving": 0.3, "std_saving": 0.0, "changes": ["a", "b"],
           "holding": 1, "hold_saving": 0.35}
    assert "(1 trial," in headline(one) and "±" not in headline(one)
    two = {**one, "trials": [{"mean_saving": 0.3}, {"mean_saving": 0.4}], "std_saving": 0.05}
    assert "(± 5.0 %," in headline(two)


def test_figures_takes_the_learning_json_itself(tmp_path):
    episodes = [{"episode": 1, "t1": 0.2, "t2": 0.5, "mean_t1": 0.5, "mean_t2": 0.5, "reward": 4.0, "baseline": 4.0,
                 "cost_of_transport": 0.25, "distance_m": 10.0, "fell": False, "fall_reason": "", "duration_s": 15.0,
                 "steps": 18}]
    record = {"settings": _settings(episodes=1, trials=1), "trials": [{"trial": 0, "episodes": episodes}],
              "evaluation": {"no_window": {"cost_of_transport": 0.221, "fell": False}, "learned": [],
                             "learned_walks": 0}}
    (tmp_path / "learning.json").write_text(json.dumps(record))
    assert main(["figures", str(tmp_path / "learning.json")]) == 0
    assert (tmp_path / "table_v.md").stat().st_size > 0 and not (tmp_path / "learning.json" / "table_v.md").exists()
