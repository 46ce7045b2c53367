"""Every script in examples/ runs on a short setting and prints what it promises (each is a subprocess, run
from outside the checkout, as a user would run a copied script), and writes only under out/ or the folder it is
given."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def run(tmp_path, script: str, *args: str) -> str:
    out = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout


def written(folder: Path) -> list[str]:
    """Every file under `folder` (the folder a script ran in), as paths relative to it."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


def test_every_example_has_a_test():
    tested = set(re.findall(r'"(\w+\.py)"', Path(__file__).read_text()))
    assert {p.name for p in EXAMPLES.glob("*.py")} <= tested


@pytest.mark.slow
def test_walk_and_plot(tmp_path):
    text = run(tmp_path, "walk_and_plot.py", "--distance", "2", "--out", "walk")
    assert re.search(r"walked 2\.\d\d m .* fell: False", text)
    assert (tmp_path / "walk" / "hip_angles.png").stat().st_size > 10_000
    assert '"cost_of_transport"' in (tmp_path / "walk" / "result.json").read_text()
    assert written(tmp_path) == ["walk/hip_angles.png", "walk/result.json"]  # only where it was told


@pytest.mark.slow
def test_window_sweep(tmp_path):
    text = run(tmp_path, "window_sweep.py", "--distance", "2", "--windows", "0.1-0.2,0.2-0.5")
    changes = [float(x) for x in re.findall(r"\(([+-]\d+\.\d) % vs none\)", text)]
    assert len(changes) == 2 and changes[0] < 0  # 0.1-0.2 s saves energy on the paper's walker
    assert "window 0.1-0.2 s: walks" in text and "window 0.2-0.5 s: falls" in text  # a longer one falls
    assert written(tmp_path) == []


@pytest.mark.slow
def test_garb_loop(tmp_path):
    text = run(tmp_path, "garb_loop.py", "--episodes", "3", "--distance", "1.5")
    rewards = [float(x) for x in re.findall(r"reward (\d+\.\d+)", text)]
    assert len(rewards) == 3 and all(r > 0 for r in rewards)
    assert text.count("policy mean") == 3
    assert_windows_walkable(text, 3)
    assert "episode   1: window 0.113–0.187 s" in text  # seed 0's first sample about the start (0.1, 0.2)
    assert written(tmp_path) == []


def assert_windows_walkable(text: str, count: int) -> None:
    """Every window printed is one an episode walks: none (t2 <= t1), or 0 <= t1 < t2."""
    windows = re.findall(r"window (none \(t2 [-\d.]+ <= t1 [-\d.]+\)|(\d+\.\d+)–(\d+\.\d+) s)", text)
    assert len(windows) == count, text
    assert all(w.startswith("none") or 0 <= float(a) < float(b) for w, a, b in windows), windows


@pytest.mark.slow
def test_return_map(tmp_path):
    text = run(tmp_path, "return_map.py", "--walks", "3", "--distance", "4")
    radius = float(re.search(r"spectral radius (\d+\.\d+)", text).group(1))
    assert 0 < radius < 1  # the paper's walker returns to its cycle
    assert text.count("touchdowns") == 3
    assert written(tmp_path) == []


@pytest.mark.slow
def test_dask_sweep(tmp_path):
    text = run(tmp_path, "dask_sweep.py", "--workers", "2", "--distance", "1.5")
    assert text.count("C_mt") == 6 and "no window: 1.5" in text
    assert written(tmp_path) == []  # nor a Dask scratch folder


@pytest.mark.slow
def test_custom_learner(tmp_path):
    """The registered learner is made by name and keeps the best window it has seen."""
    text = run(tmp_path, "custom_learner.py", "--episodes", "4", "--distance", "1.5")
    cmt = [float(x) for x in re.findall(r"C_mt (\d+\.\d+)", text)]
    assert len(cmt) == 4 and text.count("best window so far") == 4
    best = re.findall(r"best window so far (\d\.\d+)–(\d\.\d+) s", text)
    assert best[0] == ("0.100", "0.200")  # the first episode walks the start itself
    assert_windows_walkable(text.replace("best window so far", "best"), 4)
    assert written(tmp_path) == []


