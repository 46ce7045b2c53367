"""The grid search: its axes and points, its spec files, and a tiny grid run, resumed and read back."""

import csv
import json
import math

import pytest
from retired_gaits import STEADY

from drake_biped.analysis.grid_ranking import better, rank
from drake_biped.cli import main
from drake_biped.experiments.grid import (
    INITIATION_RANGES,
    TABLE_IV,
    Axis,
    cell_centres,
    grid_points,
    load_spec,
    parse_spec,
    point_config,
    read_points,
    table_iv_axes,
)
from drake_biped.params import DEFAULT_CPG, EpisodeConfig, ParameterError


def test_cell_centres_split_the_range_evenly_and_stay_off_its_edges():
    assert cell_centres(0.0, 3.0, 2) == (0.75, 2.25)
    assert cell_centres(-2.0, 2.0, 4) == (-1.5, -0.5, 0.5, 1.5)
    assert cell_centres(1.0, 5.0, 1) == (3.0,)
    with pytest.raises(ParameterError, match="points per axis 0"):
        cell_centres(0.0, 1.0, 0)
    with pytest.raises(ParameterError, match="lo <= hi"):
        cell_centres(1.0, 0.0, 2)


def test_table_iv_grid_covers_the_papers_ranges_with_valid_configurations():
    axes = table_iv_axes(2)
    assert [a.name for a in axes] == ["cpg.alpha", "cpg.u_a", "cpg.u_eta", "cpg.u_r", "cpg.kappa",
                                      "initial.hip_angle_rad", "initial.speed_mps"]
    points = grid_points(axes)
    assert len(points) == 2**7
    for a, (lo, hi) in zip(axes, [*TABLE_IV.values(), *INITIATION_RANGES.values()]):
        assert all(lo < v < hi for v in a.values)
    # The initiation's ranges are centred on the paper's 7.6 deg and 0.175 m/s.
    assert sum(axes[5].values) / 2 == pytest.approx(math.radians(7.6))
    assert sum(axes[6].values) / 2 == pytest.approx(0.175)
    for p in points:  # every point is a configuration the toolkit accepts (u_r > 0 included)
        c = point_config(EpisodeConfig(), p)
        assert (c.cpg.alpha, c.cpg.u_a, c.cpg.u_eta, c.cpg.u_r, c.cpg.kappa, c.initial.hip_angle_rad,
                c.initial.speed_mps) == tuple(p.values())


def test_points_are_every_combination_with_the_last_axis_fastest():
    axes = [Axis("cpg.u_r", (1.0, 2.0)), Axis("initial.speed_mps", (0.1, 0.2, 0.3))]
    points = grid_points(axes)
    assert len(points) == 6 and len({tuple(p.values()) for p in points}) == 6
    assert [p["initial.speed_mps"] for p in points[:3]] == [0.1, 0.2, 0.3]
    assert points[3] == {"cpg.u_r": 2.0, "initial.speed_mps": 0.1}


def test_spec_files_name_short_or_dotted_fields(tmp_path):
    spec = tmp_path / "g.yaml"
    spec.write_text("axes:\n  u_a: {min: 1.0, max: 2.0, points: 2}\n  gait.torso_pitch_rad: {values: [-0.2, -0.3]}\n"
                    "  speed: {values: [0.2]}\n")
    axes = load_spec(spec)
    assert [(a.name, a.values) for a in axes] == [
        ("cpg.u_a", (1.25, 1.75)), ("gait.torso_pitch_rad", (-0.2, -0.3)), ("initial.speed_mps", (0.2,))]
    config = point_config(EpisodeConfig(), grid_points(axes)[-1])
    assert (config.cpg.u_a, config.gait.torso_pitch_rad, config.initial.speed_mps) == (1.75, -0.3, 0.2)
    assert config.cpg.u_r == DEFAULT_CPG.u_r  # the axes not in the grid keep the base's values


