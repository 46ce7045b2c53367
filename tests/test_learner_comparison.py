"""The learner comparison's numbers on records whose answers are known."""

import math

import pytest

from drake_biped.analysis.learner_comparison import (
    best_walking_window,
    compare,
    episodes_to_within,
    running_cost,
)


def _episode(cmt, fell=False):
    return {"cost_of_transport": cmt, "fell": fell}


def test_best_walking_window_ignores_falls():
    wmap = {"windows": [{"t1": 0.1, "t2": 0.4, "walked": False, "cost_of_transport": 0.05},
                        {"t1": 0.2, "t2": 0.5, "walked": True, "cost_of_transport": 0.16},
                        {"t1": 0.3, "t2": 0.6, "walked": True, "cost_of_transport": 0.21}]}
    assert best_walking_window(wmap)["t1"] == 0.2
    with pytest.raises(ValueError, match="no window of the map walks"):
        best_walking_window({"windows": wmap["windows"][:1]})


def test_running_cost_averages_the_last_walks_and_skips_falls():
    eps = [_episode(0.3), _episode(0.05, fell=True), _episode(0.1)]
    r = running_cost(eps, length=2)
    assert r[0] == 0.3 and r[1] == 0.3 and r[2] == pytest.approx(0.2)
    assert math.isnan(running_cost([_episode(None, fell=True)])[0])


def test_episodes_to_within_is_the_first_hit():
    eps = [_episode(0.30)] * 3 + [_episode(0.16)] * 10
    assert episodes_to_within(eps, 0.16, length=1) == 4
    assert episodes_to_within(eps, 0.16, length=3) == 6  # (0.16 * 3) / 3 from episode 6
    assert episodes_to_within(eps, 0.10, length=1) is None


def test_compare_measures_distance_and_falls():
    best = {"t1": 0.2, "t2": 0.5, "cost_of_transport": 0.16}
    record = {"evaluation": {"learned_mean_cost_of_transport": 0.17, "reduction": 0.23, "learned_walks": 2},
              "trials": [{"final_mean": [0.2, 0.8], "episodes": [_episode(0.2), _episode(0.1, fell=True)]},
                         {"final_mean": [0.5, 0.9], "episodes": [_episode(0.16), _episode(0.16)]}]}
    row = compare(record, best)
    assert row["distance_to_best_s"] == pytest.approx([0.3, 0.5])
    assert row["falls"] == 1 and row["episodes"] == 4
    assert row["episodes_to_within"] == [None, 1] and row["reached"] == 1


def test_compare_without_a_walking_window_reports_no_distance():
    record = {"evaluation": {"learned_mean_cost_of_transport": None, "reduction": None, "learned_walks": 0},
              "trials": [{"final_mean": [0.2, 0.8], "episodes": [_episode(0.2)]}]}
    row = compare(record, None)
    assert row["mean_distance_to_best_s"] is None and row["episodes_to_within"] == [None] and row["reached"] == 0


def test_compare_learners_and_learn_sign_the_same_reduction_the_same_way():
    """A learned window that lowers C_mt by 37.7 % (as learned and re-walked) is "-37.7 %" in compare-learners'
    table and in learn's Table V and re-walk table alike: every signed percentage of C_mt is a change (- a fall),
    never a "+" for a saving in one report and for a rise in another."""
    import re

    from drake_biped.analysis import rewalks
    from drake_biped.analysis.figures import table_v
    from drake_biped.analysis.learner_comparison import markdown

    base, learned = 0.6, 0.6 * (1 - 0.377)
    walk = {"cost_of_transport": learned, "fell": False, "distance_m": 10.0}
    none = {"cost_of_transport": base, "fell": False, "distance_m": 10.0}
    rows = {c: {"no_window": none, 0: walk} for c in rewalks.CHANGES}
    evaluation = {"no_window": {"cost_of_transport": base, "fell": False}, "learned_walks": 1,
                  "learned": [{"trial": 0, "t1": 0.3, "t2": 0.6, "cost_of_transport": learned, "fell": False}],
                  "learned_mean_cost_of_transport": learned, "learned_std_cost_of_transport": 0.0,
                  "reduction": 1 - learned / base, "measure": "long-run C_mt",
                  "rewalks": rewalks.summary(1e-3, 0.175, [{"trial": 0, "t1": 0.3, "t2": 0.6}], rows)}
    record = {"evaluation": evaluation,
              "trials": [{"trial": 0, "final_mean": [0.3, 0.6], "episodes": [_episode(learned)]}]}
    comparison = {"best_window": {"t1": 0.3, "t2": 0.6, "cost_of_transport": learned},
                  "no_window_cost_of_transport": base,
                  "settings": {"trials": 1, "episodes": 1, "mean": [0.5, 0.5], "variance": 0.04},
                  "learners": {"garb": {**compare(record, None), "wall_s": 60.0}}}
    learn_table, compare_table = table_v({"settings": {}, **record}), markdown(comparison)
    garb_row = next(line for line in compare_table.splitlines() if line.startswith("| garb |"))
    assert garb_row.count("-37.7 %") == 2  # the C_mt change as learned and re-walked
    assert "C_mt change: paper -50 %, ours -37.7 %" in learn_table
    assert "| 0 | 0.300–0.600 s | -37.7 % | -37.7 % | -37.7 % | -37.7 % | -37.7 % | yes |" in learn_table
    for table in (learn_table, compare_table):
        assert not re.search(r"\+37\.7", table), table
        assert "C_mt change" in table
