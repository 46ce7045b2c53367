"""Output folders hold one run's records: another command or other settings are refused (or replaced with
--overwrite), one process at a time writes a folder, and finished work survives an interruption. Sizes are
bounded before any work; a cluster without workers is said within seconds; the API names wrong arguments."""

import json
import threading

import pytest
from walkers import FAST, fast_config

from drake_biped.cli import main
from drake_biped.params import ParameterError
from drake_biped.records import LOCK_FILE, RUN_FILE, claim_folder


def test_a_folder_is_held_by_one_run_and_refused_to_another_naming_both(tmp_path):
    out = tmp_path / "run"
    with claim_folder(out, "walk", {"t1": 0.3}):
        (out / "result.json").write_text("{}")
        with pytest.raises(ParameterError, match=r"another run is writing this folder \(process \d+: drake-biped walk"):
            with claim_folder(out, "walk", {"t1": 0.3}):
                pass
    assert json.loads((out / RUN_FILE).read_text()) == {"command": "walk", "settings": {"t1": 0.3},
                                                        "files": ["result.json"], "others": []}
    assert not (out / LOCK_FILE).exists() or (out / LOCK_FILE).read_text()
    with claim_folder(out, "walk", {"t1": 0.3}):  # the same run again: a resume
        pass
    with pytest.raises(ParameterError, match=r"holds the records of another run \(drake-biped walk with other "
                                             r"settings: --t1 0.3 there, 0.4 here\): .*--overwrite"):
        with claim_folder(out, "walk", {"t1": 0.4}):
            pass
    with pytest.raises(ParameterError, match=r"another run \(drake-biped walk; this run is drake-biped grid\)"):
        with claim_folder(out, "grid", {"t1": 0.3}):
            pass
    assert (out / "result.json").exists()  # nothing of the first run was touched
    with claim_folder(out, "walk", {"t1": 0.4}, overwrite=True):
        assert not (out / "result.json").exists()  # replaced: the old records are gone
    assert json.loads((out / RUN_FILE).read_text())["settings"] == {"t1": 0.4}


def test_a_refused_run_leaves_a_new_folder_as_it_found_it(tmp_path):
    out = tmp_path / "fresh"
    with pytest.raises(RuntimeError):
        with claim_folder(out, "walk", {}):
            raise RuntimeError("input refused inside the command")
    assert list(out.iterdir()) == []


def test_a_second_command_into_a_busy_folder_is_refused_and_the_first_finishes_whole(tmp_path, capsys):
    out = tmp_path / "w"
    started, release = threading.Event(), threading.Event()
    codes = {}

    def first():
        import drake_biped.cli as cli
        from drake_biped.experiments import walk

        real = walk.command

        def slow(args):
            started.set()
            release.wait(30)
            return real(args)

        cli_args = ["walk", "--distance", "0.3", "--no-animation", "--out", str(out)]
        parser_func = cli.build_parser().parse_args(cli_args)
        parser_func.func = slow
        with cli._holding_the_out_folder(parser_func):
            codes["first"] = parser_func.func(parser_func)

    thread = threading.Thread(target=first)
    thread.start()
    assert started.wait(30)
    with pytest.raises(SystemExit) as second:
        main(["walk", "--distance", "0.3", "--no-animation", "--out", str(out)])
    release.set()
    thread.join(60)
    assert second.value.code == 2
    err = [line for line in capsys.readouterr().err.strip().splitlines() if line.startswith("drake-biped")]
    assert len(err) == 1 and "another run is writing this folder" in err[0] and "drake-biped walk" in err[0]
    assert codes["first"] == 0 and json.loads((out / "result.json").read_text())["distance_m"] >= 0.3


def test_walk_into_another_walks_folder_is_refused_before_any_work(tmp_path, capsys):
    out = tmp_path / "w"
    assert main(["walk", "--distance", "0.3", "--no-animation", "--out", str(out)]) == 0
    first = (out / "result.json").read_text()
    capsys.readouterr()
    with pytest.raises(SystemExit) as e:
        main(["walk", "--distance", "0.3", "--t1", "0.2", "--t2", "0.5", "--no-animation", "--save-trajectory",
              "--out", str(out)])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds the records of another run" in err[0] and "--overwrite" in err[0]
    assert (out / "result.json").read_text() == first
    assert main(["walk", "--distance", "0.3", "--no-animation", "--out", str(out), "--overwrite"]) == 0
    assert not (out / "trajectory.npz").exists()


