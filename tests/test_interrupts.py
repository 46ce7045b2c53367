"""A run stopped part-way loses nothing finished: damaged records are named, Ctrl-C exits 130 and SIGTERM 143, each
one line saying how to resume, and the same command resumes."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from drake_biped.cli import main
from tests.test_failures import _learn, one_line, run_cli


@pytest.mark.slow
def test_damaged_records_are_named_and_nothing_finished_is_lost(tmp_path, capsys):
    main(_learn(tmp_path))
    capsys.readouterr()
    trial = tmp_path / "l" / "trials" / "trial_0.json"
    # A damaged run log is set aside with a warning, and the run goes on.
    (tmp_path / "l" / "run.json").write_text('{"sessions": [{"episo')
    main(_learn(tmp_path))
    err = capsys.readouterr().err
    assert "run.json is not a readable run log" in err and (tmp_path / "l" / "run.json.broken").is_file()
    # A damaged trial record is refused by name, with what to do, and left as it is.
    text = trial.read_text()
    trial.write_text(text[: len(text) // 2])
    code, lines = run_cli(capsys, _learn(tmp_path, 3))
    assert code == 2
    one_line(lines, str(trial), "not valid JSON", "delete it to run trial 0 again")
    assert trial.read_text() == text[: len(text) // 2]


@pytest.mark.slow
def test_the_run_log_counts_the_episodes_a_killed_session_never_logged(tmp_path, capsys):
    main(_learn(tmp_path))
    log = tmp_path / "l" / "run.json"
    record = json.loads(log.read_text())
    record["sessions"][0].update(episodes=0, finished=False)  # as a session killed before its first write
    log.write_text(json.dumps(record))
    main(_learn(tmp_path, 3))
    sessions = json.loads(log.read_text())["sessions"]
    assert [s["episodes"] for s in sessions] == [2, 1]
    assert sessions[0]["counted_from_records"] == 2 and json.loads(log.read_text())["episodes"] == 3


@pytest.mark.slow
def test_ctrl_c_is_one_line_exit_130_and_the_same_command_resumes(tmp_path):
    argv = [sys.executable, "-m", "drake_biped", "learn", "--trials", "2", "--episodes", "400", "--distance", "1",
            "--workers", "2", "--out", str(tmp_path / "l")]
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    trials = tmp_path / "l" / "trials"
    deadline = time.time() + 120
    while time.time() < deadline and not (trials.is_dir() and any(trials.iterdir())):
        time.sleep(0.5)
    time.sleep(2.0)
    os.killpg(p.pid, signal.SIGINT)  # as a terminal's Ctrl-C: the driver and every worker get it
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130
    lines = [line for line in err.replace("\r", "\n").splitlines() if line.strip() and not line.startswith("learning")]
    assert len(lines) == 1 and "interrupted; run the same command again to resume" in lines[0], lines
    assert "Traceback" not in err
    done = sum(len(json.loads(t.read_text())["episodes"]) for t in trials.glob("*.json"))
    assert json.loads((tmp_path / "l" / "run.json").read_text())["episodes"] == done > 0


# A run waiting on several Dask tasks at once (client.gather, as the Floquet analysis and the finite-difference
# Jacobian once did): Ctrl-C there left asyncio's "Task exception was never retrieved" for distributed's AllExit,
# once per abandoned wait, as the client closed.
_GATHERING = """
import time
from drake_biped.cli import run_script
from drake_biped.common.executor import dask_client

def main():
    with dask_client(workers=1) as client:
        futures = [client.submit(time.sleep, 60 + i, pure=False) for i in range(3)]
        print("gathering", flush=True)
        client.gather(futures)

if __name__ == "__main__":
    run_script(main, "gathering")
"""


@pytest.mark.slow
def test_ctrl_c_during_a_gather_closes_dask_without_a_traceback(tmp_path):
    script = tmp_path / "gathering.py"
    script.write_text(_GATHERING)
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert p.stdout.readline().strip() == "gathering"
    time.sleep(1.0)
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130
    assert err.strip() == "gathering: interrupted; run it again", err
    assert "Traceback" not in err and "AllExit" not in err


@pytest.mark.slow
def test_sigterm_to_the_whole_job_is_one_line_exit_143_and_the_same_command_resumes(tmp_path):
    """As a batch scheduler or `kill` stops a job (SIGTERM to the driver and its workers): one line saying how
    to resume, exit 143, no traceback, and the episodes finished kept."""
    argv = [sys.executable, "-m", "drake_biped", "learn", "--trials", "2", "--episodes", "400", "--distance", "1",
            "--workers", "2", "--out", str(tmp_path / "l")]
    p = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    trials = tmp_path / "l" / "trials"
    deadline = time.time() + 120
    while time.time() < deadline and not (trials.is_dir() and any(trials.iterdir())):
        time.sleep(0.5)
    time.sleep(2.0)
    os.killpg(p.pid, signal.SIGTERM)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 143
    lines = [line for line in err.replace("\r", "\n").splitlines()
             if line.strip() and not line.startswith("learning")]
    assert len(lines) == 1 and "stopped (SIGTERM); run the same command again to resume" in lines[0], lines
    assert "Traceback" not in err
    # the workers die at once, so the run log may miss the episodes finished as the signal came; the trial
    # records hold them, and a rerun counts them (test_the_run_log_counts_the_episodes_a_killed_session_never_logged)
    done = sum(len(json.loads(t.read_text())["episodes"]) for t in trials.glob("*.json"))
    assert 0 < json.loads((tmp_path / "l" / "run.json").read_text())["episodes"] <= done
