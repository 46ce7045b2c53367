import numpy as np
import pytest
from scipy.stats import norm

from drake_biped.analysis.landscape import WindowRewards, expected_reward, landscape


def fine_grid(reward_of, step=0.01):
    w = np.array([[a, b] for a in np.arange(0, 1.0001, step) for b in np.arange(0, 1.5001, step) if b > a])
    return w, np.array([reward_of(a, b) for a, b in w])


def test_window_rewards_follow_the_learning_runs_rules():
    r = WindowRewards(np.array([[0.1, 0.4], [0.3, 0.6]]), np.array([7.0, 5.0]), 4.5)
    got = r(np.array([[0.12, 0.41], [0.29, 0.7], [0.5, 0.2], [-0.3, -0.1], [-0.2, 0.38]]))
    # nearest window; t2 <= t1 no window; negative times act as 0 (so (-0.3, -0.1) is (0, 0): no window)
    np.testing.assert_array_equal(got, [7.0, 5.0, 4.5, 4.5, 7.0])


def test_expected_reward_matches_the_gaussian_integral():
    # Reward 2 for windows starting before 0.3 s, 1 otherwise; means far above the diagonal always sample a
    # window, so J = 1 + P(t1 < 0.3) = 1 + Phi((0.3 - mu1) / sigma).
    w, rew = fine_grid(lambda a, b: 2.0 if a < 0.3 else 1.0, step=0.005)
    r = WindowRewards(w, rew, 1.0)
    means = np.array([[0.2, 1.3], [0.3, 1.3], [0.45, 1.3]])
    j = expected_reward(r, means, 0.01, samples=20000, seed=1)
    np.testing.assert_allclose(j, 1.0 + norm.cdf((0.3 - means[:, 0]) / 0.1), atol=0.02)


def test_narrow_saving_beside_falls_is_invisible_to_a_wide_policy():
    # Windows starting in [0.1, 0.2] save 40 % (reward 1/0.6); windows ending after 0.7 s fall (reward 0.5);
    # the rest change nothing. A narrow policy sees nearly the whole saving; a wide one a fifth of it.
    def rew(a, b):
        if b > 0.7:
            return 0.5
        return 1 / 0.6 if 0.1 <= a <= 0.2 else 1.0

    r = WindowRewards(*fine_grid(rew), 1.0)
    out = landscape(r, [0.04, 0.0025], step=0.05, samples=3000, starts=[(0.5, 0.5)])
    wide, narrow = out["variances"]
    assert narrow["best_gain"] > 0.4
    assert wide["best_gain"] < narrow["best_gain"] / 4
    assert 0.1 <= narrow["best_mean"][0] <= 0.2 and narrow["best_mean"][1] < 0.7
    assert wide["starts"][0]["gain"] < 0  # the paper's start sits where exploration hits the falls


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="one reward per"):
        WindowRewards(np.zeros((2, 2)), np.zeros(3), 1.0)
    r = WindowRewards(np.array([[0.1, 0.4]]), np.array([2.0]), 1.0)
    with pytest.raises(ValueError, match="variance"):
        expected_reward(r, np.zeros((1, 2)), 0.0)


def test_landscape_command_reads_a_window_map(tmp_path, capsys):
    import json

    from drake_biped.cli import main

    rows = [{"t1": a, "t2": b, "cost_of_transport": 0.1 if a == 0.1 else None, "distance_m": 10.0 if a == 0.1 else 1.0}
            for a in (0.0, 0.1, 0.2) for b in (0.3, 0.4)]
    record = {"config": {"sim": {"distance_m": 10.0}}, "baseline": {"cost_of_transport": 0.2, "distance_m": 10.0},
              "windows": rows}
    (tmp_path / "window_map.json").write_text(json.dumps(record))
    assert main(["landscape", str(tmp_path), "--variance", "0.0001", "--samples", "200"]) == 0
    out = json.loads((tmp_path / "landscape.json").read_text())
    cell = out["variances"][0]
    assert out["no_window_reward"] == 5.0
    assert cell["best_expected_reward"] == 10.0 and cell["best_mean"][0] == 0.1
    assert (tmp_path / "landscape.png").stat().st_size > 0
    with pytest.raises(SystemExit):
        main(["landscape", str(tmp_path / "missing")])
    assert "no window map" in capsys.readouterr().err


def test_landscape_refuses_a_folder_it_cannot_write_before_computing(tmp_path, capsys, monkeypatch):
    """Without --out it writes beside the window map: that folder is checked first, not after the draws."""
    import json
    import os
    import pathlib

    from drake_biped.experiments import landscape as command
    from tests.test_failures import one_line, run_cli

    record = {"config": {"sim": {"distance_m": 10.0}}, "baseline": {"cost_of_transport": 0.2, "distance_m": 10.0},
              "windows": [{"t1": 0.1, "t2": 0.3, "cost_of_transport": 0.1, "distance_m": 10.0}]}
    (tmp_path / "window_map.json").write_text(json.dumps(record))

    def computed(*args, **kwargs):
        raise AssertionError("the landscape was computed")

    monkeypatch.setattr(command, "landscape", computed)
    if os.geteuid() == 0:  # root writes into a mode-555 folder: deny the write as the kernel would for anyone else
        write_text = pathlib.Path.write_text

        def denied(self, *args, **kwargs):
            if self.parent == tmp_path:
                raise PermissionError(13, "Permission denied")
            return write_text(self, *args, **kwargs)

        monkeypatch.setattr(pathlib.Path, "write_text", denied)
    tmp_path.chmod(0o555)
    try:
        code, lines = run_cli(capsys, ["landscape", str(tmp_path)])
    finally:
        tmp_path.chmod(0o755)
    assert code == 2
    one_line(lines, f"the window map folder '{tmp_path}'", "cannot write there (Permission denied)")
