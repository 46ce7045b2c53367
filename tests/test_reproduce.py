"""The reproduction: its verdict rules, its report's assembly, and a whole run on the smallest settings."""

import math
import re
from pathlib import Path

import pytest

from drake_biped.analysis.dynamics_report import floquet_text
from drake_biped.analysis.report_text import DIFFERS, NOT_REPRODUCED, PARTLY, REPRODUCED, embed
from drake_biped.analysis.verdicts import reduction_verdict, slope_verdict, stability_verdict, table_vii_rows
from drake_biped.experiments.reproduce import QUICK, Profile, Reproduction, check_out, steps_of
from drake_biped.params import ParameterError


def _evaluation(reduction, windows=((0.1, 0.4, False),)):
    learned = [{"t1": t1, "t2": t2, "fell": fell} for t1, t2, fell in windows]
    return {"reduction": reduction, "learned_walks": sum(not f for *_, f in windows), "learned": learned}


def test_reduction_verdict_follows_the_papers_40_to_50_percent_claim():
    assert reduction_verdict(_evaluation(0.45))[1] == REPRODUCED
    assert reduction_verdict(_evaluation(0.40))[1] == REPRODUCED
    assert reduction_verdict(_evaluation(0.20))[1].startswith(PARTLY + ": 20 %")
    assert reduction_verdict(_evaluation(0.01))[1] == NOT_REPRODUCED
    assert reduction_verdict(_evaluation(-0.05))[1] == NOT_REPRODUCED
    assert reduction_verdict(_evaluation(None))[1] == NOT_REPRODUCED
    ours, _ = reduction_verdict(_evaluation(0.35, ((0.1, 0.4, False), (0.5, 0.3, False), (0.1, 0.8, True))))
    assert "C_mt -35.0 %" in ours and "2 of 3 trials" in ours and "1 end with a window" in ours


def test_table_v_without_the_window_is_judged_against_058_within_ten_percent():
    """Table V's first column: the walk without a window's long-run C_mt (its whole walk's for a record without
    one) against the paper's 0.58, within 10 % reproduced; also given in eq. 1's per-kg unit (x g)."""
    from drake_biped.analysis.verdicts import cost_without_verdict

    def evaluation(cost, long=True):
        key = "long_run_cost_of_transport" if long else "cost_of_transport"
        return {"measure": "110 m walks", "no_window": {key: cost}}

    ours, verdict = cost_without_verdict(evaluation(0.2135))
    assert verdict == f"{DIFFERS}: below the paper's by 63 %"
    assert ours.startswith("0.2135 (110 m walks; 2.09 J/(kg·m)") and "0.37 × the paper's" in ours
    assert cost_without_verdict(evaluation(0.62))[1] == REPRODUCED
    assert cost_without_verdict(evaluation(0.64))[1] == f"{DIFFERS}: above the paper's by 10 %"
    assert cost_without_verdict(evaluation(0.55, long=False))[0].startswith("0.5500 (its walk;")
    assert cost_without_verdict({"no_window": None})[1] == NOT_REPRODUCED


def test_a_floquet_row_gives_no_radius_where_no_perturbation_converged():
    converged = {"spectral_radius": 0.449, "converged_epsilon": 1e-7, "fixed_point_residual": 1e-4,
                 "newton_tolerance": 1e-3, "evaluation_noise": None}
    unconverged = {**converged, "spectral_radius": 59792.3, "converged_epsilon": None}
    text = floquet_text({"none": converged, "learned": unconverged})
    assert text == ("none ρ 0.449 (stable), learned: not established: the Jacobian did not converge "
                    "(Newton's residual 1.0e-04)")


def test_slope_verdict_needs_all_three_claims():
    def summary(fails, none, adapted):
        return {"verdicts": {"learned_period_fails_to_climb": fails, "no_period_climbs": none,
                             "learning_shrinks_the_period_until_it_climbs": adapted, "trials": 2}}

    assert slope_verdict(summary(True, True, 2))[1] == REPRODUCED
    assert slope_verdict(summary(True, True, 0))[1] == PARTLY + " (2 of 3 claims hold)"
    assert slope_verdict(summary(False, False, 0))[1] == NOT_REPRODUCED + " (0 of 3 claims hold)"