@pytest.mark.parametrize("spec, match", [
    ({"axes": {"u_z": {"values": [1.0]}}}, "'u_z': not a numeric EpisodeConfig field"),
    ({"axes": {"sim.contact_approximation": {"values": [1.0]}}}, "not a numeric"),
    ({"axes": {"u_a": [0, 3, 4]}}, r"axis u_a: expected \{min, max, points\}"),
    ({"axes": {"u_a": {"min": 0, "max": 3, "points": 0}}}, "points per axis 0"),
    ({"axes": {"u_a": {"values": [1.0, math.nan]}}}, "not a finite number"),
    ({"axes": {"u_a": {"values": [1.0]}, "cpg.u_a": {"values": [2.0]}}}, "given twice"),
    ({"axes": {}}, "non-empty 'axes'"),
    ({"axes": {"u_a": {"values": [1.0]}}, "repeat": 2}, "unknown key"),
])
def test_malformed_specs_are_refused_by_name(spec, match):
    with pytest.raises(ParameterError, match=match):
        parse_spec(spec)


def test_a_value_out_of_range_names_the_point():
    with pytest.raises(ParameterError, match=r"grid point \{'cpg.u_r': -1.0\}.*u_r = -1.0"):
        point_config(EpisodeConfig(), {"cpg.u_r": -1.0})


def test_best_is_furthest_then_cheapest():
    far = {"distance_m": 5.0, "cost_of_transport": 0.5}
    assert better(far, {"distance_m": 4.0, "cost_of_transport": 0.1})
    assert better({"distance_m": 5.001, "cost_of_transport": 0.2}, far)  # same centimetre: lower C_mt
    assert not better({"distance_m": 5.0, "cost_of_transport": None}, far)


def test_a_walk_ranks_among_the_grids_by_the_same_order():
    rows = [{"distance_m": d, "cost_of_transport": c} for d, c in
            ((10.0, 0.30), (10.0, 0.20), (9.999, 0.25), (3.0, 0.1), (10.0, None), (0.4, None))]
    assert rank({"distance_m": 10.0, "cost_of_transport": 0.22}, rows) == 2  # after 0.20 only
    assert rank({"distance_m": 10.0, "cost_of_transport": 0.20}, rows) == 1  # a tie shares the rank
    assert rank({"distance_m": 10.0, "cost_of_transport": 0.35}, rows) == 4  # 0.25 at 9.999 m is the same 10.00 m
    assert rank({"distance_m": 0.1, "cost_of_transport": None}, rows) == 7


def _lines(path):
    return [json.loads(line) for line in path.read_text().splitlines()]


@pytest.mark.slow
def test_tiny_grid_finds_the_walking_point_and_a_rerun_recomputes_nothing(tmp_path, capsys):
    """Two swing amplitudes: the default gait's walks 1.2 m; one a tenth as large cannot swing the leg
    through and falls. The best point is the walker, written as a parameter file the commands accept."""
    spec = tmp_path / "g.yaml"
    spec.write_text(f"axes:\n  u_a: {{values: [{DEFAULT_CPG.u_a / 10}, {DEFAULT_CPG.u_a}]}}\n")
    out = tmp_path / "grid"
    argv = ["grid", "--spec", str(spec), "--distance", "1.2", "--workers", "1", "--out", str(out)]
    assert main(argv) == 0
    rows = {r["point"]["cpg.u_a"]: r for r in _lines(out / "points.jsonl")}
    assert rows[DEFAULT_CPG.u_a]["distance_m"] >= 1.2 and not rows[DEFAULT_CPG.u_a]["fell"]
    assert rows[DEFAULT_CPG.u_a / 10]["fell"] and rows[DEFAULT_CPG.u_a / 10]["distance_m"] < 1.2
    best = EpisodeConfig.from_dict(json.loads((out / "best_params.json").read_text()))
    assert best.cpg.u_a == DEFAULT_CPG.u_a and best.sim.distance_m == 1.2
    record = json.loads((out / "grid.json").read_text())
    assert record["walked_the_distance"] == 1 and record["points"] == 2
    assert {"drake", "git_commit"} <= set(record["versions"])
    with open(out / "grid.csv") as f:
        assert len(list(csv.DictReader(f))) == 2
    assert (out / "grid_slices.png").stat().st_size > 0

    # Rerun: nothing recomputed. A killed write (half a line) loses only that point, which runs again.
    assert main(argv) == 0
    assert len(_lines(out / "points.jsonl")) == 2
    text = (out / "points.jsonl").read_text().splitlines(keepends=True)
    (out / "points.jsonl").write_text(text[0] + text[1][:25])
    assert main(argv) == 0
    lines = (out / "points.jsonl").read_text().splitlines()
    assert len(lines) == 2 and len(read_points(out / "points.jsonl")) == 2  # the half line set aside, run again
    assert (out / "points.jsonl.broken").read_text() == text[0] + text[1][:25]
    assert json.loads((out / "grid.json").read_text()) == record
    # The run log counts what each session computed: 2 points, then none, then the one lost.
    assert [x["episodes"] for x in json.loads((out / "run.json").read_text())["sessions"]] == [2, 0, 1]
    assert "1/2 points walk 1.2 m" in capsys.readouterr().out


