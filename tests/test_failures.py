"""Every failure is one line: bad input exits 2 naming the option, file or value; a failed run exits 1; Ctrl-C
exits 130 saying how to resume; no traceback unless asked for; nothing already on disk is lost."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from drake_biped.cli import main
from drake_biped.common.options import gait_line
from drake_biped.params import EpisodeConfig, ParameterError
from drake_biped.resources import gait_identity


def run_cli(capsys, argv):
    """(exit code, stderr lines) of one command run in this process."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    err = capsys.readouterr().err
    return stop.value.code, [line for line in err.splitlines() if line.strip()]


def one_line(lines, *expected):
    assert len(lines) == 1, lines
    assert "Traceback" not in lines[0]
    for text in expected:
        assert text in lines[0], (text, lines[0])
    return lines[0]


@pytest.fixture()
def files(tmp_path):
    """Broken and odd input files."""
    f = {}
    for name, text in {"list.json": "[1, 2]", "section.json": '{"cpg": "fast"}', "bad.json": '{"cpg": {',
                       "unknown.json": '{"cpg": {"u_q": 1}}', "range.json": '{"cpg": {"alpha": 9}}',
                       "spec_bad.yaml": "axes: [", "spec_axis.yaml": "axes: {nope: {values: [1]}}",
                       "notamap.json": '{"config": {}}', "a_file": "x",
                       "spec_big.yaml": "axes: {u_a: {min: 1, max: 2, points: 400}, u_r: {min: 3, max: 5, points: 400}}",
                       "spec_noop.yaml": "axes: {t1: {values: [0.1, 0.2]}, u_a: {values: [2.3, 2.4]}}"
                       }.items():
        (tmp_path / name).write_text(text)
        f[name] = str(tmp_path / name)
    return f


