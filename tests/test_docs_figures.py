"""The pictures under docs/ are those benchmarks/docs_figures.py draws from committed records, each linked from a
document, and each what the records draw today (a stale picture fails here: `make docs-figures` redraws them)."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
PICTURES = ("*.png", "*.gif", "*.jpg", "*.jpeg", "*.svg")


def _pictures(folder: Path) -> list[str]:
    return sorted(p.name for pattern in PICTURES for p in folder.glob(pattern))


@pytest.fixture(scope="module")
def drawn(tmp_path_factory):
    if not (ROOT / "benchmarks" / "docs_figures.py").is_file():
        pytest.skip("not a checkout")
    out = tmp_path_factory.mktemp("docs")
    run = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "docs_figures.py"), "--out", str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    return out, run.stdout


def test_docs_holds_exactly_the_pictures_drawn_from_records(drawn):
    drawn, _ = drawn
    assert _pictures(ROOT / "docs") == _pictures(drawn) == ["report_summary_full.png", "walk_frame.png"]


def test_every_picture_under_docs_is_linked_from_a_document():
    texts = {p: p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]}
    for name in _pictures(ROOT / "docs"):
        linked = [p.name for p, text in texts.items()
                  if re.search(r"\]\((docs/)?" + re.escape(name) + r"\)", text)
                  and (p.parent == ROOT / "docs" or f"](docs/{name})" in text)]
        assert linked, f"docs/{name} is linked from no document"


# On another machine than the recorded walk's, the walk agrees within versions.CROSS_MACHINE_RTOL, not to the last
# digit, and its still may move by a line's width: there, the picture is compared within this mean difference of a
# pixel's channels (0-255). A stale picture (another walk, another table) differs by far more.
CROSS_MACHINE_MEAN_PIXEL = 3.0


@pytest.mark.parametrize("name", ["report_summary_full.png", "walk_frame.png"])
def test_each_picture_is_what_its_records_draw_today(drawn, name):
    from PIL import Image

    drawn, printed = drawn
    committed = np.asarray(Image.open(ROOT / "docs" / name).convert("RGBA"))
    today = np.asarray(Image.open(drawn / name).convert("RGBA"))
    assert committed.shape == today.shape, f"docs/{name} is not what its records draw today: run make docs-figures"
    exact = name != "walk_frame.png" or "compared to the last digit" in printed
    if exact:
        assert np.array_equal(committed, today), f"docs/{name} is not what its records draw today: run make docs-figures"
    else:
        difference = np.abs(committed.astype(float) - today.astype(float)).mean()
        assert difference <= CROSS_MACHINE_MEAN_PIXEL, (
            f"docs/{name} differs from what its records draw today by {difference:.2f} per channel (another machine "
            f"than the record's: {CROSS_MACHINE_MEAN_PIXEL} allowed): run make docs-figures")