def test_grid_refuses_bad_options(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["grid", "--spec", str(tmp_path / "none.yaml"), "--out", str(tmp_path / "g")])
    assert "no such file" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["grid", "--spec", "x.yaml", "--points-per-axis", "2", "--out", str(tmp_path / "g")])
    assert "either --spec or --points-per-axis" in capsys.readouterr().err


def test_shipped_specs_and_parameter_files_are_valid():
    from drake_biped.resources import gait_names, grid_spec_names, load_gait

    sizes = {name: len(grid_points(load_spec(name))) for name in grid_spec_names()}
    assert sizes == {"around_fast_servo": 64, "slope_0.02": 36, "slope_2deg": 64, "slope_2deg_paper": 32, "tiny": 4}
    for name in grid_spec_names():
        for point in grid_points(load_spec(name)):
            point_config(EpisodeConfig(), point)
    assert gait_names() == ["climbing", "climbing_2deg", "fast_servo", "paper", "paper_entrained", "paper_servo"]
    for name in ("climbing", "climbing_2deg"):  # the climbing gaits differ from the retired steady by the grid's axes
        assert load_gait(name).gait.torso_pitch_rad < load_gait(STEADY).gait.torso_pitch_rad


def test_every_shipped_gait_names_all_the_gains_it_reads():
    """A section's missing fields are the default gait's, so a shipped gait file lists every CPG, gait and
    initiation field its readings read (and none they leave unread, `GaitParams.unread`): a change of the
    default gait leaves it as it was."""
    from drake_biped.resources import gait_names, gait_path, load_gait

    full = EpisodeConfig().to_dict()
    for name in gait_names():
        data = json.loads(gait_path(name).read_text())
        unread = set(load_gait(name).gait.unread())
        for section in ("cpg", "gait", "initial"):
            expected = set(full[section]) - (unread if section == "gait" else set())
            assert set(data[section]) == expected, (name, section, set(data[section]) ^ expected)


def test_a_value_given_twice_is_refused_naming_the_axis_and_the_value():
    with pytest.raises(ParameterError, match="grid axis cpg.u_a: value 2.0 is given twice"):
        parse_spec({"axes": {"u_a": {"values": [2.0, 2.2, 2.0]}}})
    with pytest.raises(ParameterError, match="value 2.0 is given twice"):
        parse_spec({"axes": {"u_a": {"min": 2.0, "max": 2.0, "points": 2}}})


def test_an_axis_over_an_unread_gain_is_refused_for_being_unread():
    from drake_biped.experiments.grid import check_axes

    with pytest.raises(ParameterError) as refused:
        check_axes(EpisodeConfig(), [Axis("gait.hip_kd", (20.0, 30.0))])
    assert "unread under this gait's hip drive 'motor'" in str(refused.value)
    assert "t2 <= t1" not in str(refused.value)
