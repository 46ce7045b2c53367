"""What a basins record reads as: each start's attractor (`reading`), basins.md and basins.png, drawn from the
record alone.

Named for the `basins` command (drake_biped/experiments/basins.py) by design: that walks the starts, this draws their
record."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.records import save_figure


def reading(cell: dict) -> str:
    """A cell's reading for the figure: the strict label, else the jitter-scale one."""
    if cell["fell"]:
        return "falls"
    if cell["attractor"].startswith("period-"):
        return cell["attractor"]
    if cell["within_jitter"].startswith("period-"):
        return f"{cell['within_jitter']} (jitter)"
    return cell["attractor"]


def markdown(record: dict[str, Any]) -> str:
    """basins.md: per condition, how many starts end on each attractor, and the range of their step periods."""
    lines = [f"# Basins: {len(record['hip_angles_rad'])} initial hip angles x {len(record['speeds_mps'])} speeds",
             "", f"Walks of {record['distance_m']:g} m, the first {record['transient_m']:g} m dropped; window "
             f"{record['window'][0]:g}–{record['window'][1]:g} s.", "",
             "| condition | attractor | starts | mean step period (s) | long-run C_mt |", "|---|---|---|---|---|"]
    for condition, grid in record["grids"].items():
        cells = [c for row in grid for c in row]
        for kind in sorted({reading(c) for c in cells}):
            group = [c for c in cells if reading(c) == kind]
            periods = [c["step_period_mean_s"] for c in group if c["step_period_mean_s"] is not None and not c["fell"]]
            costs = [c["cost_of_transport"] for c in group if c["cost_of_transport"] is not None]
            lines.append(f"| {condition} | {kind} | {len(group)} | "
                         + (f"{min(periods):.3f}–{max(periods):.3f}" if periods else "—") + " | "
                         + (f"{format_cost(min(costs))}–{format_cost(max(costs))}" if costs else "—") + " |")
    return "\n".join(lines) + "\n"


def figure(record: dict[str, Any], path: Path) -> None:
    """One panel per condition: each start coloured by its mean step period, a fall as a cross, an irregular
    walk ringed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a, v = np.array(record["hip_angles_rad"]), np.array(record["speeds_mps"])
    fig, axes = plt.subplots(1, len(record["grids"]), figsize=(10.0, 4.2), sharey=True)
    periods = [c["step_period_mean_s"] for g in record["grids"].values() for row in g for c in row
               if not c["fell"] and c["step_period_mean_s"] is not None]
    vmin, vmax = (min(periods), max(periods)) if periods else (0.0, 1.0)
    scatter = None
    for ax, (condition, grid) in zip(np.atleast_1d(axes), record["grids"].items()):
        for i, angle in enumerate(a):
            for j, speed in enumerate(v):
                c = grid[i][j]
                if c["fell"]:
                    ax.plot(speed, angle, "kx", ms=7)
                    continue
                scatter = ax.scatter(speed, angle, c=[c["step_period_mean_s"]], cmap="viridis", vmin=vmin, vmax=vmax,
                                     s=90, marker="s")
                if not reading(c).startswith("period-"):
                    ax.scatter(speed, angle, s=160, facecolors="none", edgecolors="r", linewidths=1.2)
        ax.set_title(f"{condition} the window", fontsize=9)
        ax.set_xlabel("initiation speed (m/s)")
    np.atleast_1d(axes)[0].set_ylabel("initial hip angle (rad)")
    if scatter is not None:
        fig.colorbar(scatter, ax=axes, label="mean step period after the transient (s)")
    fig.suptitle("Where each start ends: colour the step period; x falls; red ring: irregular", fontsize=10)
    save_figure(fig, path, dpi=120)
    plt.close(fig)
