"""The reproduction: its verdict rules, its report's assembly, and a whole run on the smallest settings."""

import re

import pytest

from drake_biped.analysis.reproduce_report import (
    NOT_REPRODUCED,
    PARTLY,
    REPRODUCED,
    embed,
    reduction_verdict,
    slope_verdict,
    stability_verdict,
    table_vii_rows,
)
from drake_biped.experiments.reproduce import QUICK, Profile, Reproduction, check_out
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
    summary = {"base_cpg": {"u_a": 1.6, "u_r": 4.6, "kappa": 2.6},
               "best": {"point": {"cpg.u_a": 2.0, "cpg.kappa": 2.0, "gait.torso_pitch_rad": -0.38}}}
    rows, changes, verdict = table_vii_rows(summary)
    assert changes == "u_a +25.0 %, u_r 0.0 %, kappa -23.1 %"  # no change prints without a sign
    assert "1 of 3 CPG parameters move as in Table VII" in verdict and "torso_pitch_rad = -0.38" in verdict
    assert rows[0] == "| u_a | 2 → 2.74 (+37.0 %) | 1.6 → 2 (+25.0 %) |"


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


SMOKE = Profile("smoke", distance_m=5.0, grid_points=1, grid_initiation_points=1, learn=(1, 2),
                learn_variant=(1, 2), window_step_s=0.4, stability_trials=1, jacobian=False,
                margin_tolerance_n=100.0, slope=(1, 1), slope_grid_full=False, time_steps=(0.0005, 0.001),
                time_step_distance_m=2.0, expected_minutes=1.0, floquet_epsilons=(1e-6, 1e-5, 1e-4),
                floquet_newton_iterations=2)

SECTIONS = ("## The walk", "## Grid search, Table IV", "## Table III as printed", "## Torque-free windows",
            "## Experiment 1", "## Learners side by side",
            "### Table V", "### Exploration matched", "## Pushes and return maps", "Table VI", "### Push margins", "### The periodic orbit and its Floquet multipliers",
            "## The paper's learner on the gait searched for it", "## Slopes", "### The slope story, Figs. 8–9", "### Table VII", "### The slope story, Figs. 10–11",
            "## Time step")


@pytest.mark.slow
def test_a_whole_reproduction_writes_every_section_with_numbers_and_resumes(tmp_path):
    from drake_biped.experiments.executor import dask_client

    logs = []
    with dask_client(workers=2) as client:
        summaries = Reproduction(tmp_path, SMOKE, client, workers=2, log=logs.append).run_all()
    assert list(summaries) == list(Reproduction.STEPS)
    text = (tmp_path / "report.md").read_text()
    for heading in SECTIONS:
        assert heading in text, heading
    table = [line for line in text.splitlines() if line.startswith("| ") and "**" in line]
    assert len(table) == 16
    for row in table:  # every verdict row holds a measured number and a verdict
        ours = row.split(" | ")[2]
        assert re.search(r"\d", ours), row
    for figure in ("report_summary.png", "walk/walk.png", "learn/fig4_reward.png", "stability/fig7_return_map.png",
                   "compare_learners/compare.png", "floquet/none/floquet.png",
                   "learner_gait/learn/fig6_times.png", "learner_gait/window_map/landscape.png",
                   "slope/fig8_period.png", "slope2deg/fig9_distance.png", "grid/grid_slices.png"):
        assert f"({figure})" in text and (tmp_path / figure).is_file(), figure
    # The Floquet row says of each orbit whether its multipliers establish anything.
    from drake_biped.analysis.floquet import record_verdict

    floquet_row = next(row for row in table if "Floquet" in row)
    for name, gait in summaries["floquet"]["gaits"].items():
        assert f"({record_verdict(gait)})" in floquet_row, name
    html = (tmp_path / "report.html").read_text()
    assert html.count("<table>") >= 8 and '<img alt="Fig. 4" src="learn/fig4_reward.png"' in html
    # The slope story's numbers come from its own record.
    assert summaries["slope"]["checks"]["no_window"]["climbs"]  # the climbing gait climbs 0.02 rad
    assert not summaries["slope_default"]["no_window"]["climbs"]  # the default gait does not
    # The learner's gait: its own walk, and the window its stability runs is the learned one when a trial
    # learned one that walks, else the map's cheapest.
    lw, ls = summaries["learner_window_map"], summaries["learner_stability"]
    assert lw["gait"] == "coasting_wide" and lw["baseline"]["walked"]
    assert lw["baseline"]["cost_of_transport"] != pytest.approx(summaries["walk"]["cost_of_transport"], rel=0.05)
    learned = [r for r in summaries["learner_learn"]["evaluation"]["learned"]
               if not r["fell"] and r["t2"] > max(0.0, r["t1"])]
    assert ls["window_source"].startswith("learned") == bool(learned)
    if not learned and lw["best"] is not None:
        assert ls["window"] == [round(lw["best"]["t1"], 4), round(lw["best"]["t2"], 4)]

    logs.clear()
    again = Reproduction(tmp_path, SMOKE, None, workers=2, log=logs.append).run_all()
    assert logs == [f"[{Reproduction.folder(step)}] finished earlier: reused" for step in Reproduction.STEPS]
    assert again == summaries and (tmp_path / "report.md").read_text() == text
