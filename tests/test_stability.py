"""The stability experiment: its cells, section bookkeeping, the fit pipeline on data of known maps, resume."""

import json
import math

import numpy as np
import pytest

from drake_biped.analysis.stability_report import report_markdown, write_stability_outputs
from drake_biped.experiments.stability import (
    StabilitySettings,
    analyse,
    cell_configs,
    equilibrium,
    run_stability,
    section_sequence,
    trial_initial,
)
from drake_biped.params import EpisodeConfig, InitialConditions, ParameterError, SimulationParams

P = np.array([[1.0, 0.3], [-0.2, 1.5]])


def a_with(eigs):
    re = [complex(e) for e in eigs]
    if abs(re[0].imag) > 0:
        core = np.array([[re[0].real, -abs(re[0].imag)], [abs(re[0].imag), re[0].real]])
    else:
        core = np.diag([re[0].real, re[1].real])
    return P @ core @ np.linalg.inv(P)


def test_trials_vary_the_initiation_within_the_spread_reproducibly():
    base = InitialConditions()
    assert trial_initial(base, 0, 0, 0.15) == base
    others = [trial_initial(base, 0, k, 0.15) for k in range(1, 20)]
    assert others == [trial_initial(base, 0, k, 0.15) for k in range(1, 20)]
    assert len({o.speed_mps for o in others}) == 19
    for o in others:
        assert abs(o.speed_mps / base.speed_mps - 1) <= 0.15 and abs(o.hip_angle_rad / base.hip_angle_rad - 1) <= 0.15
    assert trial_initial(base, 1, 3, 0.15) != trial_initial(base, 0, 3, 0.15)


def test_six_cells_with_the_right_window_and_push():
    s = StabilitySettings(window=(0.2, 0.5), trials=3)
    jobs = cell_configs(EpisodeConfig(), s)
    assert len(jobs) == 18
    for condition, kind, _k, c in jobs:
        assert c.window.active == (condition == "with")
        if kind == "undisturbed":
            assert c.push is None
        else:
            assert c.push.force_n == (20.0 if kind == "forward" else -20.0)
            assert (c.push.start_s, c.push.duration_s) == (0.4, 0.1)
            assert c.push.force_n * c.push.duration_s == pytest.approx(math.copysign(2.0, c.push.force_n))


def test_steps_since_push_count_touchdowns_from_the_push():
    steps = [{"index": i + 1, "touchdown_time_s": t, "hip_angle_rad": 0.9 + i, "hip_rate_radps": 2.0}
             for i, t in enumerate([0.3, 0.8, 1.6, 2.4])]
    x, since = section_sequence({"steps": steps}, 0.4)
    assert x.shape == (4, 2) and since.tolist() == [-1, 0, 1, 2]
    _, since = section_sequence({"steps": steps}, None)
    assert since.tolist() == [-1, -1, -1, -1]


def _fake_results(settings, maps, x_star, seed=0):
    """Episode results whose touchdowns follow x_{n+1} - x* = A (x_n - x*) (+ small noise), per cell."""
    rng = np.random.default_rng(seed)
    out = {}
    for condition in ("without", "with"):
        for kind in ("undisturbed", "forward", "backward"):
            a = maps[condition][kind]
            for k in range(settings.trials):
                x = x_star + rng.normal(0, 0.05, 2)
                steps = []
                for n in range(20):
                    steps.append({"index": n + 1, "touchdown_time_s": 0.8 * (n + 1), "hip_angle_rad": float(x[0]),
                                  "hip_rate_radps": float(x[1]), "stance_leg": "left", "com_x_m": 0.0})
                    x = x_star + a @ (x - x_star) + rng.normal(0, 1e-4, 2)
                out[(condition, kind, k)] = {"steps": steps, "fell": False}
    return out


