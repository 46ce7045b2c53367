"""The bifurcation diagram: its points are the walks the API makes, labelled by the step-period rule, and a
rerun resumes from the kept walks."""

import json

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.common.walks import attractor_of_walk
from drake_biped.episode import run_episode
from drake_biped.experiments import bifurcation
from drake_biped.params import ParameterError
from tests.test_failures import one_line, run_cli


def _walk(periods, com_step=0.2, fell=False, distance=None):
    """An episode result dictionary whose touchdowns come `periods` apart, each step `com_step` long."""
    times = np.concatenate([[0.5], 0.5 + np.cumsum(periods)])
    steps = [{"touchdown_time_s": float(t), "com_x_m": com_step * k, "positive_work_j": 10.0 * k,
              "hip_angle_rad": 0.7 + 0.01 * k, "hip_rate_radps": 2.0} for k, t in enumerate(times)]
    walked = com_step * (len(times) - 1)
    return {"steps": steps, "fell": fell, "fall_reason": "hip_low" if fell else "", "mass_kg": 10.0,
            "distance_m": walked if distance is None else distance}


def test_the_transient_is_dropped_and_the_rest_labelled():
    periods = np.concatenate([np.full(20, 0.6), np.tile([0.41, 0.47], 30)])  # 4 m of transient, then period-2
    label = attractor_of_walk(_walk(periods), distance_m=1.0, transient_m=4.0)
    assert label["first_kept_step"] == 20
    assert label["step_periods_s"] == pytest.approx(periods[20:])
    assert label["attractor"] == "period-2" and label["period"] == 2
    # the long-run C_mt of the kept steps: 10 J per 0.2 m step, m g d = 10 * 9.81 * 0.2
    assert label["cost_of_transport"] == pytest.approx(10.0 / (10.0 * 9.81 * 0.2))
    short = attractor_of_walk(_walk(periods, distance=3.0), distance_m=5.0, transient_m=4.0)
    assert short["fell"] and short["attractor"] == "fell" and short["cost_of_transport"] is None


def test_points_are_the_api_walks_and_a_rerun_resumes(tmp_path, client):
    config = fast_config().override({"sim.distance_m": 9.0, "sim.max_time_s": 40.0, "window.end_s": 0.944})
    settings = bifurcation.BifurcationSettings(config, "t1", (0.46,), transient_m=3.0, lyapunov=False)
    record = bifurcation.run(settings, tmp_path, client, progress=False)
    (point,) = record["points"]
    walk = run_episode(bifurcation.point_config(settings, 0.46, 0.001))
    td = walk.touchdowns
    first = int(np.searchsorted(td["com_x_m"] - td["com_x_m"][0], 3.0))
    assert point["step_periods_s"] == pytest.approx(np.diff(td["touchdown_time_s"][first:]).tolist(), abs=0)
    assert point["cost_of_transport"] == pytest.approx(walk.long_run(transient_m=3.0)["cost_of_transport"])
    # period-1 exactly where the last 20 periods vary by less than 2 ms
    spread = np.ptp(point["step_periods_s"][-20:])
    assert (point["attractor"] == "period-1") == (spread < 0.002)
    kept = sorted((tmp_path / "walks").iterdir())
    stamps = [p.stat().st_mtime_ns for p in kept]
    again = bifurcation.run(settings, tmp_path, client, progress=False)
    assert [p.stat().st_mtime_ns for p in kept] == stamps  # read back, not walked again
    assert again["points"] == json.loads(json.dumps(record["points"]))
    assert (tmp_path / "bifurcation.png").stat().st_size > 0


def test_bad_parameters_are_one_line(capsys, tmp_path):
    with pytest.raises(ParameterError, match="u_q"):
        bifurcation.BifurcationSettings(param="u_q")
    code, lines = run_cli(capsys, ["bifurcation", "--param", "cpg.nope", "--from", "0", "--to", "1", "--num", "2",
                                   "--out", str(tmp_path / "b")])
    assert code == 2
    one_line(lines, "cpg.nope")
    code, lines = run_cli(capsys, ["bifurcation", "--param", "t1", "--from", "0.3", "--to", "0.4", "--num", "999",
                                   "--out", str(tmp_path / "c")])
    assert code == 2
    one_line(lines, "1998 walks", "--force")