def test_stability_verdict_counts_stable_cells_and_the_largest_difference():
    def cell(rho, stable, paper=0.3):
        return {"spectral_radius": rho, "stable": stable, "paper_spectral_radius": paper}

    cells = {"without": {"a": cell(0.5, True), "b": cell(0.4, True), "c": cell(0.2, True)},
             "with": {"a": cell(0.9, True), "b": cell(None, None), "c": cell(0.3, False)}}
    ours, verdict = stability_verdict(cells)
    assert ours.startswith("4 of 6 cells stable") and "up to 0.60" in ours
    assert verdict == NOT_REPRODUCED + ": 2 cell(s) not stable"
    for kinds in cells.values():
        for c in kinds.values():
            c.update(spectral_radius=0.3, stable=True)
    assert stability_verdict(cells)[1].startswith(REPRODUCED)


def test_table_vii_compares_the_direction_of_each_change():
    summary = {"base_cpg": {"u_a": 1.6, "u_r": 4.6, "kappa": 2.6}, "points": 64, "walked": 12,
               "best": {"point": {"cpg.u_a": 2.0, "cpg.kappa": 2.0, "gait.torso_pitch_rad": -0.38}}}
    rows, changes, verdict = table_vii_rows(summary)
    assert changes == "u_a +25.0 %, u_r 0.0 %, kappa -23.1 %"  # no change prints without a sign
    assert "1 of 3 CPG parameters move as in Table VII" in verdict and "torso_pitch_rad = -0.38" in verdict
    assert rows[0] == "| u_a | 2 → 2.74 (+37.0 %) | 1.6 → 2 (+25.0 %) |"


def test_table_vii_is_not_reproduced_when_no_point_climbs():
    """A grid whose best point is its furthest fall gives no 2.0° parameters to compare with Table VII."""
    summary = {"base_cpg": {"u_a": 1.6, "u_r": 4.6, "kappa": 2.6}, "points": 64, "walked": 0,
               "best": {"point": {"cpg.kappa": 3.25}, "distance_m": 2.536}}
    _, changes, verdict = table_vii_rows(summary)
    assert changes == "no point climbs (the furthest falls at 2.54 m)"
    assert verdict == NOT_REPRODUCED + ": none of the grid's 64 points climbs 2.0°"
    assert table_vii_rows({**summary, "walked": 3})[2].startswith("differs: 1 of 3")


def test_embedded_reports_keep_their_figures_and_sit_below_the_main_headings():
    text = "# Title\n\n## Part\n\n![Fig](fig7.png) [data](sub/x.json) [web](https://x.org/a) [anchor](#top)\n"
    out = embed(text, "stability")
    assert out.startswith("### Title\n\n#### Part")
    assert "![Fig](stability/fig7.png)" in out and "[data](stability/sub/x.json)" in out
    assert "(https://x.org/a)" in out and "(#top)" in out


def test_an_output_folder_keeps_one_profile(tmp_path):
    check_out(tmp_path, QUICK)
    check_out(tmp_path, QUICK)
    with pytest.raises(ParameterError, match="holds a 'quick' run"):
        check_out(tmp_path, Profile("full", *[getattr(QUICK, f) for f in list(QUICK.__dataclass_fields__)[1:]]))


SMOKE = Profile("smoke", distance_m=8.0, grid_points=1, grid_initiation_points=1, learn=(1, 2),
                learn_variant=(1, 2), window_step_s=0.4, stability_trials=1, jacobian=False,
                margin_force_step_n=50.0, slope=(1, 1), slope_grid_full=False, time_steps=(0.0005, 0.001),
                time_step_distance_m=2.0, expected_minutes=1.0, floquet_epsilons=(1e-6, 1e-5, 1e-4),
                floquet_newton_iterations=2, dynamics=(2, 2, 2), dynamics_walks_m=(5.0, 5.0, 4.0, 4.0))