BAD = [  # (argv with {tmp} and {file:NAME}, texts the one line must hold)
    (["walk", "--out", ""], ["--out", "empty path"]),
    (["walk", "--out", "{file:a_file}"], ["--out", "is a file"]),
    (["walk", "--out", "/proc/no/such/place"], ["--out", "cannot write there"]),
    (["walk", "--distance", "-1", "--out", "{tmp}/w"], ["--distance", "'-1'"]),
    (["walk", "--distance", "far", "--out", "{tmp}/w"], ["--distance", "'far'"]),
    (["walk", "--time-step", "0.5", "--out", "{tmp}/w"], ["time_step_s", "0.5"]),
    (["walk", "--params", "{tmp}/none.json", "--out", "{tmp}/w"], ["--params", "none.json"]),
    (["walk", "--params", "{file:list.json}", "--out", "{tmp}/w"], ["--params", "list.json", "got list"]),
    (["walk", "--params", "{file:section.json}", "--out", "{tmp}/w"], ["section 'cpg'", "got str 'fast'"]),
    (["walk", "--params", "{file:bad.json}", "--out", "{tmp}/w"], ["bad.json", "not valid JSON"]),
    (["walk", "--params", "{file:unknown.json}", "--out", "{tmp}/w"], ["unknown parameter", "u_q"]),
    (["walk", "--params", "{file:range.json}", "--out", "{tmp}/w"], ["range.json, section 'cpg'", "CpgParams.alpha = 9.0", "[-2, 2]"]),
    (["walk", "--params", "climbin", "--out", "{tmp}/w"], ["--params 'climbin'", "climbing"]),
    (["compare-learners", "--window-map", "{tmp}/nomap", "--out", "{tmp}/c"], ["--window-map", "nomap",
                                                                              "run drake-biped window-map"]),
    (["compare-learners", "--window-map", "{tmp}", "--learners", "garb,sgd", "--out", "{tmp}/c"],
     ["--learners", "'garb,sgd'", "cmaes"]),
    (["learn", "--learner", "sgd", "--out", "{tmp}/l"], ["--learner", "'sgd'"]),
    (["walk", "--t1", "0.5", "--out", "{tmp}/w"], ["--t1 and --t2"]),
    (["walk", "--t1", "0.5", "--t2", "0.2", "--out", "{tmp}/w"], ["--t1 0.5 --t2 0.2", "no torque-free window"]),
    (["walk", "--push", "20", "--push-start", "100", "--out", "{tmp}/w"], ["Push.start_s = 100.0", "never act"]),
    (["walk", "--push-start", "1", "--out", "{tmp}/w"], ["give --push"]),
    (["walk", "--slope", "0.5", "--out", "{tmp}/w"], ["slope_rad", "0.5"]),
    (["walk", "--seed", "-1", "--out", "{tmp}/w"], ["--seed", "'-1'"]),
    (["walk", "--no-such-option", "--out", "{tmp}/w"], ["unrecognized arguments: --no-such-option"]),
    (["fly", "--out", "{tmp}/w"], ["invalid choice: 'fly'"]),
    (["window-map", "--t1-max", "0", "--t2-max", "0.05", "--step", "0.1", "--out", "{tmp}/wm"], ["--t1-max 0 --t2-max 0.05",
                                                                                  "no window fits"]),
    (["window-map", "--step", "0", "--out", "{tmp}/wm"], ["--step", "'0'"]),
    (["grid", "--spec", "{tmp}/none.yaml", "--out", "{tmp}/g"], ["--spec", "none.yaml"]),
    (["grid", "--spec", "{file:spec_bad.yaml}", "--out", "{tmp}/g"], ["spec_bad.yaml", "not valid YAML"]),
    (["grid", "--spec", "{file:spec_axis.yaml}", "--out", "{tmp}/g"], ["grid axis 'nope'"]),
    (["grid", "--spec", "tiny", "--points-per-axis", "2", "--out", "{tmp}/g"], ["either --spec or --points-per-axis"]),
    (["learn", "--trials", "0", "--out", "{tmp}/l"], ["--trials", "'0'"]),
    (["learn", "--variance", "0", "--out", "{tmp}/l"], ["--variance", "'0'"]),
    (["learn", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1", "--out", "{tmp}/l"], ["--workers",
                                                                                           "--scheduler"]),
    (["learn", "--scheduler", "localhost", "--out", "{tmp}/l"], ["--scheduler 'localhost'", "tcp://HOST:PORT"]),
    (["stability", "--t1", "0.5", "--t2", "0.2", "--out", "{tmp}/s"], ["--t1 0.5 --t2 0.2", "t1 < t2"]),
    (["stability", "--policy", "{tmp}/none.json", "--out", "{tmp}/s"], ["--policy", "none.json"]),
    (["push-margin", "--force-step", "0", "--out", "{tmp}/p"], ["--force-step", "'0'"]),
    (["push-margin", "--force-step", "150", "--out", "{tmp}/p"], ["--force-step 150", "--max-force 100"]),
    (["slope", "--out", "{tmp}/sl"], ["required: --slope"]),
    (["slope", "--slope", "-0.1", "--out", "{tmp}/sl"], ["--slope -0.1", "> 0"]),
    (["slope", "--slope", "0.02", "--policy", "{file:notamap.json}", "--out", "{tmp}/sl"], ["notamap.json",
                                                                                            "learning record"]),
    (["landscape", "{tmp}/none"], ["no window map", "none"]),
    (["landscape", "{file:notamap.json}"], ["notamap.json", "not a window map"]),
    (["figures", "{tmp}"], ["learning.json"]),
    (["time-step-study", "--steps", "0.001,0.002", "--reference", "0.003", "--out", "{tmp}/t"],
     ["--reference 0.003", "one of --steps"]),
    (["time-step-study", "--replot", "--out", "{tmp}/t"], ["--replot", "time_step_study.json"]),
    (["gait-search", "--sigma", "-1", "--out", "{tmp}/gs"], ["--sigma", "'-1'"]),
    # runaway sizes, refused before anything is built or started (1000^7 points once died of memory)
    (["grid", "--points-per-axis", "1000", "--out", "{tmp}/g"],
     ["--points-per-axis 1000: the grid has 1,000,000,000,000,000,000,000 points (1000 x 1000 x", "limit of 20,000",
      "--force to run it anyway"]),
    (["grid", "--spec", "{file:spec_big.yaml}", "--out", "{tmp}/g"],
     ["spec_big.yaml: the grid has 160,000 points (400 x 400)", "limit of 20,000", "--force"]),
    (["learn", "--workers", "1000", "--out", "{tmp}/l"],
     ["--workers 1000: more local worker processes than this machine holds (limit ", "per core", "--force"]),
    (["window-map", "--workers", "100000", "--out", "{tmp}/wm"], ["--workers 100000", "--force"]),
    (["landscape", "{tmp}/none", "--samples", "1000000000", "--out", "{tmp}/ls"],
     ["--samples 1,000,000,000", "GiB in memory"]),
    # input that cannot give an answer, refused before any walk
    (["stability", "--trials", "2", "--distance", "3", "--out", "{tmp}/s"],
     ["--distance 3", "needs touchdown 9", "walk at least"]),
    (["time-step-study", "--steps", "0.002,0.001", "--distance", "3", "--out", "{tmp}/t"],
     ["--distance 3", "long-run means", "110 m"]),
    (["time-step-study", "--steps", "0.001,0.001", "--out", "{tmp}/t"], ["--steps 0.001,0.001", "twice"]),
    # options that change nothing
    (["bifurcation", "--param", "t1", "--from", "0.2", "--to", "0.3", "--num", "2", "--out", "{tmp}/b"],
     ["--param t1 --from 0.2 --to 0.3", "never opens", "--t2"]),
    (["bifurcation", "--param", "u_a", "--from", "2", "--to", "2.5", "--num", "2", "--second-time-step", "0.0005",
      "--out", "{tmp}/b"], ["--second-time-step 0.0005", "same result"]),
    (["grid", "--spec", "{file:spec_noop.yaml}", "--out", "{tmp}/g"], ["axis window.start_s", "changes nothing"]),
    (["walk", "--level-length", "2", "--out", "{tmp}/w"], ["--level-length 2", "changes nothing"]),
    (["walk", "--push", "0", "--out", "{tmp}/w"], ["--push 0", "changes nothing"]),
    (["learn", "--rewalk-distance", "1000000", "--out", "{tmp}/l"], ["--rewalk-distance 1e+06", "distance_m"]),
    (["floquet", "--settle-steps", "1000000000", "--out", "{tmp}/f"], ["--settle-steps 1000000000", "limit of 1,000"]),
    (["floquet", "--regression-samples", "5", "--out", "{tmp}/f"], ["regression_samples 5", "at least 20"]),
    (["floquet", "--regression-samples", "40", "--regression-sizes", "0.01", "--out", "{tmp}/f"],
     ["--regression-sizes", "'0.01'", "at least three"]),
    (["walk", "--max-time", "100000", "--out", "{tmp}/w"], ["--max-time", "GiB of logs"]),
    (["walk", "--push", "20", "--push-duration", "0", "--out", "{tmp}/w"], ["--push-duration", "must be > 0"]),
]


