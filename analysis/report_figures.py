"""The reproduction report's verdict tables drawn as pictures (report_summary.png): one row per claim, each
verdict cell coloured by its verdict."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from drake_biped.analysis.report_text import BEYOND, DIFFERS, NOT_REPRODUCED, PARTLY, REPRODUCED
from drake_biped.records import save_figure

__all__ = ["VERDICT_COLOURS", "quick_summary_figure", "summary_figure"]

VERDICT_COLOURS = ((REPRODUCED, "#c8e6c9"), (PARTLY, "#ffe0b2"), (DIFFERS, "#ffe0b2"), (NOT_REPRODUCED, "#ffcdd2"),
                   (BEYOND, "#e0e0e0"))


def _verdict_table(rows: Sequence[Sequence[str]], labels: Sequence[str], widths: Sequence[int], width_in: float,
                   verdict_of: Callable[[int, int], str | None], title: str, path: Path) -> None:
    """`rows` as a table picture, each text wrapped at its column's width (characters); a cell whose
    `verdict_of(row, column)` starts with a verdict takes its colour."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cells = [["\n".join(textwrap.wrap(text.replace("**", ""), w)) or "—" for text, w in zip(row, widths)]
             for row in rows]
    heights = [max(c.count("\n") + 1 for c in row) for row in cells]
    fig, ax = plt.subplots(figsize=(width_in, 0.9 + 0.2 * (sum(heights) + len(heights))))
    ax.axis("off")
    table = ax.table(cellText=cells, colLabels=list(labels), loc="upper center", cellLoc="left",
                     colWidths=[w / sum(widths) for w in widths])
    table.auto_set_font_size(False)
    table.set_fontsize(8)
    total = sum(heights) + len(heights) + 1
    for (r, c), cell in table.get_celld().items():
        cell.set_height((1 if r == 0 else heights[r - 1] + 1) / total * 0.95)
        if r == 0:
            cell.set_facecolor("#eeeeee")
            continue
        verdict = verdict_of(r - 1, c)
        for key, colour in VERDICT_COLOURS:
            if verdict and verdict.startswith(key):
                cell.set_facecolor(colour)
                break
    ax.set_title(title, fontsize=10)
    save_figure(fig, path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def summary_figure(verdicts: list[tuple[str, str, str, str]], title: str, path: Path) -> None:
    """The verdict table as a picture: one row per claim, the verdict cell coloured."""
    _verdict_table(verdicts, ["claim", "paper", "ours", "verdict"], (34, 26, 44, 34), 13,
                   lambda r, c: verdicts[r][3] if c == 3 else None, title, path)


def quick_summary_figure(rows: list[dict[str, str]], path: Path, full_gait: str | None = None) -> None:
    """The quick report's table as a picture: this run's column beside the full run's, each verdict coloured;
    `full_gait`: the full run's gait when it is not this run's (full_run_gait)."""
    table_rows = [(r["what"], r["paper"], r["this_run"] + (f" — {r['this_verdict']}" if r["this_verdict"] else ""),
                   r["full_run"]) for r in rows]
    _verdict_table(table_rows, ["claim", "paper", "this run (quick)", "full run (checked here)"], (30, 20, 40, 50),
                   14, lambda r, c: {2: rows[r]["this_verdict"], 3: rows[r]["full_verdict"]}.get(c),
                   "drake-biped reproduce (quick): this run beside the shipped full run"
                   + (f" (measured on {full_gait.strip('`')})" if full_gait else ""), path)