SECTIONS = ("## The walk", "## Grid search, Table IV", "## Table III as printed", "## Torque-free windows",
            "## Experiment 1", "## Learners side by side", "### Table V", "### Exploration matched",
            "## Pushes and return maps", "Table VI", "### Push margins",
            "### The periodic orbit and its Floquet multipliers", "## The gait as a dynamical system", "## Slopes", "### The slope story, Figs. 8–9",
            "### Table VII", "### The slope story, Figs. 10–11", "## Time step", "## Other gaits, and why each exists")


@pytest.mark.slow
def test_a_whole_reproduction_writes_every_section_with_numbers_and_resumes(tmp_path):
    from drake_biped.common.executor import dask_client

    logs = []
    with dask_client(workers=2) as client:
        summaries = Reproduction(tmp_path, SMOKE, client, workers=2, log=logs.append, gait="fast_servo").run_all()
    assert list(summaries) == list(steps_of(SMOKE, "fast_servo")) and "full_run" not in summaries
    text = (tmp_path / "report.md").read_text()
    for heading in SECTIONS:
        assert heading in text, heading
    table = [line for line in text.splitlines() if line.startswith("| ") and "**" in line]
    assert len(table) == 17
    for row in table:  # every verdict row holds a measured number and a verdict
        ours = row.split(" | ")[2]
        assert re.search(r"\d", ours), row
    for figure in ("report_summary.png", "walk/walk.png", "learn/fig4_reward.png", "stability/fig7_return_map.png",
                   "compare_learners/compare.png", "floquet/none/floquet.png", "slope/fig8_period.png",
                   "slope2deg/fig9_distance.png", "grid/grid_slices.png", "dynamics/t1/bifurcation.png",
                   "dynamics/basins/basins.png", "walk/energy.png", "energy/window/energy.png",
                   "energy/paper_window/energy.png"):
        assert f"({figure})" in text and (tmp_path / figure).is_file(), figure
    # the energy audit with the learned window and on the other shipped gait, without and with its window
    assert "| fast_servo, no window (the walk above) |" in text and "| paper, no window |" in text
    # The Floquet row says of each orbit whether its multipliers establish anything.
    from drake_biped.analysis.floquet import record_verdict

    # The time step row says so when the study chose another step than the one this run's experiments used.
    chosen = summaries["time_step"]["chosen_step_s"]
    time_row = next(row for row in table if row.startswith("| Time step"))
    assert ("this run's experiments at 1 ms" in time_row) == (chosen != 0.001), time_row
    floquet_row = next(row for row in table if "Floquet" in row)
    for name, gait in summaries["floquet"]["gaits"].items():
        assert record_verdict(gait) in floquet_row, name
    html = (tmp_path / "report.html").read_text()
    assert html.count("<table>") >= 8 and '<img alt="Fig. 4" src="learn/fig4_reward.png"' in html
    # One gait: Table VI, the push margins and both slope stories use the learned window, the best learned
    # trial's when one walks, else the window map's cheapest; the slopes walk the default gait.
    learned = [r for source in ("learn", "learn_variant") for r in summaries[source]["evaluation"]["learned"]
               if not r["fell"] and r["t2"] > max(0.0, r["t1"])]
    window = summaries["push_margin"]["settings"]["window"]
    assert summaries["stability"]["settings"]["window"] == window
    assert summaries["time_step"]["settings"]["windows"][0] == window  # item 1's rule judges the learned window
    assert summaries["push_margin"]["window_source"].startswith("learned") == bool(learned)
    if not learned and summaries["window_map"]["best"] is not None:
        best = summaries["window_map"]["best"]
        assert window == [round(best["t1"], 4), round(best["t2"], 4)]
    for name in ("slope", "slope2deg"):
        assert summaries[name]["settings"]["start"] == window
    assert summaries["slope"]["settings"]["config"]["cpg"] == summaries["learn"]["settings"]["config"]["cpg"]
    assert summaries["grid_slope2deg"]["base_cpg"] == summaries["learn"]["settings"]["config"]["cpg"]

    logs.clear()
    again = Reproduction(tmp_path, SMOKE, None, workers=2, log=logs.append, gait="fast_servo").run_all()
    assert logs == [f"[{step}] finished earlier: reused" for step in steps_of(SMOKE, "fast_servo")]
    # the same numbers, each step now named as reused from the folder's records, not measured by this run
    assert all(s.pop("reused") for s in again.values()) and again == summaries
    from drake_biped.analysis.reproduce_report import provenance_text

    rerun = (tmp_path / "report.md").read_text()
    reused = provenance_text({k: {**s, "reused": True} for k, s in summaries.items()})
    assert reused.startswith("Measured by this run: none.") and reused in rerun
    assert rerun.replace(reused, provenance_text(summaries)) == text
    # a full run leaves what a quick run checks: its verdict rows, keyed, and its learned windows' C_mt
    import json

    digest = json.loads((tmp_path / "verdicts.json").read_text())
    assert [r["verdict"] for r in digest["rows"]] == [row.split(" | ")[3].strip(" |*") for row in table]
    # (the C_mt the learning record's own configuration walks: its 10 m episode's, which a quick run re-walks)
    assert digest["checks"]["learn"]["no_window"] == summaries["learn"]["evaluation"]["episode"]["no_window"]