def test_analysis_recovers_the_eigenvalues_of_known_step_maps(tmp_path):
    s = StabilitySettings(trials=4, bootstrap=200, steady_from_step=10)
    eigs = {"without": {"undisturbed": [0.064 + 0.101j, 0.064 - 0.101j], "forward": [0.318, -0.234],
                        "backward": [0.378, -0.109]},
            "with": {"undisturbed": [-0.2, 0.129], "forward": [0.14 + 0.164j, 0.14 - 0.164j],
                     "backward": [0.326, 0.0345]}}
    maps = {c: {k: a_with(v) for k, v in d.items()} for c, d in eigs.items()}
    x_star = np.array([0.98, 2.85])
    record = {"settings": s.to_dict(), "versions": {}, "cells": analyse(_fake_results(s, maps, x_star), s)}
    for condition, d in eigs.items():
        np.testing.assert_allclose(record["cells"][condition]["equilibrium"], x_star, atol=1e-4)
        for kind, expected in d.items():
            cell = record["cells"][condition][kind]
            got = sorted((complex(*p) for p in cell["eigenvalues"]), key=lambda z: (z.real, z.imag))
            want = sorted((complex(e) for e in expected), key=lambda z: (z.real, z.imag))
            assert cell["n_pairs"] == 19 * 4  # every touchdown (from 0.8 s) follows the push (0.4 s)
            assert np.allclose([(g.real, abs(g.imag)) for g in got], [(w.real, abs(w.imag)) for w in want],
                               atol=0.02), (condition, kind, got, want)
            assert cell["stable"] and cell["spectral_radius_ci"][0] < cell["spectral_radius"] < cell["spectral_radius_ci"][1]
    paths = write_stability_outputs(record, tmp_path)
    assert all(p.stat().st_size > 0 for p in paths)
    md = report_markdown(record)
    assert md.count("stable (ρ < 1)") == 6 and "0.064+0.101i" in md


def test_equilibrium_needs_steady_touchdowns():
    with pytest.raises(ValueError, match="walk further"):
        equilibrium([{"steps": [{"index": 1, "hip_angle_rad": 1.0, "hip_rate_radps": 2.0}]}], 6)


def test_bad_settings_are_refused():
    with pytest.raises(ParameterError, match="window"):
        StabilitySettings(window=(0.5, 0.2))
    with pytest.raises(ParameterError, match="trials"):
        StabilitySettings(trials=0)
    with pytest.raises(ParameterError, match="spread"):
        StabilitySettings(spread=0.7)


@pytest.mark.slow
def test_a_rerun_recomputes_nothing(tmp_path):
    from drake_biped.experiments.executor import dask_client

    base = EpisodeConfig(sim=SimulationParams(distance_m=1.2, max_time_s=6.0))
    s = StabilitySettings(trials=1, steady_from_step=1, bootstrap=0)
    seen = []
    with dask_client(workers=1) as client:
        first = run_stability(tmp_path, base, s, client)
        stamps = {p.name: p.stat().st_mtime_ns for p in (tmp_path / "episodes").iterdir()}
        again = run_stability(tmp_path, base, s, client, progress=lambda d, t: seen.append((d, t)))
    assert len(stamps) == 6 + 6  # six cells' episodes, and the Jacobian at 3 kick sizes per condition
    # 1.2 m is too short for the Jacobian at touchdown 8: recorded as such, not a crash
    assert all("walk further" in j["error"] for c in ("without", "with") for j in first["jacobian"][c])
    assert {p.name: p.stat().st_mtime_ns for p in (tmp_path / "episodes").iterdir()} == stamps
    assert seen == [(6, 6)]
    assert json.dumps(first["cells"], sort_keys=True) == json.dumps(again["cells"], sort_keys=True)


class _ThresholdClient:
    """Stands in for a Dask client: an episode survives when its push is below a threshold per cell."""

    def __init__(self, limits):
        self.limits = limits
        self.calls = 0

    def submit(self, fn, config, pure=False):
        self.calls += 1
        force = config["push"]["force_n"]
        cell = ("with" if config["window"]["end_s"] > config["window"]["start_s"] else "without",
                "forward" if force > 0 else "backward")
        fell = abs(force) > self.limits[cell]
        return {"fell": fell, "distance_m": 2.0 if fell else 10.0, "fall_reason": "pitch" if fell else ""}

    def gather(self, futures):
        return futures


def test_push_margin_brackets_each_threshold_within_the_tolerance():
    from drake_biped.experiments.push_margin import push_margin

    limits = {("without", "forward"): 37.3, ("without", "backward"): 61.0,
              ("with", "forward"): 12.25, ("with", "backward"): 250.0}
    client = _ThresholdClient(limits)
    out = push_margin(EpisodeConfig(), (0.2, 0.5), client, max_force_n=200.0, tolerance_n=0.5)
    for (condition, direction), limit in limits.items():
        m = out["margins"][condition][direction]
        if limit >= 200.0:
            assert m["survived_n"] == 200.0 and m["fell_n"] is None
        else:
            assert m["survived_n"] <= limit < m["fell_n"] and m["fell_n"] - m["survived_n"] <= 0.5
            assert m["impulse_ns"] == pytest.approx(0.1 * m["survived_n"])
    assert client.calls <= 4 * (1 + math.ceil(math.log2(200 / 0.5)))


