"""Every script in examples/ runs on a short setting and prints what it promises (each is a subprocess, run
from outside the checkout, as a user would run a copied script)."""

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


def test_every_example_has_a_test():
    tested = set(re.findall(r'"(\w+\.py)"', Path(__file__).read_text()))
    assert {p.name for p in EXAMPLES.glob("*.py")} <= tested


@pytest.mark.slow
def test_walk_and_plot(tmp_path):
    text = run(tmp_path, "walk_and_plot.py", "--distance", "2", "--out", "walk")
    assert re.search(r"walked 2\.\d\d m .* fell: False", text)
    assert (tmp_path / "walk" / "hip_angles.png").stat().st_size > 10_000
    assert '"cost_of_transport"' in (tmp_path / "walk" / "result.json").read_text()


@pytest.mark.slow
def test_window_sweep(tmp_path):
    text = run(tmp_path, "window_sweep.py", "--distance", "2", "--windows", "0.2-0.5,0.1-0.2")
    changes = [float(x) for x in re.findall(r"\(([+-]\d+\.\d) % vs none\)", text)]
    assert len(changes) == 2 and changes[0] < 0  # 0.2-0.5 s saves energy on the default gait
    assert "window 0.2-0.5 s: walks" in text


@pytest.mark.slow
def test_garb_loop(tmp_path):
    text = run(tmp_path, "garb_loop.py", "--episodes", "3", "--distance", "1.5")
    rewards = [float(x) for x in re.findall(r"reward (\d+\.\d+)", text)]
    assert len(rewards) == 3 and all(r > 0 for r in rewards)
    assert text.count("policy mean") == 3


@pytest.mark.slow
def test_return_map(tmp_path):
    text = run(tmp_path, "return_map.py", "--walks", "3", "--distance", "4")
    radius = float(re.search(r"spectral radius (\d+\.\d+)", text).group(1))
    assert 0 < radius < 1  # the default gait is a stable limit cycle
    assert text.count("touchdowns") == 3


@pytest.mark.slow
def test_dask_sweep(tmp_path):
    text = run(tmp_path, "dask_sweep.py", "--workers", "2", "--distance", "1.5")
    assert text.count("C_mt") == 6 and "no window: 1.5" in text


@pytest.mark.slow
def test_custom_learner(tmp_path):
    """The registered learner is made by name and keeps the best window it has seen."""
    text = run(tmp_path, "custom_learner.py", "--episodes", "4", "--distance", "1.5")
    cmt = [float(x) for x in re.findall(r"C_mt (\d+\.\d+)", text)]
    assert len(cmt) == 4 and text.count("best window so far") == 4
    best = re.findall(r"best window so far \((\d\.\d+), (\d\.\d+)\)", text)
    assert best[0] == ("0.300", "0.400")  # the first episode walks the start itself