def _digest():
    rows = [{"key": k, "what": k, "paper": "p", "ours": f"{k} measured", "verdict": v} for k, v in
            (("table_iii", NOT_REPRODUCED), ("learn", NOT_REPRODUCED), ("learner_learn", REPRODUCED),
             ("stability", REPRODUCED))]
    return {"rows": rows, "code": {}, "checks": {}}


def test_a_quick_row_never_judges_what_its_size_cannot_and_shows_the_full_runs_verdict_checked():
    from drake_biped.analysis.reproduce_report import CANNOT_JUDGE, quick_rows

    s = {"table_iii": {"fell": True, "steps": 2, "distance_m": 1.22},
         "learn": {"settings": {"trials": 2, "episodes": 4}, "evaluation": _evaluation(-0.011)},
         "full_run": {"checks": {"learner_learn": {"walks": 6, "agree": 6, "max_relative_difference": 0.0},
                                 "learn": {"walks": 2, "agree": 1, "max_relative_difference": 0.02}}}}
    rows = {r["what"]: r for r in quick_rows(s, _digest())}
    # measured here and judgeable at any size: its own verdict
    assert rows["table_iii"]["this_verdict"] == NOT_REPRODUCED and "1.22 m" in rows["table_iii"]["this_run"]
    # a few episodes of learning: what it measured, no verdict of its own, the full run's beside it
    assert rows["learn"]["this_verdict"] == CANNOT_JUDGE and "after 2 × 4 episodes" in rows["learn"]["this_run"]
    assert rows["learn"]["full_run"].startswith("learn measured: not reproduced")
    assert "✗ checked here: 1 of 2 re-walks" in rows["learn"]["full_run"]
    assert rows["learner_learn"]["this_run"] == "not run at this size" and rows["learner_learn"]["this_verdict"] == ""
    assert rows["learner_learn"]["full_run"].endswith("✓ checked here: 6 re-walks give the recorded C_mt to the "
                                                      "last digit")
    assert "checked" not in rows["stability"]["full_run"]  # nothing of Table VI is re-walked
    # a record of another machine, or one that names none, is checked within the stated tolerance, and says so
    from drake_biped.analysis.reproduce_report import _check_text

    text = _check_text({"walks": 3, "agree": 3, "same_digits": 1, "rule": "relative 0.001",
                        "max_relative_difference": 0.0008})
    assert text.startswith(" ✓ checked here: 3 re-walks give the recorded C_mt within a relative 0.001") and \
        "1 of 3 to the last digit (largest difference 0.080 %)" in text
    assert not any(r["this_verdict"] == NOT_REPRODUCED for k, r in rows.items() if k != "table_iii")