def test_basins_walk_each_start_with_and_without_the_window(tmp_path, client):
    from drake_biped.experiments import basins

    config = fast_config().override({"sim.distance_m": 6.0, "sim.max_time_s": 30.0})
    settings = basins.BasinSettings(config, (0.405, 0.944), (0.12, 0.14), (0.19,), transient_m=2.0)
    start = basins.start_config(settings, "with", 0.14, 0.19)
    assert (start.initial.hip_angle_rad, start.initial.speed_mps) == (0.14, 0.19)
    assert (start.window.start_s, start.window.end_s) == (0.405, 0.944)
    assert basins.start_config(settings, "without", 0.14, 0.19).window.end_s == 0.0
    record = basins.run(settings, tmp_path, client, progress=False)
    walk = run_episode(start)
    cell = record["grids"]["with"][1][0]
    assert cell["distance_m"] == walk.distance_m and cell["fell"] == walk.fell
    td = walk.touchdowns
    first = int(np.searchsorted(td["com_x_m"] - td["com_x_m"][0], 2.0))
    assert cell["step_period_mean_s"] == pytest.approx(np.mean(np.diff(td["touchdown_time_s"][first:])[-20:]))


def test_envelopes_and_the_slope_premise():
    def points(fell):
        return [{"value": 0.01 * k, "fell": f} for k, f in enumerate(fell)]

    without = points([False, False, False, True, False])
    with_window = points([False, True, True, True, True])
    assert bifurcation.walked_up_to(without) == 0.02  # the walk at 0.04 does not count: 0.03 fell before it
    assert bifurcation.walked_up_to(points([True, False])) is None
    p = bifurcation.premise(without, with_window)
    assert p["without_up_to"] == 0.02 and p["with_up_to"] == 0.0 and p["band"] == [0.01, 0.02, 0.04] and p["holds"]
    assert not bifurcation.premise(with_window, without)["holds"]  # the window never fails where none climbs
    assert bifurcation.premise(points([False, True]), points([False, True]))["band"] == []


def test_options_that_would_change_nothing_are_refused_naming_them(capsys, tmp_path):
    argv = ["bifurcation", "--param", "u_a", "--out", str(tmp_path / "b")]
    code, lines = run_cli(capsys, [*argv, "--from", "2", "--to", "2.5", "--num", "1"])
    assert code == 2
    one_line(lines, "--num 1 --from 2 --to 2.5", "--to would change nothing")
    code, lines = run_cli(capsys, [*argv, "--from", "2", "--to", "2", "--num", "3"])  # one value three times
    assert code == 2
    one_line(lines, "value 2 is given twice")
    assert bifurcation.BifurcationSettings(param="u_a", values=(2.0,)).values == (2.0,)  # --num 1 --to = --from


def test_an_unread_gain_is_refused_for_being_unread_not_for_the_window():
    """The default gait carries no window: the old message blamed t2 <= t1 for any parameter that changed nothing."""
    with pytest.raises(ParameterError) as refused:
        bifurcation.BifurcationSettings(param="gait.hip_kd", values=(20.0, 30.0))
    assert "unread under this gait's hip drive 'motor'" in str(refused.value)
    assert "t2 <= t1" not in str(refused.value)


def test_a_slope_sweep_whose_walks_end_on_the_level_is_refused():
    config = fast_config().override({"sim.distance_m": 12.0, "sim.max_time_s": 80.0,
                                       "ground.slope_rad": 0.01, "ground.level_length_m": 20.0})
    with pytest.raises(ParameterError, match="--distance 12 --level-length 20"):
        bifurcation.BifurcationSettings(config, "slope", (0.01, 0.02), transient_m=3.0)


def test_without_lyapunov_the_report_describes_no_exponent():
    point = {"value": 0.3, "time_step_s": 0.001, "attractor": "period-1", "within_jitter": {"attractor": "period-1"},
             "step_periods_s": [0.5] * 20, "lyapunov": None, "cost_of_transport": None}
    record = {"param": "t1", "values": [0.3], "distance_m": 60.0, "transient_m": 10.0, "period_tolerance_s": 0.002,
              "period_window": 20, "jitter_tolerance_s": 0.01, "points": [point], "walked_up_to": 0.3}
    from drake_biped.analysis.bifurcation_report import markdown

    with_it = markdown(record)
    assert "Lyapunov: a finite-size exponent" in with_it and "| Lyapunov |" in with_it
    without = markdown({**record, "lyapunov": False})
    assert "finite-size exponent" not in without and "| Lyapunov |" not in without
    assert "no Lyapunov exponents" in without
    assert all(line.count("|") == 7 for line in without.splitlines() if line.startswith("|"))
