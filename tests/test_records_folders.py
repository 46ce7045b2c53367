"""A run deletes only what the toolkit wrote (records.claim_folder): the run file lists the files its runs wrote,
`--overwrite` deletes those and nothing else, a folder of files no run listed is refused naming them, and a
folder of records from before the lists still resumes."""

import json
import random
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from drake_biped.cli import main
from drake_biped.params import ParameterError
from drake_biped.records import LOCK_FILE, RUN_FILE, claim_folder, write_atomic

REPO = Path(__file__).resolve().parents[1]


def _header(out: Path) -> dict:
    return json.loads((out / RUN_FILE).read_text())


def _tree(out: Path) -> dict[str, bytes | str]:
    """Every file under `out` but the run file and the lock, with its content (text where it reads as text)."""
    def content(p: Path) -> bytes | str:
        try:
            return p.read_text()
        except UnicodeDecodeError:
            return p.read_bytes()

    return {p.relative_to(out).as_posix(): content(p) for p in sorted(out.rglob("*"))
            if p.is_file() and p.name not in (RUN_FILE, LOCK_FILE)}


def _write_a_run(out: Path, name: str) -> None:
    """What a run writes: a record, a kept episode in a subfolder, a figure through a plain write."""
    write_atomic(out / f"{name}.json", {"run": name})
    (out / "walks").mkdir(exist_ok=True)
    write_atomic(out / "walks" / f"{name}-000.json", {"episode": 0})
    (out / "episodes" / name).mkdir(parents=True, exist_ok=True)
    (out / "episodes" / name / "e.json").write_text("{}")
    (out / f"{name}.png").write_bytes(b"png")


def test_overwrite_deletes_the_runs_files_and_keeps_the_users(tmp_path, capsys):
    out = tmp_path / "run"
    with claim_folder(out, "grid", {"seed": 1}):
        _write_a_run(out, "grid")
    assert _header(out)["files"] == ["episodes/", "episodes/grid/", "episodes/grid/e.json", "grid.json", "grid.png",
                                     "walks/", "walks/grid-000.json"]
    (out / "notes.txt").write_text("what I saw")  # the user's, beside the records and among them
    (out / "walks" / "mine.txt").write_text("mine")
    with pytest.raises(ParameterError, match="holds the records of another run"):
        with claim_folder(out, "learn", {"seed": 1}):
            pass
    capsys.readouterr()
    with claim_folder(out, "learn", {"seed": 1}, overwrite=True):
        assert _tree(out) == {"notes.txt": "what I saw", "walks/mine.txt": "mine"}
        assert not (out / "episodes").exists()  # the run's folders, left empty, are gone; walks/ holds mine.txt
        write_atomic(out / "learning.json", {})
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "kept as they are: notes.txt, walks/mine.txt" in err[0]
    assert _header(out)["files"] == ["learning.json"]
    assert _header(out)["others"] == ["notes.txt", "walks/", "walks/mine.txt"]
    with claim_folder(out, "grid", {"seed": 2}, overwrite=True):  # and again: the others stay others
        pass
    assert _tree(out) == {"notes.txt": "what I saw", "walks/mine.txt": "mine"}


def test_a_rerun_with_overwrite_replaces_only_its_own_files(tmp_path):
    out = tmp_path / "run"
    with claim_folder(out, "walk", {"t1": 0.3}):
        _write_a_run(out, "first")
        (out / "only-first.json").write_text("{}")
    (out / "notes.txt").write_text("n")
    with claim_folder(out, "walk", {"t1": 0.4}, overwrite=True):
        _write_a_run(out, "first")
    assert not (out / "only-first.json").exists()
    assert set(_tree(out)) == {"notes.txt", "first.json", "first.png", "walks/first-000.json",
                               "episodes/first/e.json"}
    assert _header(out)["settings"] == {"t1": 0.4}


def test_a_folder_of_files_no_run_listed_is_refused_naming_them(tmp_path):
    out = tmp_path / "mine"
    (out / "data").mkdir(parents=True)
    for k in range(30):
        (out / "data" / f"{k}.csv").write_text("1")
    for name in ("a.txt", "b.txt", "c.txt", "d.txt", "e.txt"):
        (out / name).write_text(name)
    before = _tree(out)
    with pytest.raises(ParameterError) as info:
        with claim_folder(out, "walk", {}):
            pass
    message = str(info.value)
    assert "\n" not in message and f"--out {out} holds files no drake-biped run listed as its own" in message
    assert ": a.txt, b.txt, c.txt, d.txt, data/ and 1 more;" in message  # a folder stands for what it holds
    assert "--overwrite" in message
    assert _tree(out) == before and not (out / RUN_FILE).exists()


def test_overwrite_takes_over_an_unlisted_folder_as_it_is(tmp_path, capsys):
    """Without a run file the folder's files may be records of an older version, to be resumed: --overwrite
    writes beside them and deletes none of them, now or later."""
    out = tmp_path / "old"
    out.mkdir()
    (out / "run.json").write_text("old log")
    (out / "notes.txt").write_text("n")
    with claim_folder(out, "learn", {"seed": 1}, overwrite=True):
        assert (out / "run.json").read_text() == "old log"
        write_atomic(out / "learning.json", {})
    assert "writing beside files no drake-biped run listed as its own" in capsys.readouterr().err
    assert _header(out)["files"] == ["learning.json"] and _header(out)["others"] == ["notes.txt", "run.json"]
    with claim_folder(out, "grid", {}, overwrite=True):
        pass
    assert _tree(out) == {"notes.txt": "n", "run.json": "old log"}