@pytest.mark.parametrize("argv, expected", BAD, ids=[" ".join(a[:3]) for a, _ in BAD])
def test_bad_input_is_one_line_naming_it_with_exit_code_2(tmp_path, files, capsys, argv, expected):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    argv = [files[a[6:-1]] if a.startswith("{file:") else a for a in argv]
    before = sorted(p.name for p in tmp_path.iterdir())
    code, lines = run_cli(capsys, argv)
    assert code == 2
    one_line(lines, *expected)
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written, no --out folder left


@pytest.mark.parametrize("name, text, message", [
    ("broken.urdf", "<robot name='x'><link name='a'></robot>", "could not parse the model broken.urdf"),
    ("empty.urdf", "<robot name='x'><link name='a'/></robot>", "the model has no joint named"),
    ("missing.urdf", None, "--model '{path}': no such file"),
    ("robot.obj", "v 0 0 0", "--model '{path}': not a .urdf or .sdf file"),
])
def test_a_broken_model_is_one_line(tmp_path, capsys, name, text, message):
    path = tmp_path / name
    if text is not None:
        path.write_text(text)
    code, lines = run_cli(capsys, ["walk", "--model", str(path), "--distance", "0.1", "--no-animation",
                                   "--out", str(tmp_path / "w")])
    assert code == 2
    one_line(lines, message.format(path=path))
    assert not (tmp_path / "w").exists()


def _with_torso_mesh(tmp_path, uri: str, name: str) -> Path:
    """The shipped URDF with a visual mesh `uri` on the torso, as `name` in tmp_path (an .sdf: as SDFormat)."""
    from sdf_of_urdf import urdf_to_sdf

    from drake_biped.resources import shipped_model_file

    text = shipped_model_file().read_text()
    text = text.replace('<link name="torso">', f'<link name="torso"><visual><geometry><mesh filename="{uri}"/>'
                                               '</geometry></visual>', 1)
    if name.endswith(".sdf"):
        text = urdf_to_sdf(text)
        text = text.replace('<link name="torso">', f'<link name="torso"><visual name="look"><geometry><mesh><uri>{uri}'
                                                   '</uri></mesh></geometry></visual>', 1)
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", ["mine.urdf", "mine.sdf"])
@pytest.mark.parametrize("uri, message", [
    ("meshes/nope.obj", "names the file 'meshes/nope.obj', which does not exist: looked for {tmp}/meshes/nope.obj "
                        "(in the model file's folder)"),
    ("package://nopkg/box.obj", "names the file 'package://nopkg/box.obj' in the package 'nopkg', which is unknown: "
                                "the model file's folder {tmp} has no package.xml"),
    ("package://drake_biped/nope.obj", "names the file 'package://drake_biped/nope.obj', which does not exist: "
                                       "looked for "),
])
def test_a_models_missing_file_is_one_line_naming_it_and_where_it_was_looked_for(tmp_path, capsys, name, uri,
                                                                                    message):
    path = _with_torso_mesh(tmp_path, uri, name)
    code, lines = run_cli(capsys, ["walk", "--model", str(path), "--distance", "0.1", "--no-animation",
                                   "--out", str(tmp_path / "w")])
    assert code == 2
    line = one_line(lines, f"the model {name} " + message.format(tmp=tmp_path.resolve()))
    assert "invalid when parsing a string" not in line
    assert not (tmp_path / "w").exists()


def test_a_failed_run_is_one_line_with_exit_code_1_and_a_traceback_on_request(tmp_path, capsys, monkeypatch):
    from drake_biped.experiments import walk

    def broken(*args, **kwargs):
        raise RuntimeError("the disk is full")

    monkeypatch.setattr(walk, "run", broken)
    argv = ["walk", "--out", str(tmp_path / "w")]
    code, lines = run_cli(capsys, argv)
    assert code == 1
    one_line(lines, "failed: RuntimeError: the disk is full", "--debug")
    with pytest.raises(RuntimeError, match="the disk is full"):
        main([*argv, "--debug"])
    monkeypatch.setenv("DRAKE_BIPED_DEBUG", "1")
    with pytest.raises(RuntimeError, match="the disk is full"):
        main(argv)


def _learn(tmp_path, episodes=2):
    return ["learn", "--trials", "1", "--episodes", str(episodes), "--distance", "0.5", "--rewalk-distance", "0.5",
            "--workers", "1", "--out", str(tmp_path / "l")]