def test_a_folder_keeps_the_gait_it_walked_and_a_parameter_file_edited_since_is_another_run(tmp_path, capsys):
    """The run record names the gait (its shipped name or None, and its SHA-256); the same command with a
    parameter file whose gains changed since is another run's, refused before any work, naming both gaits."""
    from drake_biped.resources import gait_identity, load_gait

    params, out = tmp_path / "mine.json", tmp_path / "w"
    params.write_text(json.dumps({"gait": {"torso_kd": 15.0}}))
    argv = ["walk", "--params", str(params), "--distance", "0.1", "--no-animation", "--out", str(out)]
    assert main(argv) == 0
    recorded = json.loads((out / RUN_FILE).read_text())["gait"]
    assert recorded == gait_identity(load_gait(params)) and recorded["name"] is None
    assert capsys.readouterr().out.startswith(f"gait: another gait (sha256 {recorded['sha256'][:12]}), plant step")
    params.write_text(json.dumps({"gait": {"torso_kd": 16.0}}))
    with pytest.raises(SystemExit) as e:
        main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert e.value.code == 2 and len(err) == 1, err
    assert f"on another gait: another gait (sha256 {recorded['sha256'][:12]}) there" in err[0]
    main(["walk", "--distance", "0.1", "--no-animation", "--out", str(tmp_path / "p")])
    assert json.loads((tmp_path / "p" / RUN_FILE).read_text())["gait"]["name"] == "paper"


def test_a_window_map_beyond_its_limit_is_refused_before_any_work(tmp_path, capsys):
    from drake_biped.experiments.window_map import MAX_WINDOWS, WindowMapSettings

    grid = {"t1_max_s": 0.6, "t2_max_s": 0.9, "min_length_s": 0.1}
    with pytest.raises(ParameterError, match=r"gives 301,101 windows, more than the limit of 20,000"):
        WindowMapSettings(t1_step_s=0.001, t2_step_s=0.001, **grid)
    assert WindowMapSettings(t1_step_s=0.001, t2_step_s=0.001, force=True, **grid).window_count() == 301_101 > MAX_WINDOWS
    placed = WindowMapSettings().for_step_period(0.9)  # the gait's own grid: t1 to T, t2 to 1.5 T, steps T / 10
    assert (placed.t1_max_s, placed.t2_max_s, placed.t1_step_s, placed.t2_step_s) == (0.9, 1.35, 0.09, 0.09)
    assert placed.window_count() == len(placed.windows())
    assert max(t1 for t1, _ in placed.windows()) == pytest.approx(0.9)
    assert max(t2 for _, t2 in placed.windows()) == pytest.approx(1.35)
    with pytest.raises(SystemExit) as e:  # a grid given whole is refused before any work
        main(["window-map", "--step", "0.001", "--t1-max", "0.6", "--t2-max", "0.9", "--distance", "0.3",
              "--out", str(tmp_path / "m")])
    assert e.value.code == 2 and "360,600 windows" in capsys.readouterr().err
    assert not (tmp_path / "m").exists()


def test_a_window_map_keeps_every_finished_episode_and_sets_a_damaged_log_aside(tmp_path, client, capsys):
    """Each finished row is appended to episodes.jsonl as it comes and read back by a rerun, which runs nothing
    again. A damaged line and a torn last line: the file is set aside as episodes.jsonl.broken, as it was, with
    one warning naming the lines (as docs/CLI.md says); the rows that read carry over, the two lost episodes
    run again, and the map is the same."""
    from drake_biped.experiments.window_map import WindowMapSettings, run

    settings = WindowMapSettings(fast_config().override({"sim.distance_m": 0.3}), t1_max_s=0.1, t2_max_s=0.3,
                                 t1_step_s=0.1, t2_step_s=0.1)
    out = tmp_path / "wm"
    first = run(settings, out, client, progress=False)
    keep = out / "episodes.jsonl"
    lines = keep.read_text().splitlines()
    assert len(lines) == 6 and len(first["windows"]) == 5
    capsys.readouterr()
    run(settings, out, client, progress=False)
    assert keep.read_text().splitlines() == lines and capsys.readouterr().err == ""  # nothing run again
    damaged = "\n".join([lines[0], '{"config": {"cpg"', *lines[2:5]]) + "\n" + lines[5][:25]
    keep.write_text(damaged)
    again = run(settings, out, client, progress=False)
    err = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(err) == 1 and f"{keep} has 2 line(s) that do not read as a window-map episode (line 2, 6" in err[0]
    assert err[0].endswith("kept as episodes.jsonl.broken")
    assert (out / "episodes.jsonl.broken").read_text() == damaged
    assert (again["baseline"], again["windows"]) == (first["baseline"], first["windows"])
    now = keep.read_text().splitlines()
    assert now[:4] == [lines[0], *lines[2:5]] and sorted(now) == sorted(lines)  # 4 carried over, 2 run again


