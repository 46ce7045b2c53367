"""The stability experiment: its cells, section bookkeeping, the fit pipeline on data of known maps, resume."""

import json
import math

import numpy as np
import pytest
from walkers import fast_config

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
    jobs = cell_configs(fast_config(), s)
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


def test_a_short_distance_is_refused_once_with_the_distance_that_is_enough():
    """The distance named is enough for every touchdown the analysis needs, so it is accepted when given."""
    import re

    def refusal(distance_m, kicks=(0.005,)):
        config = fast_config().override({"sim.distance_m": distance_m})
        try:
            StabilitySettings(trials=1, config=config, jacobian_kicks=kicks).check_walks_reach()
        except ParameterError as exc:
            return str(exc)
        return None

    first = refusal(2.0)
    enough = float(re.search(r"walk at least ([\d.]+) m", first).group(1))
    assert "touchdown 9" in first and refusal(enough) is None
    assert f"walk at least {enough:g} m" in refusal(enough - 1.0)
    assert "needs touchdown 6" in refusal(2.0, kicks=())  # without the Jacobian, the equilibrium's touchdowns


def test_the_window_compared_is_the_walked_gaits_and_named_or_the_command_asks_for_one(tmp_path, capsys):
    """Stability and push-margin compare the window of the gait they walk, from its file, and print where it
    comes from; a gait that declares none is refused (exit 2) with what to give, never given another's."""
    from drake_biped.cli import build_parser
    from drake_biped.experiments import push_margin, stability
    from drake_biped.params import DEFAULT_WINDOW_S
    from drake_biped.resources import gait_compare_window, gait_path

    def settings(*argv):
        args = build_parser().parse_args([*argv, "--out", str(tmp_path / "o")])
        return (stability if argv[0] == "stability" else push_margin).settings_from_args(args)

    for command in ("stability", "push-margin"):
        paper = settings(command, "--params", "paper")
        assert paper.window == (0.1, 0.2) and "window map" in paper.window_source
        gait, window = capsys.readouterr().out.splitlines()
        assert gait.startswith("gait: paper (sha256 ")  # every command that walks a gait names it first
        assert window.startswith("window 0.1-0.2 s: the cheapest window of this gait's window map")
        assert settings(command).window == DEFAULT_WINDOW_S == (0.1, 0.2)  # no --params: the paper's walker's
        assert capsys.readouterr().out.rstrip().endswith("(gait file paper)")  # no --params: the paper's walker
        fast = settings(command, "--params", "fast_servo")
        assert fast.window == gait_compare_window("fast_servo")[0] == (0.3672, 0.8629)
        assert "learned" in capsys.readouterr().out
        with pytest.raises(ParameterError, match="--params paper_servo: the gait declares no window.*--t1 and --t2"):
            settings(command, "--params", "paper_servo")
        assert settings(command, "--params", "paper_servo", "--t1", "0.2", "--t2", "0.3").window == (0.2, 0.3)
        assert capsys.readouterr().out.splitlines()[-1] == "window 0.2-0.3 s: --t1/--t2"
    # the key is no parameter of the walk: the file still reads as a configuration
    assert EpisodeConfig.from_dict(json.loads(gait_path("paper").read_text())).window.active is False
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"compare_window": {"start_s": 0.3, "end_s": 0.2, "source": "x"}}))
    with pytest.raises(ParameterError, match="compare_window: start_s 0.3, end_s 0.2"):
        gait_compare_window(bad)


@pytest.mark.slow
def test_a_rerun_recomputes_nothing(tmp_path):
    from drake_biped.common.executor import dask_client

    base = fast_config(sim=SimulationParams(distance_m=1.2, max_time_s=6.0))
    s = StabilitySettings(trials=1, steady_from_step=1, bootstrap=0)
    seen = []
    with dask_client(workers=1) as client:
        first = run_stability(tmp_path, base, s, client)
        stamps = {str(p): p.stat().st_mtime_ns for p in (tmp_path / "episodes").rglob("*.json")}
        again = run_stability(tmp_path, base, s, client, progress=lambda d, t: seen.append((d, t)))
    # six cells' episodes, the Jacobian at 3 kick sizes per condition, and each Jacobian's reference walk
    assert len(stamps) == 6 + 6 + 6
    assert (tmp_path / "episodes" / "jacobian_with_0.01" / "reference.json").is_file()
    # 1.2 m is too short for the Jacobian at touchdown 8: recorded as such, not a crash
    assert all("walk further" in j["error"] for c in ("without", "with") for j in first["jacobian"][c])
    assert {str(p): p.stat().st_mtime_ns for p in (tmp_path / "episodes").rglob("*.json")} == stamps
    assert seen == [(6, 6)]
    assert json.dumps(first["cells"], sort_keys=True) == json.dumps(again["cells"], sort_keys=True)


