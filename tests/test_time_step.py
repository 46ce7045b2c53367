"""The time-step study's rule for choosing the default step, on results whose answer is known."""

import pytest
from walkers import fast_config

from drake_biped.analysis import time_step_report
from drake_biped.cli import main
from drake_biped.experiments.time_step import choose_step

STEPS = [0.00025, 0.0005, 0.001, 0.002, 0.005]


def _rows(table):
    """table: {window: {step: C_mt or None for a fall}}"""
    rows = []
    for window, by_step in table.items():
        for h, cmt in by_step.items():
            rows.append({"time_step_s": h, "window": window, "walked": cmt is not None, "cost_of_transport": cmt})
    return rows


def test_largest_passing_step_above_the_reference_is_chosen():
    rows = _rows({
        None: {0.00025: 1.00, 0.0005: 1.00, 0.001: 1.015, 0.002: 1.01, 0.005: None},
        (0.2, 0.5): {0.00025: 0.70, 0.0005: 0.70, 0.001: 0.713, 0.002: 0.75, 0.005: None},
    })
    out = choose_step(rows, STEPS, 0.0005, 0.02)
    assert out["chosen_step_s"] == 0.001  # 2 ms moves the window's C_mt by +7 %
    assert out["passing_steps"] == [0.00025, 0.0005, 0.001]
    dev = {(r["time_step_s"], r["window"]): r["cmt_deviation"] for r in rows}
    assert dev[(0.001, (0.2, 0.5))] == pytest.approx(0.013 / 0.70)
    assert dev[(0.005, None)] is None


def test_a_walk_that_falls_at_the_reference_is_not_judged_but_a_fall_elsewhere_fails_the_step():
    rows = _rows({
        None: {0.00025: 1.0, 0.0005: 1.0, 0.001: 1.0, 0.002: None, 0.005: None},
        (0.2, 0.7): {0.00025: None, 0.0005: None, 0.001: 0.8, 0.002: None, 0.005: None},
    })
    out = choose_step(rows, STEPS, 0.0005, 0.02)
    assert out["not_judged"] == [[0.2, 0.7]]
    assert out["chosen_step_s"] == 0.001  # the no-window walk falls at 2 ms


def test_a_failing_step_stops_the_choice_even_if_a_coarser_one_passes():
    rows = _rows({None: {0.00025: 1.0, 0.0005: 1.0, 0.001: 1.05, 0.002: 1.0, 0.005: 1.0}})
    assert choose_step(rows, STEPS, 0.0005, 0.02)["chosen_step_s"] == 0.0005


def test_reference_outside_the_steps_is_refused(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["time-step-study", "--out", str(tmp_path), "--steps", "0.001,0.002", "--reference", "0.0005"])
    assert exc.value.code == 2
    assert "--reference" in capsys.readouterr().err


def test_a_named_gait_and_its_windows_are_what_every_step_walks(monkeypatch):
    """The study walks the given gait (its CPG and gains kept, its time step replaced) with no window and
    each given window, and its tables list those windows."""
    from drake_biped.common import executor
    from drake_biped.experiments import time_step
    from drake_biped.resources import load_gait

    gait = load_gait("paper")
    seen = []

    def fake_map(client, fn, items, progress=None):
        seen.extend(items)
        def steps(cmt):  # 100 steps of 0.4 s and 0.3 m from 10 m on, each costing cmt
            return [{"touchdown_time_s": 0.4 * k, "com_x_m": 0.3 * k,
                     "positive_work_j": cmt * 10.0 * 9.81 * 0.3 * k} for k in range(140)]

        return [{"fell": False, "distance_m": 10.0, "termination": "distance", "mass_kg": 10.0,
                 "cost_of_transport": 0.6, "steps": steps(0.5 - c["window"]["end_s"] / 10),
                 "mean_speed_mps": 1.0, "step_period_s": 0.4, "real_time_factor": 5.0} for c in items]

    monkeypatch.setattr(executor, "map_ordered", fake_map)
    rec = time_step.study([0.0005, 0.001], 0.0005, 10.0, None, progress=False, config=gait,
                          windows=[(0.3, 0.7), (0.5, 1.0)])
    assert len(seen) == 6
    assert {c["cpg"]["u_r"] for c in seen} == {gait.cpg.u_r}
    assert {c["gait"]["torso_pitch_rad"] for c in seen} == {gait.gait.torso_pitch_rad}
    # the paper's clock: the controller refined with the plant, and each record says so
    assert sorted({(c["sim"]["time_step_s"], c["sim"]["update_period_s"], c["sim"]["controller_clock"])
                   for c in seen}) == [(0.0005, 0.0005, "plant step"), (0.001, 0.001, "plant step")]
    assert {(c["window"]["start_s"], c["window"]["end_s"]) for c in seen} == {(0.0, 0.0), (0.3, 0.7), (0.5, 1.0)}
    assert rec["walks"] == [None, [0.3, 0.7], [0.5, 1.0]] and rec["chosen_step_s"] == 0.001
    rec.update(gait="Gait coasting_wide", versions={"git_commit": "x", "drake": "y"}, date="d")
    table = time_step_report.markdown(rec)
    assert "Gait coasting_wide" in table and "| window 0.5–1 s |" in table and "0.2–0.5" not in table