def test_a_scheduler_without_workers_is_said_within_seconds(monkeypatch):
    from distributed import LocalCluster

    from drake_biped.common import executor

    monkeypatch.setattr(executor, "WORKER_WAIT_S", 1.0)
    with LocalCluster(n_workers=0, host="127.0.0.1", dashboard_address=None) as cluster:
        with pytest.raises(ParameterError, match=r"--scheduler .*has no workers \(none joined within 1 s\); start "
                                                 r"one: dask worker"):
            with executor.dask_client(scheduler=cluster.scheduler_address):
                pass


@pytest.mark.parametrize("call, match", [
    (lambda: fast_config().override({"seed": 1}).seed == 1 or None, None),
    (lambda: __import__("drake_biped.episode", fromlist=["x"]).run_episode(fast_config(), cache="x"),
     r"run_episode: cache must be a DiagramCache or None, got str 'x'"),
    (lambda: __import__("drake_biped.episode", fromlist=["x"]).run_episode("default"),
     r"run_episode: config must be an EpisodeConfig"),
    (lambda: __import__("drake_biped.model", fromlist=["x"]).body_of_model("x"),
     r"body_of_model: model must be a RobotModel"),
    (lambda: __import__("drake_biped.experiments.window_map", fromlist=["x"]).run({"t1_max_s": 0.3}, "never", None),
     r"window_map.run: settings must be a WindowMapSettings, got dict"),
    (lambda: __import__("drake_biped.experiments.grid", fromlist=["x"]).run({}, "never", None),
     r"grid.run: settings must be a GridSettings, got dict"),
])
def test_the_api_names_a_wrong_argument(tmp_path, monkeypatch, call, match):
    monkeypatch.chdir(tmp_path)
    if match is None:
        assert call()
        return
    with pytest.raises(ParameterError, match=match):
        call()
    assert not (tmp_path / "never").exists()


def test_foreign_records_are_named_not_a_key_error(tmp_path):
    """A grid's points as a search log, a window map as a time-step study: one ParameterError naming the file
    and what it is not; a search resumed with another objective is refused naming both."""
    from drake_biped.experiments import gait_search, time_step

    log = tmp_path / "search.jsonl"
    log.write_text(json.dumps({"key": "x", "row": {}}) + "\n")
    settings = gait_search.GaitSearchSettings()
    with pytest.raises(ParameterError, match=r"search.jsonl, line 1: not a gait-search log \(no 'generation'\)"):
        gait_search._check_log(gait_search._read_log(log), settings, "es", log)
    log.write_text(json.dumps({"generation": 0, "parent": {}, "parent_score": 0.1, "objective": "walk",
                               "sigma": 0.1, "mutations": "default", "seed": 0, "policy_draws": 12}) + "\n")
    # (a log of the servo's mutation set by its former name, "default")
    other = gait_search.GaitSearchSettings(config=FAST, objective="hold", sigma=0.3)
    with pytest.raises(ParameterError, match=r"begun with other settings \(objective 'walk' there, 'hold' here; "
                                             r"sigma 0.1 there, 0.3 here\)"):
        gait_search._check_log(gait_search._read_log(log), other, "es", log)
    # a search begun under an objective whose scoring has changed since: refused, naming it
    same = gait_search.GaitSearchSettings(config=FAST, objective="walk", sigma=0.1, seed=0)
    first = {"generation": 0, "parent": {}, "parent_score": 0.1, "objective": "walk", "sigma": 0.1,
             "mutations": same.mutations, "seed": 0, "policy_draws": same.policy_draws, "method": "es"}
    for about, refused in ((gait_search.OBJECTIVES["walk"].about, False), (None, False), ("scored otherwise", True)):
        log.write_text(json.dumps({**first, **({} if about is None else {"objective_about": about})}) + "\n")
        if refused:
            with pytest.raises(ParameterError, match=r"begun when the objective 'walk' scored otherwise: it cannot be resumed"):
                gait_search._check_log(gait_search._read_log(log), same, "es", log)
        else:
            gait_search._check_log(gait_search._read_log(log), same, "es", log)
    (tmp_path / "time_step_study.json").write_text(json.dumps({"baseline": {}, "windows": []}))
    with pytest.raises(ParameterError, match=r"not a time-step study \(no 'steps'\)"):
        time_step.replot(tmp_path)