def test_the_packaged_full_run_is_the_shipped_full_runs_verdicts():
    """The package carries the committed full run's verdicts.json (a wheel has no benchmarks/ folder): the two
    copies must be the same file."""
    from pathlib import Path

    from drake_biped.analysis.reproduce_report import full_run_records
    from drake_biped.resources import full_run_digest

    shipped = Path(__file__).resolve().parents[1] / full_run_records(full_run_digest()) / "verdicts.json"
    if not shipped.is_file():
        pytest.skip("not a checkout")
    import json

    assert full_run_digest() == json.loads(shipped.read_text())
    assert {r["key"] for r in full_run_digest()["rows"]} >= {"learn", "stability", "floquet"}


def test_the_quick_report_names_the_full_runs_gait_when_it_is_not_the_default():
    """A full run measured on another gait than the one this run walks is named by its shipped gait (or
    "another gait"), so that its column is not read as this gait's; on the same gait, nothing is said."""
    from drake_biped.analysis.reproduce_report import full_run_gait, full_run_gait_name
    from drake_biped.params import EpisodeConfig
    from drake_biped.resources import load_gait

    def digest(config):
        return {"checks": {"learn": {"config": config.to_dict()}}}

    assert full_run_gait(digest(EpisodeConfig())) is None  # the default is the paper's walker
    assert full_run_gait(digest(load_gait("paper_servo"))) == "`paper_servo`"
    assert full_run_gait(digest(EpisodeConfig().override({"u_a": 2.2}))) == "another gait"
    assert full_run_gait({"checks": {}}) is None and full_run_gait(None) is None
    # a run on another gait names the full run's gait, and nothing when the full run is its own
    assert full_run_gait(digest(load_gait("fast_servo")), "paper") == "`fast_servo`"
    assert full_run_gait(digest(load_gait("paper")), "fast_servo") == "`paper`"
    assert full_run_gait(digest(load_gait("fast_servo")), "fast_servo") is None
    # and the quick report points at the folder of the gait's committed full run
    from drake_biped.analysis.reproduce_report import full_run_records

    assert full_run_records(digest(load_gait("paper"))) == "benchmarks/results/reproduce-paper"
    assert full_run_records(digest(load_gait("fast_servo"))) == "benchmarks/results/reproduce-full"
    # the gait a reproduction walks unless told is the one whose full run ships
    from drake_biped.experiments.reproduce import DEFAULT_STORY
    from drake_biped.resources import full_run_digest

    assert full_run_gait_name(full_run_digest()) == DEFAULT_STORY
    assert full_run_gait(full_run_digest(), DEFAULT_STORY) is None


def test_a_story_runs_on_its_own_gait_and_a_folder_keeps_one_gait(tmp_path):
    """`--gait paper`: every step's walker is the shipped `paper` gait (its own plant step), its matched
    exploration and its t1 sweep are its story's, the shipped full run (the paper walker's) is not checked on
    `fast_servo`, and a folder of one gait's run refuses another's."""
    import dataclasses

    from drake_biped.experiments.reproduce import STORIES, ReproduceSettings, story_of
    from drake_biped.params import EpisodeConfig
    from drake_biped.resources import load_gait

    paper = Reproduction(tmp_path, QUICK, None, gait="paper")
    shipped = load_gait("paper")
    assert paper.base == shipped and paper.level.cpg == shipped.cpg and paper.level.gait == shipped.gait
    assert paper.level.sim == dataclasses.replace(shipped.sim, distance_m=QUICK.distance_m)
    assert Reproduction(tmp_path, QUICK, None, gait="fast_servo").base == load_gait("fast_servo")
    assert Reproduction(tmp_path, QUICK, None).base == shipped == EpisodeConfig()  # the paper's walker unless told
    # fast_servo's sweep is fixed; the paper's follows the learned window, ending before its t2
    assert STORIES["fast_servo"].t1_values((0.37, 0.86), 9)[::8] == (0.30, 0.46)
    values = STORIES["paper"].t1_values((0.1, 0.2), 5)
    assert values[0] == 0.02 and values[-1] == 0.18 and len(set(values)) == 5
    assert STORIES["paper"].t1_values((0.02, 0.3), 3)[0] == 0.0
    # the time-step study's second window: fast_servo's is its committed run's (0.3-0.6 s), the paper walker's
    # (the study's own, `time-step` without --params) one of its own map's windows that walk
    from drake_biped.experiments.time_step import WALKS

    assert STORIES["fast_servo"].study_window == (0.3, 0.6) and STORIES["paper"].study_window == (0.5, 0.6) == \
        WALKS[-1]
    assert "full_run" in steps_of(QUICK) and "full_run" not in steps_of(QUICK, "fast_servo")
    with pytest.raises(ParameterError, match="--gait 'slow'"):
        story_of("slow")
    with pytest.raises(ParameterError, match="--gait 'slow'"):
        ReproduceSettings(QUICK, "slow")
    check_out(tmp_path, QUICK, "paper")
    check_out(tmp_path, QUICK, "paper")
    check_out(tmp_path, QUICK)  # the paper's walker unless told
    with pytest.raises(ParameterError, match="holds a run on the 'paper' gait"):
        check_out(tmp_path, QUICK, "fast_servo")
    check_out(tmp_path / "d", QUICK, "fast_servo")
    with pytest.raises(ParameterError, match="holds a run on the 'fast_servo' gait"):
        check_out(tmp_path / "d", QUICK)