def _api_cases():
    import numpy as np

    import drake_biped as db
    from drake_biped.common.learning_runs import LearningSettings
    from drake_biped.experiments.bifurcation import BifurcationSettings
    from drake_biped.experiments.gait_search import GaitSearchSettings
    from drake_biped.experiments.grid import Axis, GridSettings
    from drake_biped.experiments.landscape import LandscapeSettings
    from drake_biped.experiments.stability import StabilitySettings
    from drake_biped.experiments.time_step import TimeStepSettings
    from drake_biped.experiments.window_map import WindowMapSettings

    return [
        (lambda: db.EpisodeConfig(cpg={"u_a": 1.0}), db.ParameterError, "EpisodeConfig.cpg must be a CpgParams"),
        (lambda: db.CpgParams(u_a="fast"), db.ParameterError, "CpgParams.u_a must be a number, got 'fast'"),
        (lambda: db.EpisodeConfig().override({"gait.nope": 1}), db.ParameterError, "'gait.nope' is not"),
        (lambda: db.TorqueFreeWindow(start_s=-1.0), db.ParameterError, "TorqueFreeWindow.start_s = -1.0"),
        (lambda: db.EpisodeConfig.from_dict([1]), db.ParameterError, "expected a mapping of EpisodeConfig"),
        (lambda: db.EpisodeConfig.from_dict({"sim": {"time_step_s": 0.001, "control_period_s": 0.0015}}),
         db.ParameterError, "whole multiple"),
        (lambda: db.load_gait("nope"), db.ParameterError, "--params 'nope'"),
        (lambda: db.Push(force_n=1e6), db.ParameterError, "Push.force_n = 1000000.0"),
        (lambda: db.SimulationParams(contact_approximation="soft"), db.ParameterError, "'soft' is not one of"),
        (lambda: db.GarbLearner(variance=0.0), ValueError, "variance must be a finite number > 0"),
        (lambda: db.fit_return_map([np.zeros((2, 2))]), ValueError, "needs at least 3 pairs"),
        (lambda: WindowMapSettings(t1_max_s=0.0, t2_max_s=0.05, t1_step_s=0.1, t2_step_s=0.1), db.ParameterError, "no window fits"),
        (lambda: TimeStepSettings(steps=(0.001,), reference_s=0.002), db.ParameterError, "--reference 0.002"),
        (lambda: StabilitySettings(window=(0.5, 0.2)), db.ParameterError, "need 0 <= t1 < t2"),
        (lambda: GaitSearchSettings(generations=0), db.ParameterError, "generations (0)"),
        (lambda: db.EpisodeConfig(push=db.Push(20.0, start_s=70.0)), db.ParameterError, "would never act"),
        # the API bounds sizes and refuses what cannot answer or changes nothing, as the command line does
        (lambda: LandscapeSettings("m", samples=10**9), db.ParameterError, "GiB in memory"),
        (lambda: LandscapeSettings("m", variances=(float("nan"),)), db.ParameterError, "--variance"),
        (lambda: LearningSettings(trials=10, episodes=10**6), db.ParameterError, "10,000,000 episodes"),
        (lambda: TimeStepSettings(distance_m=3.0), db.ParameterError, "long-run means"),
        (lambda: StabilitySettings(config=db.EpisodeConfig().override({"sim.distance_m": 3.0})).check_walks_reach(),
         db.ParameterError, "needs touchdown 6"),
        (lambda: BifurcationSettings(param="t1", values=(0.2, 0.3)), db.ParameterError, "never opens"),
        (lambda: GridSettings(axes=(Axis("window.start_s", (0.1, 0.2)),)), db.ParameterError, "changes nothing"),
        (lambda: db.EpisodeConfig(push=db.Push(20.0, duration_s=0.0)), db.ParameterError, "never act"),
        (lambda: db.reward(float("nan"), 10.0, 10.0), ValueError, "NaN"),
        (lambda: db.cost_of_transport(float("nan"), 10.0, 1.0), ValueError, "positive_work_j"),
    ]


@pytest.mark.parametrize("k", range(16))
def test_bad_values_through_the_api_raise_naming_them(k):
    make, error, text = _api_cases()[k]
    with pytest.raises(error) as caught:
        make()
    assert text in str(caught.value) and "\n" not in str(caught.value)


def test_a_damaged_grid_point_line_is_named_and_recomputed(tmp_path, capsys):
    from drake_biped.experiments.grid import read_points

    store = tmp_path / "points.jsonl"
    store.write_text('{"key": "a", "distance_m": 1.0}\n{"key": "b", "dist\n{"key": "c", "distance_m": 2.0}\n{"ke')
    damaged = store.read_text()
    assert sorted(read_points(store)) == ["a", "c"]
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "points.jsonl has 2 line(s) that do not read as a grid point record (line 2, 4" \
        in err and "kept as points.jsonl.broken" in err
    assert (tmp_path / "points.jsonl.broken").read_text() == damaged  # set aside as it was
    assert [json.loads(line)["key"] for line in store.read_text().splitlines()] == ["a", "c"]


def _drawn_ground(ground):
    """{name: ((x, z) of the top face's back end, (x, z) of its front end)} of the ground's visual boxes."""
    import numpy as np
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.model import add_biped

    handles = add_biped(DiagramBuilder(), ground, 1e-3)
    inspector = handles.scene_graph.model_inspector()
    boxes = {}
    for geometry in handles.plant.GetVisualGeometriesForBody(handles.plant.world_body()):
        name, box, pose = inspector.GetName(geometry), inspector.GetShape(geometry), inspector.GetPoseInFrame(geometry)
        if "mark" in name:
            continue
        ends = [pose.translation() + pose.rotation().matrix() @ np.array([s * box.width() / 2, 0, box.height() / 2])
                for s in (-1, 1)]
        boxes[name] = tuple((float(e[0]), float(e[2])) for e in ends)
    return boxes


@pytest.mark.parametrize("level_length", [None, 0.0, 60.5, 100.0, 1000.0])
def test_the_drawn_ground_covers_every_accepted_level_length(level_length):
    # It stopped at 60 m: a level part longer than that asked Drake for a Box of negative width (a crash).
    from drake_biped.params import Ground

    ground = Ground(slope_rad=0.02, level_length_m=level_length)
    boxes = sorted(_drawn_ground(ground).values())
    assert boxes[0][0][0] == pytest.approx(-5.0) and boxes[-1][1][0] >= (level_length or 0.0) + 60.0 - 1e-9
    for (back, front), nxt in zip(boxes, [*boxes[1:], None]):
        for x, z in (back, front):  # the drawn surface is the ground itself
            assert z == pytest.approx(ground.height(x), abs=1e-9)
        if nxt is not None:
            assert nxt[0][0] == pytest.approx(front[0])  # no gap between the level and the sloped part