def test_walk_into_a_folder_holding_a_users_result_is_refused_naming_it(tmp_path, capsys):
    out = tmp_path / "w"
    out.mkdir()
    (out / "result.json").write_text('{"mine": true}')
    with pytest.raises(SystemExit) as stop:
        main(["walk", "--distance", "0.3", "--no-animation", "--out", str(out)])
    assert stop.value.code == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and err[0].startswith("drake-biped walk: error: --out") and ": result.json;" in err[0]
    assert (out / "result.json").read_text() == '{"mine": true}' and sorted(p.name for p in out.iterdir()) == [
        "result.json"]


def test_a_run_stopped_before_it_listed_its_files_has_them_counted_at_its_resume(tmp_path):
    """A killed run (SIGKILL: no cleanup) leaves its run file marked as writing; its resume counts what appeared
    since that claim as the run's, and the user's file from before the claim stays the user's."""
    out = tmp_path / "k"
    out.mkdir()
    (out / "notes.txt").write_text("n")
    script = ("import os, sys; from pathlib import Path; from drake_biped.records import claim_folder\n"
              "out = Path(sys.argv[1])\n"
              "with claim_folder(out, 'grid', {}, overwrite=True):\n"
              "    (out / 'sub').mkdir(); (out / 'sub' / 'point.json').write_text('{}'); os._exit(9)\n")
    assert subprocess.run([sys.executable, "-c", script, str(out)], cwd=REPO).returncode == 9
    assert _header(out)["writing"] is True and _header(out)["files"] == []
    with claim_folder(out, "grid", {}):  # the resume
        assert _header(out)["files"] == ["sub/", "sub/point.json"] and _header(out)["others"] == ["notes.txt"]
    assert "writing" not in _header(out)
    with claim_folder(out, "learn", {}, overwrite=True):
        pass
    assert _tree(out) == {"notes.txt": "n"}


def test_a_failed_run_that_wrote_records_keeps_its_claim(tmp_path):
    out = tmp_path / "f"
    with pytest.raises(RuntimeError):
        with claim_folder(out, "learn", {"seed": 1}):
            (out / "trials").mkdir()
            write_atomic(out / "trials" / "trial_0.json", {})
            raise RuntimeError("a worker died")
    assert _header(out)["files"] == ["trials/", "trials/trial_0.json"]
    with claim_folder(out, "learn", {"seed": 1}):  # resumes without a word
        assert (out / "trials" / "trial_0.json").exists()


@pytest.mark.parametrize("folder", ["learn-default-seed1", "time-step-study-learned"])
def test_the_committed_records_from_before_the_lists_still_resume(tmp_path, folder):
    """A run file with no list of files (written by an older drake-biped): the same run resumes and the run file
    stays as it was; another run's --overwrite is refused naming the files, since none can be shown to be the
    toolkit's."""
    out = tmp_path / folder
    shutil.copytree(REPO / "benchmarks" / "results" / folder, out)
    header = _header(out)
    assert "files" not in header
    files = _tree(out)
    with claim_folder(out, header["command"], header["settings"]):
        pass
    assert _header(out) == header and _tree(out) == files
    with pytest.raises(ParameterError, match=r"lists no files \(an older drake-biped's, or unreadable\), so --overwrite "
                                             r"cannot tell them from files of your own: "):
        with claim_folder(out, "walk", {}, overwrite=True):
            pass
    assert _header(out) == header and _tree(out) == files


def test_runs_and_a_user_sharing_a_folder_never_lose_the_users_files(tmp_path):
    """Runs of two settings resume, fail and replace each other (--overwrite) while the user adds files, some in
    the runs' own folders: every user file survives as written, and after a replacement no file of an earlier
    run is left."""
    rng = random.Random(68)
    made = iter(range(10**6))  # every user file a name of its own

    def add_user_file(out: Path, user: dict[str, str]) -> None:
        name = f"{rng.choice(['', 'walks/', 'deep/er/'])}user-{next(made)}.txt"
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(name)
        user[name] = name

    for case in range(12):
        out = tmp_path / f"case{case}"
        out.mkdir()
        user: dict[str, str] = {}
        current, written = None, set()
        for _ in range(rng.randint(0, 2)):
            add_user_file(out, user)
        for step in range(8):
            settings = {"seed": rng.choice([1, 2])}
            same = current == settings
            try:
                with claim_folder(out, "grid", settings, overwrite=True):
                    if not same:
                        left = {p for p in _tree(out) if p not in user}
                        assert left == set(), (case, step, left)  # nothing of another run is left
                        written = set()
                    for _ in range(rng.randint(0, 3)):
                        name = rng.choice(["", "walks/", "deep/er/", "episodes/a/"]) + f"run-{step}-{rng.random()}"
                        (out / name).parent.mkdir(parents=True, exist_ok=True)
                        write_atomic(out / name, {})
                        written.add(name)
                    if rng.random() < 0.3:
                        add_user_file(out, user)  # while the run holds the folder: it counts as the run's
                        written.add(next(reversed(user)))
                        user.pop(next(reversed(user)))
                    if rng.random() < 0.2:
                        raise RuntimeError("failed")
                current = settings
            except RuntimeError:  # a new claim that wrote nothing leaves the folder unclaimed
                current = settings if written or same else None
            if rng.random() < 0.5:
                add_user_file(out, user)
            assert {p: t for p, t in _tree(out).items() if p in user} == user, (case, step)
            if (out / RUN_FILE).exists():
                assert set(_header(out)["files"]) >= written