@pytest.mark.slow
def test_the_quick_run_walks_the_full_runs_learned_windows_again_and_gets_its_numbers(tmp_path):
    """The quick profile's check of the shipped full run: every learned window (and no window) re-walked
    gives the C_mt the full run recorded, to the last digit on the record's machine and within
    versions.CROSS_MACHINE_RTOL elsewhere (the rule named); its report carries both columns."""
    from drake_biped.analysis.reproduce_report import full_run_gait_name
    from drake_biped.common.executor import dask_client
    from drake_biped.resources import full_run_digest

    quick = Profile(**{**QUICK.to_dict(), "steps": ("walk", "table_iii", "full_run"), "distance_m": 2.0})
    gait = full_run_gait_name(full_run_digest())  # a quick run checks the full run on the full run's own gait
    with dask_client(workers=2) as client:
        summaries = Reproduction(tmp_path, quick, client, workers=2, log=lambda _: None, gait=gait).run_all()
    checks = summaries["full_run"]["checks"]
    assert set(checks) == set(full_run_digest()["checks"]) >= {"learn", "learn_variant"}
    text = (tmp_path / "report.md").read_text()
    for check in checks.values():
        assert check["agree"] == check["walks"], check["rows"]
        assert f"✓ checked here: {check['walks']} re-walk" in text
        if check["rule"] != "last digit":
            assert f"within a {check['rule']}" in text and check["rule"] == "relative 0.001"
    assert "| this run (quick) | full run (checked here) |" in text and "not run at this size" in text


def test_every_shipped_gait_says_why_it_exists_and_the_report_reads_it_from_the_file():
    """Every gait file has an `about` with why, where from and its claim; the report's closing section lists
    the gaits other than the default with their files' reasons; gaits/paper.json is EpisodeConfig()."""
    import json

    from drake_biped.analysis.reproduce_report import other_gaits_section
    from drake_biped.params import EpisodeConfig
    from drake_biped.resources import gait_about, gait_names, gait_path, load_gait

    assert "paper" in gait_names()
    for name in gait_names():
        about = json.loads(gait_path(name).read_text())["about"]
        assert about == gait_about(name) and all(w in about for w in ("Why:", "Source:", "Claim:")), name
    section = "\n".join(other_gaits_section())
    assert all(f"| `{name}` | {gait_about(name)} |" in section for name in gait_names() if name != "paper")
    assert "| `paper` |" not in section
    assert load_gait("paper") == EpisodeConfig()