def test_a_failed_drake_check_is_a_drake_failure_through_the_api_and_one_line_on_the_command_line(
        tmp_path, capsys, monkeypatch):
    """pydrake raises a failed DRAKE_DEMAND as SystemExit, which `except Exception` misses: the API, the Dask
    episode task and the command line raise or report it as DrakeFailure (a RuntimeError) naming the call."""
    from collections import OrderedDict

    from pydrake.common import trigger_an_assertion_failure

    import drake_biped as db
    from drake_biped import episode, model
    from drake_biped.common.executor import episode_task

    monkeypatch.setattr(model, "_add_ground", lambda plant, ground, contact: trigger_an_assertion_failure())
    monkeypatch.setattr(episode._CACHE, "_entries", OrderedDict())  # no diagram built before this test
    config = db.EpisodeConfig().override({"sim.distance_m": 0.3})
    for name, call in (("build_plant", lambda: db.build_plant()), ("build_diagram", lambda: db.build_diagram(config)),
                       ("run_episode", lambda: db.run_episode(config)),
                       ("episode on a Dask worker", lambda: episode_task(config.to_dict()))):
        with pytest.raises(db.DrakeFailure) as caught:
            call()
        assert isinstance(caught.value, RuntimeError)
        assert str(caught.value) == (f"{name}: a check inside Drake failed (in trigger_an_assertion_failure(): "
                                     "condition 'false' failed.)")
    code, lines = run_cli(capsys, ["walk", "--distance", "0.3", "--no-animation", "--out", str(tmp_path / "w")])
    assert code == 1
    one_line(lines, "drake-biped walk: failed: DrakeFailure: a check inside Drake failed",
             "trigger_an_assertion_failure()", "--debug")
    with pytest.raises(SystemExit, match="Failure at"):  # the original, with --debug
        main(["walk", "--distance", "0.3", "--no-animation", "--out", str(tmp_path / "w"), "--debug"])


def _api_argument_cases():
    import numpy as np

    import drake_biped as db
    from drake_biped.learners.registry import learner_from_state

    return {  # what the API once did with these: AttributeError, KeyError, TypeError, IndexError, NaNs, numpy's own
        "override(list)": (lambda: db.EpisodeConfig().override([("u_a", 1.0)]), db.ParameterError,
                           "EpisodeConfig.override: values must be a mapping of field names to values ({'u_a': "
                           "1.8}), got list [('u_a', 1.0)]"),
        "run_episode(dict)": (lambda: db.run_episode({"sim": {"distance_m": 0.3}}), db.ParameterError,
                              "run_episode: config must be an EpisodeConfig or None, got dict {'sim': "
                              "{'distance_m': 0.3}}; build it with EpisodeConfig.from_dict(...)"),
        "build_diagram(dict)": (lambda: db.build_diagram({}), db.ParameterError,
                                "build_diagram: config must be an EpisodeConfig, got dict {}"),
        "simulate(config=3)": (lambda: db.simulate(config=3), db.ParameterError,
                               "simulate: config must be an EpisodeConfig, got int 3"),
        "build_plant(dict)": (lambda: db.build_plant({"slope_rad": 0.1}), db.ParameterError,
                              "build_plant: ground must be a Ground or None, got dict {'slope_rad': 0.1}"),
        "load_gait(None)": (lambda: db.load_gait(None), db.ParameterError,
                            "--params None: expected a shipped name (one of ['climbing'"),
        "GarbLearner.from_state({})": (lambda: db.GarbLearner.from_state({}), db.ParameterError,
                                       "GarbLearner.from_state: the state has no 'mean', 'variance'"),
        "from_state(bad rng)": (lambda: db.GarbLearner.from_state({**db.GarbLearner().state(), "rng": 5}),
                                db.ParameterError, "GarbLearner.from_state: the state cannot be restored"),
        "learner_from_state(cmaes)": (lambda: learner_from_state({"learner": "cmaes"}), db.ParameterError,
                                      "CmaesLearner.from_state: the state has no 'start'"),
        "learner_from_state(pgpe)": (lambda: learner_from_state({"learner": "pgpe"}), db.ParameterError,
                                     "PgpeLearner.from_state: the state has no 'mean'"),
        "moving_average(x, -2)": (lambda: db.moving_average(np.ones(5), -2), ValueError,
                                  "moving_average: the window n must be an integer >= 1, got -2"),
        "moving_average(x, 0)": (lambda: db.moving_average(np.ones(5), 0), ValueError,
                                 "moving_average: the window n must be an integer >= 1, got 0"),
        "moving_average(2-D)": (lambda: db.moving_average(np.ones((2, 2))), ValueError,
                                "moving_average: x must be one series (a 1-D array), got shape (2, 2)"),
        "make_learner(seed=-1)": (lambda: db.make_learner("garb", seed=-1), db.ParameterError,
                                  "make_learner('garb'): seed must be an integer >= 0 or None, got -1"),
        "make_learner(cmaes, seed=1.5)": (lambda: db.make_learner("cmaes", seed=1.5), db.ParameterError,
                                          "make_learner('cmaes'): seed must be an integer >= 0 or None, got 1.5"),
        "PgpeLearner(seed=-3)": (lambda: db.make_learner("pgpe").__class__(seed=-3), db.ParameterError,
                                 "PgpeLearner: seed must be an integer >= 0 or None, got -3"),
    }


