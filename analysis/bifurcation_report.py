"""bifurcation.md and bifurcation.png, drawn from a bifurcation record alone.

Named for the `bifurcation` command (drake_biped/experiments/bifurcation.py) by design: that walks the sweep, this
draws its record."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from drake_biped.analysis.attractor import NEIGHBOUR_KICK_RADPS, PERIOD_WINDOW
from drake_biped.analysis.cost_of_transport import format_cost, format_cost_interval
from drake_biped.records import save_figure


def markdown(record: dict[str, Any]) -> str:
    """bifurcation.md: one row per point."""
    jitter = record["jitter_tolerance_s"]
    lyapunov = record.get("lyapunov", True)  # records before the key always walked the neighbours
    exponent_text = (f"Lyapunov: a finite-size exponent (per step) from a neighbour walk kicked by "
                     f"{NEIGHBOUR_KICK_RADPS:g} rad/s on the swing hip." if lyapunov
                     else "No neighbour walks (--no-lyapunov): no Lyapunov exponents.")
    lines = [f"# Bifurcation over {record['param']}", "",
             f"Walks of {record['distance_m']:g} m; the steps within {record['transient_m']:g} m of the first "
             f"touchdown dropped; period-k where every k-th of the last periods varies by less than "
             f"{1e3 * record['period_tolerance_s']:g} ms (period-1: the last {record['period_window']}), and read "
             f"again at {1e3 * jitter:g} ms, the scale of the controller's jitter. {exponent_text}", "",
             f"| {record['param']} | step (ms) | attractor | at {1e3 * jitter:g} ms | last {record['period_window']} step "
             f"periods (s) |{' Lyapunov |' if lyapunov else ''} long-run C_mt (95 %) |",
             "|---|---|---|---|---|" + ("---|" if lyapunov else "") + "---|"]
    for p in record["points"]:
        periods = p["step_periods_s"][-record["period_window"]:]
        span = f"{min(periods):.3f}–{max(periods):.3f}" if periods else "—"
        lyap = p.get("lyapunov") or {}
        exponent = "—" if lyap.get("exponent") is None else f"{lyap['exponent']:+.2f}"
        if p["cost_of_transport"] is None:
            cmt = "—"
        else:
            lo, hi = p["interval_95"] or (None, None)
            cmt = (format_cost_interval(p["cost_of_transport"], 0.5 * (hi - lo)) if lo is not None
                   else format_cost(p["cost_of_transport"]))
        lines.append(f"| {p['value']:g} | {1e3 * p['time_step_s']:g} | {p['attractor']} | "
                     f"{p['within_jitter']['attractor']} | {span} |{f' {exponent} |' if lyapunov else ''} {cmt} |")
    up_to = record.get("walked_up_to")
    values = record["values"]
    if up_to is None:
        envelope = "none: the first falls."
    elif up_to == values[-1] and len(values) > 1:
        envelope = f"the sweep's end, {up_to:g}: every value walks, so the envelope is ≥ {up_to:g} (not reached)."
    else:
        envelope = f"{up_to:g}."
    lines += ["", f"Every walk from {record['param']} = {values[0]:g} walks up to " + envelope]
    return "\n".join(lines) + "\n"


def figure(record: dict[str, Any], path: Path) -> None:
    """Garcia-style: every kept step period, and the section's hip angle, against the parameter (one marker
    per plant step), falls marked on the axis; the attractor named above each value."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 6.0), sharex=True)
    markers = {h: (m, c) for h, m, c in zip(record["time_steps_s"], ("o", "x"), ("C0", "C3"))}
    for h in record["time_steps_s"]:
        m, c = markers[h]
        points = [p for p in record["points"] if p["time_step_s"] == h]
        for p in points:
            if p["fell"]:
                continue
            periods = p["step_periods_s"][-4 * PERIOD_WINDOW:]
            angles = [s[0] for s in p["sections"][-4 * PERIOD_WINDOW:]]
            top.plot([p["value"]] * len(periods), periods, marker=m, ls="", ms=2.5, color=c, alpha=0.6)
            bottom.plot([p["value"]] * len(angles), angles, marker=m, ls="", ms=2.5, color=c, alpha=0.6)
        top.plot([], [], marker=m, ls="", color=c, label=f"plant step {1e3 * h:g} ms")
    fell = [p["value"] for p in record["points"] if p["fell"]]
    if fell:
        for ax in (top, bottom):
            ax.plot(fell, [ax.get_ylim()[0]] * len(fell), marker="v", color="k", ls="", label="falls")
    for p in record["points"]:
        if p["time_step_s"] == record["time_steps_s"][0]:
            text = p["attractor"].replace("period-", "P")
            jitter = (p.get("within_jitter") or {}).get("attractor", "")
            if jitter.startswith("period-") and jitter != p["attractor"]:
                text += f"\n{jitter.replace('period-', 'P')} at {1e3 * record['jitter_tolerance_s']:g} ms"
            top.annotate(text, (p["value"], 1.0), xycoords=("data", "axes fraction"), ha="center", va="bottom",
                         fontsize=7)
    top.set_ylabel("step period (s)")
    bottom.set_ylabel("hip angle at touchdown (rad)")
    bottom.set_xlabel(record["param"])
    top.legend(fontsize=8, loc="lower right")
    fig.suptitle(f"Steps after the first {record['transient_m']:g} m of {record['distance_m']:g} m walks", fontsize=10,
                 y=0.995)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