def test_the_learned_window_is_the_best_learned_trial_else_the_maps_cheapest(tmp_path):
    import json

    from drake_biped.analysis.reproduce_report import window_name
    from drake_biped.resources import gait_compare_window

    r = Reproduction(tmp_path, SMOKE, None, log=lambda _: None, gait="fast_servo")
    declared, source = gait_compare_window("fast_servo")
    assert r.learned_window() == (declared, f"no trial learned one and no window of the map walks: {source}", None)
    assert window_name(r.learned_window()[1]) == "the window its gait file declares"
    (tmp_path / "window_map").mkdir()
    (tmp_path / "window_map" / "summary.json").write_text(json.dumps({"best": {"t1": 0.31234, "t2": 0.9}}))
    assert r.learned_window()[:2] == ((0.3123, 0.9), "the window map's cheapest (no trial learned one)")
    assert window_name(r.learned_window()[1]) == "the window map's cheapest window"  # the report's words

    def learned(folder, rows):
        (tmp_path / folder).mkdir(exist_ok=True)
        (tmp_path / folder / "learning.json").write_text(json.dumps({"evaluation": {"learned": [
            {"trial": k, "t1": t1, "t2": t2, "cost_of_transport": c, "fell": f} for k, (t1, t2, c, f) in
            enumerate(rows)]}}))

    learned("learn_variant", [(0.2, 0.6, 0.3, False)])
    assert r.learned_window()[:2] == ((0.2, 0.6), "learned (learn_variant, trial 0)")
    assert window_name(r.learned_window()[1]) == "the learned window"
    # the paper's settings first; of its trials the cheapest that walks with a window
    learned("learn", [(0.4, 0.3, 0.1, False), (0.41, 1.0, 0.2, True), (0.43, 1.05, 0.25, False),
                      (-0.1, 0.9, 0.22, False)])
    assert r.learned_window() == ((0.0, 0.9), "learned (learn, trial 3)", tmp_path / "learn" / "learning.json")


def test_the_2deg_grid_raises_the_story_gaits_cpg_as_table_vii_does():
    from drake_biped.experiments.reproduce import FULL
    from drake_biped.resources import load_gait

    c, g = load_gait("fast_servo").cpg, load_gait("fast_servo").gait
    axes = {a.name: a.values for a in Reproduction(Path("."), FULL, None, gait="fast_servo").slope_axes()}
    assert len(axes) == 5 and math.prod(len(v) for v in axes.values()) == 64
    for k in ("u_a", "u_r", "kappa"):
        assert axes[f"cpg.{k}"] == (getattr(c, k), round(1.25 * getattr(c, k), 4))
    assert axes["gait.torso_pitch_rad"][0] == g.torso_pitch_rad and max(axes["gait.torso_pitch_rad"]) == \
        g.torso_pitch_rad  # leaning further forward only
    quick = {a.name: a.values for a in Reproduction(Path("."), SMOKE, None, gait="fast_servo").slope_axes()}
    assert set(quick) == {"gait.torso_pitch_rad", "cpg.u_a"} and all(len(v) == 2 for v in quick.values())
    paper = {a.name: a.values for a in Reproduction(Path("."), FULL, None).slope_axes()}
    assert paper["cpg.u_a"] == (2.0, 2.5) and paper["cpg.u_r"] == (2.1, 2.625) and paper["cpg.kappa"] == (1.8, 2.25)
    # under the hip motor the placement gain is unread: the paper's grid has no axis that walks alike
    assert "gait.placement_gain" not in paper and len(paper) == 4 and "gait.placement_gain" in axes
    # the shipped spec that gives the step its own command (`grid --params paper --spec slope_2deg_paper`) is it
    from drake_biped.experiments.grid import load_spec

    assert {a.name: a.values for a in load_spec("slope_2deg_paper")} == paper


