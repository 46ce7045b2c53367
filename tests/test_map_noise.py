"""benchmarks/map_noise.py: it never replaces a user's file, reads only its own records, and its table reports
what the records hold."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest


def _module():
    folder = Path(__file__).resolve().parents[1] / "benchmarks"
    if str(folder) not in sys.path:  # the script imports its neighbours, as when run from there
        sys.path.insert(0, str(folder))
    spec = importlib.util.spec_from_file_location("map_noise_under_test", folder / "map_noise.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_folder_holding_a_users_map_noise_md_is_refused_and_left_as_it_was(tmp_path, monkeypatch, capsys):
    module = _module()
    notes = tmp_path / "map_noise.md"
    notes.write_text("# my notes\n")
    monkeypatch.setattr(sys, "argv", ["map_noise.py", "--out", str(tmp_path), "--h-ms", "0.5"])
    with pytest.raises(SystemExit) as stop:
        module.main()
    assert stop.value.code == 2 and "map_noise.md" in capsys.readouterr().err
    assert notes.read_text() == "# my notes\n" and sorted(p.name for p in tmp_path.iterdir()) == ["map_noise.md"]


def test_the_table_reads_only_the_scripts_records_and_reports_their_fits(tmp_path):
    module = _module()
    record = {"command": module.COMMAND + " --gait paper", "time_step_s": 3.5e-4,
              "map": {"spread": {"a": 0.2, "b": 0.01}, "fits": [
                  {"size": 0.01, "noise_relative": 0.012, "noise_absolute": 0.056, "radius": 0.24,
                   "interval": [0.117, 2.17], "samples": 54, "falls": 2},
                  {"size": 0.03, "error": "too few left to fit"}]}}
    (tmp_path / "walker-h0.35ms.json").write_text(json.dumps(record))
    (tmp_path / "other.json").write_text(json.dumps({**record, "command": "python my_script.py"}))
    records = module.own_records(tmp_path, module.COMMAND)
    assert list(records) == ["walker-h0.35ms"]
    rows = module.row_text("walker-h0.35ms", records["walker-h0.35ms"])
    assert rows[0] == ("| walker-h0.35ms | 0.35 ms | a 0.2, b 0.01 | 0.01 | 5.60e-02 (1.2e-02) | 0.24 (0.117–2.17) "
                       "| 2 of 56 |")
    assert "too few left to fit" in rows[1]
