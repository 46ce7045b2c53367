"""benchmarks/touchdown_grid.py's measure: the share of the step periods' variance their touchdowns' phases on the
plant's grid explain, checked on series whose dependence on the phase is chosen."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np


def _module():
    folder = Path(__file__).resolve().parents[1] / "benchmarks"
    if str(folder) not in sys.path:  # the script imports its neighbour, as when run from there
        sys.path.insert(0, str(folder))
    path = folder / "touchdown_grid.py"
    spec = importlib.util.spec_from_file_location("touchdown_grid_under_test", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_grid_phase_share_is_near_one_for_a_sawtooth_and_near_chance_for_periods_that_ignore_the_phase():
    explained_by = _module().variance_explained_by_phase
    rng = np.random.default_rng(1)
    phases = rng.uniform(0.0, 1.0, 400)
    # a sawtooth of 3 ms over the phase: 8 bins leave a ramp's 1/64 of the variance within them
    saw = 0.863 + 0.003 * phases
    explained, chance, means = explained_by(saw, phases, 8)
    assert 0.97 < explained < 0.995 and abs(chance - 7 / 399) < 1e-12
    assert np.all(np.diff(means) > 0) and abs(means[0] - (0.863 + 0.003 / 16)) < 2e-4
    # periods drawn apart from the phase: what the bins explain is chance's share
    noise = 0.863 + 0.001 * rng.standard_normal(400)
    explained, chance, _ = explained_by(noise, phases, 8)
    assert explained < 3 * chance
    # half of each: about half
    both = 0.863 + 0.003 * phases + 0.003 / np.sqrt(12) * rng.standard_normal(400)
    assert 0.4 < explained_by(both, phases, 8)[0] < 0.6
    # a constant has no variance to explain; an empty bin has no mean
    assert explained_by(np.full(20, 0.9), np.linspace(0, 0.49, 20), 8)[0] is None
    assert explained_by(saw[:20], np.linspace(0, 0.49, 20), 8)[2][-1] is None


def test_the_summary_never_replaces_a_users_file_and_only_the_scripts_records_are_read(tmp_path):
    """A folder with a touchdown_grid.md or .png the script did not write is refused (its summary would replace
    them); the script's own summary is rewritten; only records its command wrote enter the table."""
    module = _module()
    assert module.foreign_summary(tmp_path) is None
    (tmp_path / "touchdown_grid.png").write_bytes(b"a user's figure")
    assert module.foreign_summary(tmp_path) == tmp_path / "touchdown_grid.png"
    (tmp_path / "touchdown_grid.md").write_text("# my notes\n")
    assert module.foreign_summary(tmp_path) == tmp_path / "touchdown_grid.md"
    (tmp_path / "touchdown_grid.md").write_text(module.TABLE_HEADER + "| a row |\n")
    assert module.foreign_summary(tmp_path) is None
    (tmp_path / "mine.json").write_text('{"command": "python my_script.py"}')
    (tmp_path / "broken.json").write_text("{")
    (tmp_path / "walk-h0.5ms.json").write_text('{"command": "python benchmarks/touchdown_grid.py --gait paper"}')
    assert list(module.own_records(tmp_path)) == ["walk-h0.5ms"]