def test_a_fixed_rate_loop_is_refined_over_the_plant_step_alone(monkeypatch, tmp_path, capsys):
    """A robot's 1 kHz loop stays 1 kHz at every plant step of the study; a step that does not divide it is
    refused before any walk, and the default steps are those that divide it."""
    from drake_biped.common import executor
    from drake_biped.experiments import time_step

    seen = []

    def fake_map(client, fn, items, on_result=None):
        seen.extend(items)
        return [{"fell": False, "distance_m": 10.0, "termination": "distance", "mass_kg": 10.0,
                 "cost_of_transport": 0.6, "steps": [], "mean_speed_mps": 1.0, "step_period_s": 0.4,
                 "real_time_factor": 5.0} for _ in items]

    monkeypatch.setattr(executor, "map_ordered", fake_map)
    fixed = fast_config().override({"sim.control_period_s": 1e-3})
    time_step.study([0.00025, 0.0005, 0.001], 0.00025, 10.0, None, progress=False, config=fixed, windows=[])
    assert sorted({(c["sim"]["time_step_s"], c["sim"]["update_period_s"], c["sim"]["controller_clock"])
                   for c in seen}) == [(0.00025, 0.001, "fixed rate"), (0.0005, 0.001, "fixed rate"),
                                       (0.001, 0.001, "fixed rate")]
    with pytest.raises(SystemExit) as exc:
        main(["time-step-study", "--out", str(tmp_path / "x"), "--control-period", "0.001",
              "--steps", "0.002,0.001"])
    assert exc.value.code == 2 and "--steps 0.002" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
    from drake_biped.cli import build_parser

    args = build_parser().parse_args(["time-step-study", "--out", str(tmp_path / "y"), "--control-period", "0.001"])
    assert time_step.settings_from_args(args).steps == (0.001, 0.0005, 0.00025, 0.000125)


def test_walks_too_short_for_a_long_run_mean_compare_the_whole_walk_and_say_so(monkeypatch, tmp_path, capsys):
    """A study of 3 m walks is refused unless told to compare the whole walks' C_mt (--measure episode); then its
    report says that is what it compared, and gives no Richardson estimate of two steps."""
    from drake_biped.common import executor
    from drake_biped.experiments import time_step

    with pytest.raises(SystemExit) as exc:
        main(["time-step-study", "--steps", "0.002,0.001", "--distance", "3", "--out", str(tmp_path / "x")])
    assert exc.value.code == 2 and "--measure episode" in capsys.readouterr().err

    def fake_map(client, fn, items, on_result=None):
        return [{"fell": False, "distance_m": 3.0, "termination": "distance", "mass_kg": 10.0,
                 "cost_of_transport": 0.6 + c["sim"]["time_step_s"], "steps": [], "mean_speed_mps": 1.0,
                 "step_period_s": 0.4, "real_time_factor": 5.0} for c in items]

    monkeypatch.setattr(executor, "map_ordered", fake_map)
    rec = time_step.study([0.001, 0.002], 0.001, 3.0, None, progress=False, windows=[], measure="episode")
    rec.update(versions={"git_commit": "x", "drake": "y"}, date="d")
    text = time_step_report.markdown(rec)
    assert "C_mt is the whole walk's" in text and "the long-run mean after" not in text
    assert "0.6010 (0.0 %)" in text and "0.6020 (+0.2 %)" in text
    assert "Not computed: it needs three finest steps that halve" in text


def test_a_study_compares_the_walked_gaits_own_window_and_names_the_gait(tmp_path, capsys, monkeypatch):
    """Without --windows, `--params NAME` compares that gait's own window (its file's), printed with the gait;
    without --params, the paper walker's two (WALKS). A record written before the walks were recorded is read
    with the walks it walked then (none, 0.3672-0.8629 s and 0.3-0.6 s)."""
    import json

    from drake_biped.cli import build_parser
    from drake_biped.experiments import time_step
    from drake_biped.resources import gait_compare_window

    def settings(*argv):
        return time_step.settings_from_args(build_parser().parse_args(["time-step-study", *argv, "--out",
                                                                        str(tmp_path / "t")]))

    fast = settings("--params", "fast_servo")
    gait, window = capsys.readouterr().out.splitlines()
    assert gait.startswith("gait: fast_servo (sha256 ") and window.startswith("window 0.3672-0.8629 s:")
    assert fast.windows == (gait_compare_window("fast_servo")[0],)
    assert settings().windows is None and time_step.WALKS == [None, (0.1, 0.2), (0.5, 0.6)]
    assert capsys.readouterr().out.startswith("gait: paper (sha256 ")
    # a record from before the walks were recorded: its report is drawn with the walks it walked
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / "time_step_study.json").write_text(json.dumps({"steps": [], "rows": [], "reference_s": 1e-3}))
    drawn = []
    monkeypatch.setattr(time_step, "markdown", lambda rec: drawn.append(rec["walks"]) or "")
    monkeypatch.setattr(time_step, "figure", lambda rec, path: None)
    time_step.replot(tmp_path / "old")
    assert drawn == [[None, (0.3672, 0.8629), (0.3, 0.6)]]