@pytest.mark.parametrize("argv, words", [
    (["learn", "--trials", "1000", "--episodes", "1000"], "--trials 1000 x --episodes 1000: 1,000,000 episodes"),
    (["slope", "--slope", "0.02", "--trials", "2000", "--episodes", "100"], "--trials 2000 x --episodes 100: 200,000"),
    (["stability", "--trials", "20000"], "--trials 20000: 120,000 walks"),
    (["gait-search", "--generations", "1000", "--offspring", "8"], "--generations 1000 x --offspring 8: 8,000"),
    (["compare-learners", "--window-map", "m", "--trials", "100", "--episodes", "500"],
     "--learners garb,cmaes,pgpe x --trials 100 x --episodes 500: 150,000"),
    (["landscape", "m", "--samples", "1000000"], "--samples 1,000,000 x 3 variances: 3,000,000 draws"),
    (["time-step-study", "--steps", ",".join(f"{1e-3 + k * 1e-6:.6g}" for k in range(700))],
     "--steps (700) x walks (3): 2,100 walks"),
])
def test_every_size_a_user_gives_is_bounded_before_any_work(tmp_path, capsys, argv, words):
    with pytest.raises(SystemExit) as e:
        main([*argv, "--out", str(tmp_path / "o")])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and words in err[0] and "--force" in err[0]
    assert not (tmp_path / "o").exists()


def test_a_cluster_that_loses_every_worker_is_said_within_seconds(monkeypatch):
    """A run waiting on a scheduler whose only worker leaves for good stops within seconds with a ClusterLost
    naming the scheduler, instead of waiting without a word."""
    import time

    from distributed import LocalCluster

    from drake_biped.common import executor

    monkeypatch.setattr(executor, "WORKER_WAIT_S", 1.0)
    with LocalCluster(n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None) as cluster:
        start = time.monotonic()
        with pytest.raises(executor.ClusterLost, match=r"--scheduler .*: every worker left the cluster"):
            with executor.dask_client(scheduler=cluster.scheduler_address) as client:
                future = client.submit(time.sleep, 60, pure=False)
                cluster.scale(0)
                future.result()
        assert time.monotonic() - start < 30


@pytest.mark.parametrize("epsilon, words", [
    (None, "no perturbation converged: not established: the Jacobian did not converge"),
    (1e-4, "converged at epsilon 0.0001"),
])
def test_floquet_says_on_the_console_whether_its_orbit_is_established(tmp_path, capsys, monkeypatch, epsilon, words):
    from drake_biped.experiments import floquet

    record = {"spectral_radius": 13.441, "fixed_point_residual": 1e-9, "converged_epsilon": epsilon,
              "evaluation_noise": None, "settings": {"newton_tolerance": 1e-6}}
    monkeypatch.setattr(floquet, "run", lambda settings, out, client: record)
    assert main(["floquet", "--workers", "1", "--out", str(tmp_path / "f")]) == 0
    out = capsys.readouterr().out
    assert "spectral radius 13.4410" in out and words in out and "epsilon None" not in out


def test_the_command_line_runs_its_bars_without_tqdms_monitor_thread(tmp_path):
    """tqdm's monitor thread, stopped at exit, printed its own traceback when a second Ctrl-C came while the
    process exited: the command line turns it off."""
    from tqdm import tqdm

    tqdm.monitor_interval = 10
    with pytest.raises(SystemExit):
        main(["walk", "--t1", "0.5", "--out", str(tmp_path / "w")])  # refused: --t1 without --t2
    assert tqdm.monitor_interval == 0


def test_a_compressed_record_reads_as_the_record(tmp_path):
    """A large record kept compressed (learning.json.gz beside no learning.json) reads where learning.json is
    asked for, and a path ending in .gz reads as the JSON it holds."""
    import gzip

    from drake_biped.records import read_json

    data = {"trials": [{"trial": 0, "final_mean": [0.3, 0.8]}]}
    with gzip.open(tmp_path / "learning.json.gz", "wt") as f:
        json.dump(data, f)
    assert read_json(tmp_path / "learning.json", "--policy") == data
    assert read_json(tmp_path / "learning.json.gz", "--policy") == data
    (tmp_path / "bad.json.gz").write_bytes(b"\x1f\x8b not gzip")
    with pytest.raises(ParameterError, match="bad.json.gz: cannot be read"):
        read_json(tmp_path / "bad.json.gz", "--policy")