class _Done:
    def __init__(self, value):
        self.value = value

    def result(self):
        return self.value


class _LinearStepClient:
    """Stands in for a Dask client running walks whose touchdown 8 responds to a swing-hip kick through M
    and whose touchdown 9 follows touchdown 8 through J (plus optional jumps)."""

    def __init__(self, m, j, x0, y0, jump=0.0):
        self.m, self.j, self.x0, self.y0, self.jump = m, j, x0, y0, jump
        self.rng = np.random.default_rng(0)

    def submit(self, fn, config, kick=None, pure=False):
        d = np.zeros(2) if kick is None else self.m @ [kick["hip_angle_rad"], kick["hip_rate_radps"]]
        x = self.x0 + d
        y = self.y0 + self.j @ d + (self.jump * self.rng.standard_normal(2) if kick else 0.0)
        steps = [{"index": 7, "touchdown_time_s": 5.6, "hip_angle_rad": 1.0, "hip_rate_radps": 3.0}]
        steps += [{"index": i, "touchdown_time_s": t, "hip_angle_rad": float(s[0]), "hip_rate_radps": float(s[1])}
                  for i, t, s in ((8, 6.4, x), (9, 7.2, y))]
        return _Done({"steps": steps, "fell": False})

    def gather(self, futures):
        return [f.result() for f in futures]


def test_finite_difference_jacobian_recovers_a_known_step_map():
    from drake_biped.experiments.stability import finite_difference_jacobian

    j_true = a_with([0.3 + 0.2j, 0.3 - 0.2j])
    m = np.array([[0.8, 0.05], [-2.0, 0.9]])  # a kick moves both section coordinates
    client = _LinearStepClient(m, j_true, np.array([0.98, 2.85]), np.array([0.98, 2.85]))
    fd = finite_difference_jacobian(EpisodeConfig(), client, step=8, angle_rad=0.005, rate_radps=0.05)
    np.testing.assert_allclose(fd["jacobian"], j_true, atol=1e-9)
    assert fd["spectral_radius"] == pytest.approx(abs(0.3 + 0.2j), abs=1e-9)
    assert fd["relative_residual"] < 1e-9 and fd["kicks_lost"] == 0
    assert fd["kick_time_s"] == pytest.approx(6.4 - 0.03)
    # Jumps as large as the response leave most of it unexplained, and the residual says so.
    noisy = finite_difference_jacobian(EpisodeConfig(), _LinearStepClient(m, j_true, client.x0, client.y0, jump=0.01),
                                       step=8, angle_rad=0.005, rate_radps=0.05)
    assert noisy["relative_residual"] > 0.3


def test_policy_option_takes_the_best_learned_window(tmp_path, capsys):
    from drake_biped.cli import _policy_window, main

    learned = [{"trial": 0, "t1": 0.5, "t2": 0.3, "cost_of_transport": 0.221, "fell": False},
               {"trial": 1, "t1": 0.14, "t2": 0.30, "cost_of_transport": 0.144, "fell": False},
               {"trial": 2, "t1": 0.08, "t2": 0.27, "cost_of_transport": 0.154, "fell": False},
               {"trial": 3, "t1": 0.1, "t2": 0.8, "cost_of_transport": 0.1, "fell": True}]
    path = tmp_path / "learning.json"
    path.write_text(json.dumps({"evaluation": {"learned": learned}}))
    assert _policy_window(path) == (0.14, 0.30)
    path.write_text(json.dumps({"evaluation": {"learned": learned[:1]}}))
    with pytest.raises(SystemExit):
        main(["stability", "--policy", str(path), "--out", str(tmp_path / "s")])
    assert "no trial learned a torque-free period" in capsys.readouterr().err


def test_a_cell_whose_trials_fall_is_not_called_stable():
    s = StabilitySettings(trials=3, bootstrap=0, steady_from_step=10)
    maps = {c: {k: a_with([0.3, -0.1]) for k in ("undisturbed", "forward", "backward")} for c in ("without", "with")}
    results = _fake_results(s, maps, np.array([0.98, 2.85]))
    results[("with", "backward", 1)]["fell"] = True
    cells = analyse(results, s)
    assert cells["with"]["backward"]["spectral_radius_below_one"] and not cells["with"]["backward"]["stable"]
    assert cells["with"]["forward"]["stable"]
    md = report_markdown({"settings": s.to_dict(), "versions": {}, "cells": cells})
    assert "not stable: 1 of 3 trials fell" in md