def test_table_iii_ranks_among_the_grids_points_by_the_grids_order(tmp_path):
    import json

    from drake_biped.analysis.reproduce_report import table_iii_rank

    assert table_iii_rank(tmp_path) is None
    (tmp_path / "grid").mkdir()
    rows = [(10.0, 0.25), (10.0, 0.18), (4.2, 0.4), (0.3, None)]
    (tmp_path / "grid" / "points.jsonl").write_text("".join(
        json.dumps({"key": str(k), "distance_m": d, "cost_of_transport": c}) + "\n" for k, (d, c) in enumerate(rows)))
    assert table_iii_rank(tmp_path) is None  # no walk of Table III's own
    (tmp_path / "grid" / "table_iii.json").write_text(json.dumps({"distance_m": 10.0, "cost_of_transport": 0.2193}))
    assert table_iii_rank(tmp_path) == (2, 5)
    import gzip  # a committed run's points are compressed

    points = tmp_path / "grid" / "points.jsonl"
    points.with_name("points.jsonl.gz").write_bytes(gzip.compress(points.read_bytes()))
    points.unlink()
    assert table_iii_rank(tmp_path) == (2, 5)


@pytest.mark.parametrize("gait", ["paper", "fast_servo"])
def test_the_committed_full_runs_report_reads_its_own_gait_in_every_section(monkeypatch, gait):
    """The report of each committed full run's records (the shipped one, the paper's walker's, and the default
    gait, fast_servo's) names its gait where a section names the gait (a loop over the slope claims once left its last
    claim's words in the grid and window-map sections)."""
    from drake_biped.analysis import reproduce_report
    from drake_biped.analysis.reproduce_report import FULL_RUN_RECORDS, report_markdown
    from drake_biped.experiments.reproduce import FULL, STORIES
    from drake_biped.records import read_kept

    out = Path(__file__).resolve().parents[1] / FULL_RUN_RECORDS[gait]
    if not out.is_dir():
        pytest.skip("not a checkout")
    summaries = {step: read_kept(out / step / "summary.json") for step in steps_of(FULL, gait)}
    # steps added since the run was measured (the energy audit's walks) are not in its records
    summaries = {step: summary for step, summary in summaries.items() if summary is not None or step != "energy"}
    monkeypatch.setattr(reproduce_report, "summary_figure", lambda *a, **k: None)  # the records stay as committed
    text, verdicts = report_markdown(out, summaries, FULL, {}, gait, STORIES[gait].why)
    name = f"the `{gait}` gait"
    assert f"## Torque-free windows of {name} (`window_map/`)" in text
    assert f"Table III itself (with {name}'s other gains)" in text
    assert "Slope story" not in text.split("## Experiment 1")[0].split("| what | paper |")[0]
    assert [v[0] for v in verdicts if v[0].startswith("Slope story")] == [
        "Slope story, 0.02 rad (Figs. 8–9)", "Slope story, 2.0° with the grid's best (Figs. 10–11)"]


def test_a_report_says_which_steps_this_run_measured_and_which_it_reused(tmp_path):
    """A folder resumed (or copied) from other records: their steps are named as reused, with the code that
    measured them, never as measured by this run."""
    from drake_biped.analysis.reproduce_report import provenance_text

    copied = Reproduction(tmp_path, QUICK, None, log=lambda _: None)
    first = copied.experiment("walk", {"d": 1}, lambda folder: {"distance_m": 1.0})
    assert "reused" not in first and set(first["measured_by"]) == {"drake_biped", "git_commit", "drake"}
    again = Reproduction(tmp_path, QUICK, None, log=lambda _: None)
    reused = again.experiment("walk", {"d": 1}, lambda folder: pytest.fail("walked again"))
    assert reused["reused"] and reused["measured_by"] == first["measured_by"]
    fresh = again.experiment("grid", {"p": 2}, lambda folder: {"points": 2})
    text = provenance_text({"walk": reused, "grid": fresh})
    code = first["measured_by"]
    assert "Measured by this run: grid." in text
    assert (f"not measured again: walk (measured by drake-biped {code['drake_biped']} ({code['git_commit']}), "
            f"Drake {code['drake']})") in text
    assert "every number below is measured by this run" not in text.lower()
    assert provenance_text({"grid": fresh}) == "Every number below is measured by this run."
    old = provenance_text({"walk": {"reused": True}, "grid": fresh})  # a summary from before code was recorded
    assert "walk (measured by code not recorded)" in old
