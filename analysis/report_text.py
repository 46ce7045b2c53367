"""What every report section writes the same way: the verdicts' words, numbers and changes in text, and a
sub-report's Markdown embedded in a larger one."""

from __future__ import annotations

import re
from pathlib import Path

from drake_biped.analysis.series import signed_percent

__all__ = ["BEYOND", "DIFFERS", "NOT_REPRODUCED", "PARTLY", "REPRODUCED", "embed", "num", "pct", "read_markdown",
           "steps_text"]

REPRODUCED, PARTLY, NOT_REPRODUCED, DIFFERS, BEYOND = (
    "reproduced", "partly reproduced", "not reproduced", "differs", "beyond the paper")


def pct(x: float | None) -> str:
    if x is None:
        return "—"
    return signed_percent(x)


def num(x: float | None, digits: int = 3) -> str:
    return "—" if x is None else f"{x:.{digits}f}"


def steps_text(n: int) -> str:
    return f"{n} step" if n == 1 else f"{n} steps"


def embed(markdown: str, folder: str) -> str:
    """A sub-report inside this one: headings two levels down, relative links prefixed with `folder`."""
    text = re.sub(r"^(#+) ", lambda m: "#" * min(6, len(m.group(1)) + 2) + " ", markdown, flags=re.M)

    def link(m: re.Match) -> str:
        target = m.group(2)
        if re.match(r"^[a-z]+:|^/|^#", target):
            return m.group(0)
        return f"{m.group(1)}({folder}/{target})"

    return re.sub(r"(!?\[[^\]]*\])\(([^)\s]+)\)", link, text)


def read_markdown(out: Path, rel: str) -> str:
    """The Markdown an experiment wrote at `out`/`rel`, or a line saying it was not written."""
    path = out / rel
    return path.read_text() if path.is_file() else f"({rel} was not written)\n"
