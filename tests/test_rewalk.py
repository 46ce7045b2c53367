"""Learned windows re-walked with the plant step halved and from a nudged start: each saving against no window
under the same change, falls counted and never averaged, and the command repeating a run's own re-walks."""

import json

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.analysis.rewalks import CHANGES, HOLD_SAVING, headline, markdown, summary
from drake_biped.common.walks import changed, rewalk
from drake_biped.params import ParameterError, SimulationParams


def _row(cmt, fell=False):
    return {"cost_of_transport": cmt, "distance_m": 10.0, "fell": fell, "mean_speed_mps": 0.5,
            "step_period_s": 0.8}


def test_a_saving_is_judged_against_no_window_under_the_same_change():
    """No window costs 0.2, 0.25, 0.2, 0.1 under the four walks. Trial 0 costs half of each: saves 50 %
    everywhere and holds. Trial 1 saves 50 % as learned but falls at half the step: it has three savings, one
    fall, and does not hold. Trial 2 saves 30 % under one change: below HOLD_SAVING, it does not hold."""
    base = dict(zip(CHANGES, (0.2, 0.25, 0.2, 0.1)))
    rows = {c: {"no_window": _row(base[c]), 0: _row(0.5 * base[c]),
                1: _row(0.5 * base[c], fell=c == "half_step"),
                2: _row((0.7 if c == "speed_1.05" else 0.5) * base[c])} for c in CHANGES}
    learned = [{"trial": k, "t1": 0.1, "t2": 0.5} for k in range(3)]
    record = summary(0.001, 0.175, learned, rows)
    t0, t1, t2 = record["trials"]
    assert t0["savings"] == pytest.approx(dict.fromkeys(CHANGES, 0.5)) and t0["holds"]
    assert t1["savings"]["half_step"] is None and t1["falls"] == 1 and not t1["holds"]
    assert t1["mean_saving"] == pytest.approx(0.5) and t1["least_saving"] is None
    assert t2["savings"]["speed_1.05"] == pytest.approx(0.3) and 0.3 < HOLD_SAVING and not t2["holds"]
    assert t2["mean_saving"] == pytest.approx((3 * 0.5 + 0.3) / 4) and t2["least_saving"] == pytest.approx(0.3)
    means = [0.5, 0.5, (3 * 0.5 + 0.3) / 4]
    assert record["mean_saving"] == pytest.approx(np.mean(means))
    assert record["std_saving"] == pytest.approx(np.std(means))
    assert record["holding"] == 1
    assert "1 of 3 trials save ≥ 35 % in every walk" in headline(record)
    table = markdown(record)
    assert "| 1 | 0.100–0.500 s | -50.0 % | falls | -50.0 % | -50.0 % | -50.0 % | no |" in table
    assert "| no window | — | C_mt 0.2000 | C_mt 0.2500 | C_mt 0.2000 | C_mt 0.1000 | | |" in table


def test_a_window_that_never_opens_is_not_a_learned_window():
    """A final mean (1.85, 1.99) s on a 0.9 s step has t2 > t1 but never frees the hip: its walk is the one
    without a window to the last digit. It is not the learned window; a mean that changed the walk is, and the
    re-walk table says which is which."""
    from drake_biped.analysis.rewalks import window_acted
    from drake_biped.common.learning_record import best_learned_trial

    plain = {**_row(0.2135), "step_period_s": 0.898}
    late = {**plain, "trial": 0, "t1": 1.85, "t2": 1.99}
    acting = {**_row(0.2001), "trial": 1, "t1": 0.1, "t2": 0.2}
    none = {**plain, "trial": 2, "t1": 0.6, "t2": 0.04}
    assert not window_acted(late, plain) and window_acted(acting, plain) and not window_acted(none, plain)
    assert window_acted(late, None)  # nothing to compare with: t2 > t1 decides
    record = {"evaluation": {"no_window": plain, "learned": [late, acting, none]}}
    assert best_learned_trial(record)["trial"] == 1
    record["evaluation"]["learned"] = [late, none]
    with pytest.raises(ParameterError, match="never frees the hip"):
        best_learned_trial(record)
    rows = {c: {"no_window": plain, 0: plain, 1: _row(0.2001)} for c in CHANGES}
    table = markdown(summary(0.0005, 0.175, [late, acting], rows))
    assert "| 0 | 1.850–1.990 s (never opens: the walk is the one without a window) |" in table
    assert "| 1 | 0.100–0.200 s | " in table


def test_no_saving_where_the_walk_without_a_window_falls():
    rows = {c: {"no_window": _row(0.2, fell=c == "speed_0.95"), 0: _row(0.1)} for c in CHANGES}
    record = summary(0.001, 0.175, [{"trial": 0, "t1": 0.1, "t2": 0.5}], rows)
    assert record["trials"][0]["savings"]["speed_0.95"] is None and not record["trials"][0]["holds"]


def test_the_changes_halve_the_plant_step_and_scale_the_initiation_speed():
    config = fast_config()
    half = changed(config, "half_step")
    assert half.sim.time_step_s == 0.5 * config.sim.time_step_s
    assert half.sim.update_period_s == half.sim.time_step_s  # the paper's clock: the controller refined with it
    fixed = config.override({"sim.control_period_s": 1e-3})  # a robot's 1 kHz loop is kept
    assert changed(fixed, "half_step").sim.update_period_s == 1e-3
    assert changed(config, "speed_0.95").initial.speed_mps == pytest.approx(0.95 * config.initial.speed_mps)
    assert changed(config, "speed_1.05").initial.speed_mps == pytest.approx(1.05 * config.initial.speed_mps)
    assert changed(config, "as_learned") == config
    with pytest.raises(ParameterError, match="not one of"):
        changed(config, "speed_2")


