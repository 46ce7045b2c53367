"""The window map's grid is the gait's own: placed by the step period of its walk without a window."""

import pytest
from walkers import fast_config

from drake_biped.experiments.window_map import PAST_TOUCHDOWN, WindowMapSettings, run
from drake_biped.params import ParameterError


def test_a_map_left_to_the_gait_spans_its_whole_step_and_past_touchdown(tmp_path, client):
    """The default gait (its steps about 0.42 s): t1 runs to the step period, t2 past it, to 1.5 x; the grid and
    the period are in the record; the baseline is walked once (kept), not again for the grid."""
    config = fast_config().override({"sim.distance_m": 2.0})
    record = run(WindowMapSettings(config, t1_step_s=0.2, t2_step_s=0.2), tmp_path / "wm", client, progress=False)
    grid, period = record["grid"], record["baseline"]["step_period_s"]
    assert 0.35 < period < 0.5 and grid["step_period_s"] == period
    assert grid["t1_max_s"] == pytest.approx(period, abs=1e-6)
    assert grid["t2_max_s"] == pytest.approx(PAST_TOUCHDOWN * period, abs=1e-6)
    t1s, t2s = {w["t1"] for w in record["windows"]}, {w["t2"] for w in record["windows"]}
    assert t1s == {0.0, 0.2, 0.4} and max(t2s) > period  # windows that run past touchdown
    lines = (tmp_path / "wm" / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == 1 + len(record["windows"])


def test_a_gait_without_a_step_period_asks_for_the_grid():
    with pytest.raises(ParameterError, match="gives no step period .* give --t1-max, --t2-max and --step"):
        WindowMapSettings().for_step_period(None)
    given = WindowMapSettings(t1_max_s=0.3, t2_max_s=0.5, t1_step_s=0.1, t2_step_s=0.1)
    assert given.for_step_period(None) is given  # a whole grid needs no period
    with pytest.raises(ParameterError, match="placed by the gait's step period"):
        WindowMapSettings().window_count()
