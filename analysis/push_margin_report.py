"""push_margin.md and push_margin.png, drawn from a push-margin record alone; `margin_text`, a margin as the reports write it.

Named for the `push-margin` command (drake_biped/experiments/push_margin.py) by design: that pushes the walks, this
draws their record."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from drake_biped.records import save_figure


def margin_text(cell: dict[str, Any]) -> str:
    """A direction's margin as a report gives it: "35", or "≥ 100" where every force tried survives."""
    if cell.get("margin_n") is None:
        return "—"
    return ("≥ " if cell.get("at_grid_top") else "") + f"{cell['margin_n']:g}"


def markdown(record: dict[str, Any]) -> str:
    """push_margin.md: the margins and, per condition, where the grid's pushes fell."""
    window = record["window"]
    names = {"without": "without torque-free period",
             "with": f"with torque-free period {window[0]:.4f}–{window[1]:.4f} s"}
    lines = ["| | forward margin (N) | backward margin (N) | the step pushed (s) |", "|---|---|---|---|"]
    for condition in record["margins"]:  # the record keeps the conditions in order
        m = record["margins"][condition]
        if m["step_s"] is None:
            lines.append(f"| {names[condition]} | — | — | the unpushed walk "
                         f"{'has no step after the settling time' if m['unpushed_walks'] else 'falls'} |")
            continue
        lines.append(f"| {names[condition]} | {margin_text(m['forward'])} | {margin_text(m['backward'])} | "
                     f"{m['step_s'][0]:.3f}–{m['step_s'][1]:.3f} |")
    lines += ["", f"Each force from {record['force_step_n']:g} N to {record['max_force_n']:g} N in steps of "
              f"{record['force_step_n']:g} N, for {record['push_duration_s']:g} s, at {record['phases']} phases of the "
              f"first step after {record['settle_s']:g} s; survived: the walk still walks its "
              f"{record['distance_m']:g} m. The margin: the largest force at and below which every phase survives "
              "(≥: every force tried survives, so the margin is not reached).",
              ""]
    for condition in record["margins"]:  # the record keeps the conditions in order
        m = record["margins"][condition]
        if m["step_s"] is None:
            continue
        for direction in ("forward", "backward"):
            falls = [f"{f:g} N at phase {j}/{record['phases']}" for f, row in zip(record["forces_n"],
                                                                           m[direction]["survived"])
                     for j, ok in enumerate(row) if not ok]
            above = [x for x in falls if float(x.split(" N")[0]) > m[direction]["margin_n"]]
            lines.append(f"- {names[condition]}, {direction}: {len(falls)} of "
                         f"{len(record['forces_n']) * record['phases']} pushes fall"
                         + (f"; the first above the margin: {above[0]}" if above else "") + ".")
    return "\n".join(lines) + "\n"


def figure(record: dict[str, Any], path: Path) -> None:
    """The survival maps: force (signed: + forward) against the phase of the step, one panel per condition."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    forces, phases = record["forces_n"], record["phases"]
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.0), sharey=True)
    for ax, condition in zip(axes, record["margins"]):
        m = record["margins"][condition]
        ax.set_title(f"{condition} the window" + ("" if m["step_s"] else " (no steady step)"), fontsize=9)
        if m["step_s"] is None:
            continue
        grid = np.full((2 * len(forces), phases), np.nan)
        for j in range(phases):
            for i in range(len(forces)):
                grid[len(forces) - 1 - i, j] = float(m["backward"]["survived"][i][j])
                grid[len(forces) + i, j] = float(m["forward"]["survived"][i][j])
        signed = [-f for f in reversed(forces)] + list(forces)
        step = record["force_step_n"]
        ax.imshow(grid, origin="lower", aspect="auto", cmap="RdYlGn", vmin=0, vmax=1,
                  extent=(-0.5 / phases, 1 - 0.5 / phases, signed[0] - step / 2, signed[-1] + step / 2))
        for direction, sign in (("forward", 1), ("backward", -1)):
            ax.axhline(sign * (m[direction]["margin_n"] + step / 2), color="k", lw=1, ls="--")
        ax.set_xlabel("phase of the step pushed (fraction of its period)")
    axes[0].set_ylabel("push force (N, + forward)")
    fig.suptitle("Survival of a push in steady state (green survives; dashed: the margins)", fontsize=10)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