def test_the_rewalk_command_repeats_a_learning_runs_own_rewalks(tmp_path, client):
    """A learning run re-walks its final policy means; `drake-biped rewalk --policy` on its record gets the
    same numbers, the walks as learned are Table V's, and halving the step changes the walk."""
    from drake_biped.cli import main
    from drake_biped.common import learning_runs as learning

    config = fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0))
    settings = learning.LearningSettings(config, trials=1, episodes=2, mean=(0.1, 0.4), variance=1e-6)
    record = learning.run(settings, tmp_path / "learn", client, progress=False, rewalk_distance_m=0.6)
    rewalks = record["evaluation"]["rewalks"]
    (trial,) = rewalks["trials"]
    assert trial["t2"] > trial["t1"] > 0.0  # a window, walked under every change
    assert trial["walks"]["as_learned"]["cost_of_transport"] == record["evaluation"]["learned"][0]["cost_of_transport"]
    assert {**rewalks["no_window"]["as_learned"], "episode_cost_of_transport":
            rewalks["no_window"]["as_learned"]["cost_of_transport"]} == record["evaluation"]["no_window"]
    assert rewalks["no_window"]["half_step"]["cost_of_transport"] != rewalks["no_window"]["as_learned"]["cost_of_transport"]
    assert "## The learned windows re-walked" in (tmp_path / "learn" / "table_v.md").read_text()
    assert len(list((tmp_path / "learn" / "rewalks").glob("*.json"))) == 8  # 4 changes x (no window, trial 0)
    assert main(["rewalk", "--policy", str(tmp_path / "learn" / "learning.json"), "--workers", "1",
                 "--out", str(tmp_path / "rw")]) == 0
    again = json.loads((tmp_path / "rw" / "rewalk.json").read_text())
    assert {k: again[k] for k in rewalks} == json.loads(json.dumps(rewalks))


def test_an_interrupted_rewalk_resumes_from_the_walks_it_kept(tmp_path, client):
    """Each walk is kept as it finishes: a rerun reads a kept walk back (a marked one shows its mark), walks
    again only what is missing, and gives the first record where nothing was changed."""
    config = fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0))
    learned = [{"trial": 0, "t1": 0.1, "t2": 0.4}]
    first = rewalk(config, learned, client, distance_m=0.6, keep=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"{c}-{k}.json" for c in CHANGES
                                                                for k in ("no_window", 0))
    assert json.dumps(rewalk(config, learned, client, distance_m=0.6, keep=tmp_path)) == json.dumps(first)
    marked = tmp_path / "half_step-0.json"
    kept = json.loads(marked.read_text())
    marked.write_text(json.dumps({**kept, "cost_of_transport": 123.0}))
    (tmp_path / "speed_0.95-no_window.json").unlink()  # interrupted before this walk finished
    again = rewalk(config, learned, client, distance_m=0.6, keep=tmp_path)
    assert again["trials"][0]["walks"]["half_step"]["cost_of_transport"] == 123.0
    assert again["no_window"]["speed_0.95"] == first["no_window"]["speed_0.95"]
    assert (tmp_path / "speed_0.95-no_window.json").exists()


def test_rewalk_refuses_a_file_that_is_not_a_learning_record(tmp_path, capsys):
    from drake_biped.cli import main

    path = tmp_path / "walk.json"
    path.write_text(json.dumps({"config": {}}))
    with pytest.raises(SystemExit) as exit_:
        main(["rewalk", "--policy", str(path), "--workers", "1", "--out", str(tmp_path / "rw")])
    assert exit_.value.code == 2
    assert f"--policy {path}: not a learning record" in capsys.readouterr().err
    assert not (tmp_path / "rw").exists()


def test_table_vs_verdict_is_judged_on_the_rewalked_saving():
    """As learned the windows save 48 %; re-walked, 20 %: the verdict is the re-walked one (partly), and a
    record without re-walks says it judged one walk each."""
    from drake_biped.analysis.report_text import NOT_REPRODUCED, PARTLY, REPRODUCED
    from drake_biped.analysis.verdicts import reduction_verdict

    evaluation = {"reduction": 0.48, "learned_walks": 5,
                  "learned": [{"t1": 0.1, "t2": 0.5, "fell": False} for _ in range(5)]}
    ours, verdict = reduction_verdict(evaluation)
    assert verdict == REPRODUCED and "one walk each, not re-walked" in ours
    evaluation["rewalks"] = {"mean_saving": 0.2, "std_saving": 0.1, "holding": 1, "hold_saving": HOLD_SAVING}
    ours, verdict = reduction_verdict(evaluation)
    assert verdict.startswith(PARTLY) and "C_mt -20.0 % re-walked" in ours and "as learned -48.0 %" in ours
    assert "1 of 5 trials save ≥ 35 %" in ours
    evaluation["rewalks"]["mean_saving"] = None
    assert reduction_verdict(evaluation)[1] == NOT_REPRODUCED