@pytest.mark.parametrize("case", list(_api_argument_cases()))
def test_wrong_arguments_through_the_api_raise_naming_the_argument_and_value(case):
    make, error, text = _api_argument_cases()[case]
    with pytest.raises(error) as caught:
        make()
    assert text in str(caught.value) and "\n" not in str(caught.value)


def test_an_unreadable_params_file_is_bad_input_naming_it(tmp_path, capsys, monkeypatch):
    """Once exit 1 (PermissionError). chmod 000 stops everyone but root; as root the read itself is made to fail."""
    import pathlib

    params = tmp_path / "locked.json"
    params.write_text("{}")
    params.chmod(0)
    try:
        if os.geteuid() == 0:  # root reads a mode-000 file: deny the read as the kernel would for anyone else
            read_text = pathlib.Path.read_text

            def denied(self, *args, **kwargs):
                if self == params:
                    raise PermissionError(13, "Permission denied", str(self))
                return read_text(self, *args, **kwargs)

            monkeypatch.setattr(pathlib.Path, "read_text", denied)
        code, lines = run_cli(capsys, ["walk", "--params", str(params), "--out", str(tmp_path / "w")])
    finally:
        params.chmod(0o644)
    assert code == 2
    one_line(lines, f"--params {params}: cannot be read (Permission denied)")
    assert not (tmp_path / "w").exists()


@pytest.mark.parametrize("text", ["[" * 50_000 + "]" * 50_000, '{"cpg": ' * 50_000 + "1" + "}" * 50_000])
def test_a_params_file_nested_beyond_the_recursion_limit_is_bad_input_naming_it(tmp_path, capsys, text):
    params = tmp_path / "deep.json"
    params.write_text(text)
    code, lines = run_cli(capsys, ["walk", "--params", str(params), "--out", str(tmp_path / "w")])
    assert code == 2  # once exit 1 with "RecursionError" and no file named
    one_line(lines, f"--params {params}: JSON nested too deeply to read")


def test_a_params_file_that_is_not_text_is_bad_input_naming_it(tmp_path, capsys):
    params = tmp_path / "binary.json"
    params.write_bytes(b"\xff\xfe\x00{")
    code, lines = run_cli(capsys, ["walk", "--params", str(params), "--out", str(tmp_path / "w")])
    assert code == 2
    one_line(lines, f"--params {params}: not UTF-8 text")


@pytest.mark.parametrize("record, missing", [({"settings": {}}, "it has no 'trials' list"),
                                             ({"trials": [{"trial": 0, "episodes": [{"reward": 1.0}]}]},
                                              "trials[0], episode 1 has no 'cost_of_transport'"),
                                             ([1, 2], "it holds a JSON list, not an object")])
def test_figures_of_a_record_that_is_not_a_learning_record_names_the_file(tmp_path, capsys, record, missing):
    (tmp_path / "learning.json").write_text(json.dumps(record))
    code, lines = run_cli(capsys, ["figures", str(tmp_path)])
    assert code == 2  # once exit 1 with "KeyError: 'trials'"
    one_line(lines, f"figures DIR: {tmp_path / 'learning.json'}: not a learning record", missing)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["learning.json"]  # no figure drawn


def test_version_prints_the_package_the_commit_and_drake(capsys):
    from drake_biped.versions import versions

    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    out, err = capsys.readouterr()
    v = versions()
    assert stop.value.code == 0 and err == ""
    assert out == (f"drake-biped {v['drake_biped']}, git commit {v['git_commit'] or 'unknown (not a source checkout)'}, "
                   f"Drake {v['drake']}\n")
    assert v["drake"]  # the installed Drake's version, never "unknown" here
    module = subprocess.run([sys.executable, "-m", "drake_biped", "--version"], capture_output=True, text=True,
                            timeout=120)
    assert module.returncode == 0 and module.stdout.startswith(f"drake-biped {v['drake_biped']}, git commit ")


def test_runaway_sizes_through_the_api_are_refused_unless_forced():
    from drake_biped.common import executor
    from drake_biped.experiments import grid

    with pytest.raises(ParameterError, match=r"GridSettings.axes: the grid has 78,125 points \(5 x 5 x 5 x 5 x 5 x 5 "
                                             r"x 5\), more than the limit of 20,000 .* or force=True"):
        grid.GridSettings(axes=tuple(grid.table_iv_axes(5)))
    assert grid.point_count(grid.GridSettings(axes=tuple(grid.table_iv_axes(5)), force=True).axes) == 5**7
    assert grid.point_count(grid.GridSettings(axes=tuple(grid.table_iv_axes(4))).axes) == 4**7  # within the limit
    limit = executor.max_local_workers()
    assert limit == executor.MAX_LOCAL_WORKERS_PER_CORE * (os.cpu_count() or 1)
    executor.check_cluster_options(limit, None)
    with pytest.raises(ParameterError, match=rf"--workers {limit + 1}: .*\(limit {limit}: "):
        executor.check_cluster_options(limit + 1, None)
    executor.check_cluster_options(limit + 1, None, force=True)
    with pytest.raises(ParameterError, match="--workers 1000"):
        with executor.dask_client(workers=1000):  # refused before a worker starts
            pass