def test_push_margin_is_the_largest_force_every_phase_survives_however_survival_varies(monkeypatch):
    """A survival that is not monotone in the force (the backward push without the window falls at 20-25 N at
    one phase only, and survives again above): the margin is the largest grid force at and below which every
    phase survives, every force of the grid is walked at every phase, and the pushes land in the first step
    that starts after the settling time, at its phases."""
    from drake_biped.common import executor
    from drake_biped.experiments import push_margin

    def fake_map(client, fn, items, progress=None):
        out = []
        for c in items:
            steps = [{"touchdown_time_s": 0.43 * k} for k in range(30)]
            push = c["push"]
            cond = "with" if c["window"]["end_s"] > c["window"]["start_s"] else "without"
            fell = False
            if push is not None:
                f, start = push["force_n"], push["start_s"]
                phase = round((start - 5.16) / 0.43 * 4) if start >= 5.16 else -1
                assert 0 <= phase < 4, start
                if cond == "without" and f < 0 and 20 <= -f <= 25 and phase == 2:
                    fell = True
                if cond == "with" and f > 0 and f >= 35:
                    fell = True
            out.append({"fell": fell, "distance_m": 3.0 if fell else 12.0, "steps": steps})
        return out

    monkeypatch.setattr(executor, "map_ordered", fake_map)
    settings = push_margin.PushMarginSettings(fast_config().override({"sim.distance_m": 12.0}), (0.2, 0.5),
                                              max_force_n=40.0, force_step_n=5.0, phases=4, settle_s=5.0)
    assert settings.forces == [5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0] and settings.episodes == 128
    record = push_margin.push_margin(settings, client=None)
    m = record["margins"]
    assert m["without"]["step_s"] == pytest.approx([5.16, 5.59])  # the first step to start at or after 5 s
    assert m["without"]["backward"]["margin_n"] == 15.0 and m["without"]["forward"]["margin_n"] == 40.0
    assert m["without"]["backward"]["survived"][-1] == [True] * 4  # survives again above the margin
    assert m["with"]["forward"]["margin_n"] == 30.0 and m["with"]["backward"]["margin_n"] == 40.0
    assert push_margin.margin_of([5.0, 10.0], [[False, True], [True, True]]) == 0.0
    from drake_biped.analysis.push_margin_report import markdown

    text = markdown(record)
    assert "the first above the margin: 20 N at phase 2/4" in text


def test_a_push_margin_map_beyond_its_limit_is_refused_before_any_work():
    from drake_biped.experiments.push_margin import PushMarginSettings

    with pytest.raises(ParameterError, match=r"push margin: 8000 pushed walks .* above 5000; .*--force"):
        PushMarginSettings(max_force_n=100.0, force_step_n=1.0, phases=20)
    assert PushMarginSettings(max_force_n=100.0, force_step_n=1.0, phases=20, force=True).episodes == 8000


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
    fd = finite_difference_jacobian(fast_config(), client, step=8, angle_rad=0.005, rate_radps=0.05)
    np.testing.assert_allclose(fd["jacobian"], j_true, atol=1e-9)
    assert fd["spectral_radius"] == pytest.approx(abs(0.3 + 0.2j), abs=1e-9)
    assert fd["relative_residual"] < 1e-9 and fd["kicks_lost"] == 0
    assert fd["kick_time_s"] == pytest.approx(6.4 - 0.03)
    # Jumps as large as the response leave most of it unexplained, and the residual says so.
    noisy = finite_difference_jacobian(fast_config(), _LinearStepClient(m, j_true, client.x0, client.y0, jump=0.01),
                                       step=8, angle_rad=0.005, rate_radps=0.05)
    assert noisy["relative_residual"] > 0.3


def test_policy_option_takes_the_best_learned_window(tmp_path, capsys):
    from drake_biped.cli import main
    from drake_biped.common.options import policy_window as _policy_window

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