BAD_ARGUMENTS = [  # (script, arguments, what the one line names); once tracebacks, or exit 0 saying nothing
    ("walk_and_plot.py", ["--distance", "nan"], ["argument --distance", "'nan' is not a finite number"]),
    ("walk_and_plot.py", ["--t1", "99"], ["TorqueFreeWindow.start_s = 99.0", "[0, 10]"]),
    ("return_map.py", ["--walks", "1"], ["argument --walks", "'1' must be >= 2"]),
    ("dask_sweep.py", ["--workers", "0"], ["argument --workers", "'0' must be >= 1"]),
    ("dask_sweep.py", ["--scheduler", "localhost"], ["--scheduler 'localhost'", "tcp://HOST:PORT"]),
    ("window_sweep.py", ["--windows", "abc"], ["argument --windows", "'abc': a window is T1-T2"]),
    ("window_sweep.py", ["--windows", "0.5-0.2"], ["argument --windows", "'0.5-0.2': T2 <= T1 is no window"]),
    ("garb_loop.py", ["--episodes", "-1"], ["argument --episodes", "'-1' must be >= 1"]),
    ("garb_loop.py", ["--distance", "1e5"], ["SimulationParams.distance_m = 100000.0 is outside"]),
    ("custom_learner.py", ["--episodes", "0"], ["argument --episodes", "'0' must be >= 1"]),
]


@pytest.mark.parametrize("script, args, expected", BAD_ARGUMENTS, ids=[f"{s} {' '.join(a)}" for s, a, _ in BAD_ARGUMENTS])
def test_a_bad_argument_is_one_line_naming_it_with_exit_code_2(tmp_path, script, args, expected):
    out = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=tmp_path, capture_output=True,
                         text=True, timeout=120)
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert out.returncode == 2 and len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
    assert lines[0].startswith(f"{script}: error: ") and all(text in lines[0] for text in expected), lines[0]
    assert out.stdout == "" and not any(tmp_path.iterdir())  # nothing walked, nothing written


def test_a_failed_run_of_an_example_is_one_line_with_exit_code_1(tmp_path):
    """Two 0.3 m walks have no touchdown to fit a return map to: the run fails, in one line."""
    out = subprocess.run([sys.executable, str(EXAMPLES / "return_map.py"), "--walks", "2", "--distance", "0.3"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert out.returncode == 1 and len(lines) == 1 and "Traceback" not in out.stderr, out.stderr
    assert lines[0] == ("return_map.py: failed: ValueError: fit_return_map needs at least 3 pairs for a 2-D map, "
                        "got 0 (set DRAKE_BIPED_DEBUG=1 for the traceback)")


def test_own_robot(tmp_path):
    """Without --out the edited URDF goes to out/own_robot, never into the folder the script runs in."""
    text = run(tmp_path, "own_robot.py", "--distance", "1.5")
    assert written(tmp_path) == ["out/own_robot/own_robot.urdf"]
    rows = {line.split()[0]: line[36:].split() for line in text.splitlines() if line.startswith(("shipped", "own"))}
    assert list(rows) == ["shipped", "own:"]
    # the model's mass: the torso 20 % heavier, the shanks as heavy as before
    assert float(rows["shipped"][0]) == 10.202
    assert float(rows["own:"][0]) == pytest.approx(10.202 + 0.2 * 6.646, abs=1e-3)
    assert all(row[5] in ("walked", "fell") for row in rows.values())
    urdf = (tmp_path / "out" / "own_robot" / "own_robot.urdf").read_text()
    assert '<origin xyz="0 0 -0.3487" />' in urdf  # the ankle 10 % further down the shank