def test_a_short_walk_says_it_has_too_few_touchdowns_for_a_step_period(tmp_path, capsys):
    # It printed "step n/a / n/a". A 0.3 m walk ends before its first touchdown.
    assert main(["walk", "--distance", "0.3", "--no-animation", "--out", str(tmp_path / "w")]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines()[0].startswith("gait: paper (sha256 ")
    first = out.splitlines()[1]
    assert first.startswith("ended: distance: 0.30 m") and "n/a" not in first
    assert first.endswith("0 steps, too few for a step period and length (3 touchdowns needed)")
    assert "animation:" not in out and "Traceback" not in err


def test_the_walk_names_its_saved_animation_not_a_meshcat_address_that_dies_with_it(caplog):
    import logging

    from drake_biped.experiments import walk

    with caplog.at_level(logging.INFO, logger="drake"):
        meshcat = walk.start_meshcat()
    assert meshcat.web_url().startswith("http://")  # a server was started, to record the walk
    assert not [r for r in caplog.records if "Meshcat listening" in r.getMessage()]  # and not announced
    assert not any(isinstance(f, walk._DropMeshcatAddress) for f in logging.getLogger("drake").filters)
    assert walk.animation_lines("out/w") == ["animation: out/w/walk.html (a standalone Meshcat recording: open it "
                                             "in a browser, no server needed) and out/w/walk.gif"]


@pytest.mark.parametrize("reduction, words", [(0.4489, "44.9 % lower"), (-0.001, "0.1 % higher"),
                                              (-0.25, "25.0 % higher"), (0.0004, "the same (to 0.1 %)")])
def test_learn_says_a_negative_saving_is_higher(tmp_path, reduction, words):
    # It printed "-0.1 % lower".
    from drake_biped.experiments.learning import summary_lines

    (tmp_path / "table_v.md").write_text("| table |\n")
    (tmp_path / "run.json").write_text(json.dumps({"sessions": [{"episodes": 2, "learning_wall_s": 1.0,
                                                                 "episodes_per_min": 120.0}],
                                                   "episodes": 2, "learning_wall_s": 1.0}))
    base = 0.2
    record = {"evaluation": {"no_window": {"cost_of_transport": base}, "reduction": reduction,
                             "learned_mean_cost_of_transport": base * (1 - reduction)}}
    line = summary_lines(record, tmp_path)[1]
    assert line == f"C_mt without a torque-free period 0.2000, with the learned ones {base * (1 - reduction):.4f}: {words}"


def test_window_map_prints_c_mt_to_four_significant_digits_and_what_it_wrote(tmp_path, capsys, monkeypatch):
    # It printed C_mt=0.22461234567890123 and no "wrote" line; then 0.000 for a small C_mt.
    from contextlib import nullcontext

    from drake_biped.common import executor
    from drake_biped.experiments import window_map

    row = {"t1": 0.2, "t2": 0.5, "walked": True, "cost_of_transport": 0.12345678901234567, "cmt_change": -0.45}
    record = {"config": {"sim": {"distance_m": 10.0}}, "windows": [row],
              "baseline": {"walked": True, "cost_of_transport": 0.22461234567890123}}
    monkeypatch.setattr(executor, "dask_client", lambda **kwargs: nullcontext())
    monkeypatch.setattr(window_map, "run", lambda settings, out, client: record)
    assert main(["window-map", "--out", str(tmp_path / "wm")]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines() == [gait_line(EpisodeConfig()), "no window: walked=True C_mt=0.2246", "1/1 windows walk 10 m",
                                "lowest C_mt: window (0.2, 0.5) C_mt=0.1235 (C_mt change -45.0 % vs no window)",
                                f"wrote {tmp_path / 'wm'}/window_map.json, window_map.csv, window_map.png"]
    assert err == ""


def test_a_run_log_belongs_to_one_command_and_another_command_is_refused_before_any_work(tmp_path, capsys):
    """`learn` into a folder a `grid` run used merged the grid's log ("3 episodes ... over 2 sessions" for a
    2-episode run). Each log names its command; another command's run there is refused by name."""
    main(_learn(tmp_path))  # a real learning run: 2 episodes, one session
    capsys.readouterr()
    log = tmp_path / "l" / "run.json"
    before = log.read_text()
    assert json.loads(before)["command"] == "learn"
    files = sorted(p.name for p in (tmp_path / "l").iterdir())
    code, lines = run_cli(capsys, ["grid", "--spec", "tiny", "--distance", "0.5", "--workers", "1",
                                   "--out", str(tmp_path / "l")])
    assert code == 2
    one_line(lines, f"--out {tmp_path / 'l'} holds the records of another run (drake-biped learn",
             "this run is drake-biped grid", "--overwrite")
    assert log.read_text() == before and sorted(p.name for p in (tmp_path / "l").iterdir()) == files
    # a folder whose records name no run (written through the API): the learning run's own log refuses it
    # and the other way round, through the API too: a grid's log is never a learning run's
    from drake_biped.common.progress import RunProgress, SessionLog

    grid_out = tmp_path / "g"
    report = RunProgress(grid_out, None, None, "grid", "point", bar=False, command="grid")
    report(0, 3)
    report(3, 3)
    report.close()
    code, lines = run_cli(capsys, _learn(tmp_path)[:-1] + [str(grid_out)])
    assert code == 2  # no run file lists run.json as a run's own: the folder is refused, naming it
    one_line(lines, f"--out {grid_out} holds files no drake-biped run listed as its own", ": run.json;",
             "--overwrite")
    code, lines = run_cli(capsys, _learn(tmp_path)[:-1] + [str(grid_out), "--overwrite"])
    assert code == 2
    one_line([line for line in lines if "warning" not in line], f"{grid_out / 'run.json'} is the run log of "
             "drake-biped grid", "learn does not run into")
    assert sorted(p.name for p in grid_out.iterdir()) == ["run.json"]  # no learning record begun
    with pytest.raises(ParameterError, match="is the run log of drake-biped grid"):
        SessionLog(grid_out / "run.json", None, None, command="slope")


def test_a_run_log_from_before_logs_named_their_command_is_taken_over(tmp_path):
    from drake_biped.common.progress import SessionLog

    path = tmp_path / "run.json"
    path.write_text(json.dumps({"sessions": [{"episodes": 2, "learning_wall_s": 1.0, "finished": True}]}))
    log = SessionLog(path, 1, None, command="learn", every_s=0.0)
    log.update(1, finished=True)
    record = json.loads(path.read_text())
    assert record["command"] == "learn" and [s["episodes"] for s in record["sessions"]] == [2, 1]


def test_a_failed_drake_check_in_a_dask_task_reaches_the_driver_as_a_drake_failure():
    """On a worker, pydrake's SystemExit would end the worker, not the task: every task the experiments map
    over the cluster (map_ordered) raises it as DrakeFailure, which the driver gets like any task error."""
    from drake_biped.api_guard import DrakeFailure
    from drake_biped.common.executor import dask_client, map_ordered

    def window_row(_):  # as an experiment's task would, deep inside Drake
        from pydrake.common import trigger_an_assertion_failure

        trigger_an_assertion_failure()

    with dask_client(workers=1) as client:
        with pytest.raises(DrakeFailure, match=r"^window_row on a Dask worker: a check inside Drake failed \(in "
                                               r"trigger_an_assertion_failure\(\): condition 'false' failed\.\)$"):
            map_ordered(client, window_row, [0])
        assert map_ordered(client, abs, [-2, 3]) == [2, 3]  # the worker lives on


def _worker_log_level():
    import logging

    return logging.getLogger("distributed.worker").getEffectiveLevel()


def test_the_local_clusters_workers_log_only_critical_lines(client):
    """What a worker logs at ERROR while the cluster closes under it (a heartbeat to a scheduler already gone,
    after Ctrl-C) would add lines to the one that says how to resume: the workers start with Dask's logging at
    CRITICAL (the driver's own logging is left as it is)."""
    import logging

    assert client.submit(_worker_log_level, pure=False).result() == logging.CRITICAL


def test_the_local_cluster_keeps_a_worker_whose_heartbeat_is_late(client):
    """A run suspended for longer than Dask's worker-ttl (5 minutes: Ctrl-Z, a machine asleep) lost every task
    running when it woke, the scheduler removing its workers before they could beat again: the embedded
    cluster's scheduler checks no heartbeat's age (a local worker's death closes its connection)."""
    scheduler = client.cluster.scheduler
    assert scheduler.worker_ttl is None and "worker-ttl" not in scheduler.periodic_callbacks
    assert len(scheduler.workers) == 2


def test_a_walk_on_a_level_part_longer_than_60_m_runs(tmp_path, capsys):
    # The command: exit 1 with Drake's "Box(): width = -40.008" (the drawn ground stopped at 60 m).
    out = tmp_path / "w"
    code = main(["walk", "--slope", "0.02", "--level-length", "100", "--distance", "0.3", "--no-animation",
                 "--out", str(out)])
    stdout, err = capsys.readouterr()
    assert code == 0 and "Traceback" not in err and "error" not in err and "Failure" not in err
    assert stdout.splitlines()[-1] == f"wrote {out}/"
    record = json.loads((out / "result.json").read_text())
    assert record["config"]["ground"] == {"slope_rad": 0.02, "level_length_m": 100.0, "friction": 1.0}
    assert record["termination"] == "distance" and record["distance_m"] >= 0.3


def test_a_time_step_above_the_converged_range_warns_and_a_diverging_walk_says_so(tmp_path, capsys):
    """walk --time-step 0.01 was accepted silently and its diverging control loop reported as an ordinary
    fall: now one warning line before the walk, 'DIVERGED' on the console and 'diverged' in the record; the
    walk is a result (exit 0)."""
    code = main(["walk", "--time-step", "0.01", "--distance", "1", "--no-animation", "--out", str(tmp_path / "w")])
    err = capsys.readouterr()
    assert code == 0
    assert [line for line in err.err.splitlines() if line.startswith("warning:")] == [
        "warning: --time-step 0.01 is above 1 ms, coarser than any shipped gait's step and than the steps at which "
        "their walks converge (docs/RESULTS.md, 'Physics with a continuous limit', 'Its plant step, refined past "
        "0.25 ms'); from 5 ms the control loop diverges, which ends an episode as 'diverged'"]
    assert err.out.splitlines()[0] == "gait: paper (sha256 " + gait_identity(EpisodeConfig())["sha256"][:12] + \
        "), plant step 10 ms"
    assert err.out.splitlines()[1].startswith("DIVERGED (the control loop diverged")
    record = json.loads((tmp_path / "w" / "result.json").read_text())
    assert record["termination"] == "diverged" and record["fell"]


def test_bad_input_keeps_exit_code_2_with_debug(tmp_path, capsys):
    """--debug adds the traceback; a bad params file is still bad input, exit 2, its one line last."""
    bad = tmp_path / "bad.json"
    bad.write_text('{"cpg": {"alpha": 9}}')
    with pytest.raises(SystemExit) as stop:
        main(["walk", "--params", str(bad), "--out", str(tmp_path / "w"), "--debug"])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith("drake-biped walk: error: ")
    assert "CpgParams.alpha = 9.0" in err.strip().splitlines()[-1]
