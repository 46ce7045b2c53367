"""time_step_study.md and time_step_study.png, drawn from a time-step study's record alone; `halving`, whether
its three finest steps halve (Richardson's estimate needs them).

Named for the `time-step-study` command (drake_biped/experiments/time_step.py) by design: that walks the steps, this
draws its record."""

from __future__ import annotations

import json
from pathlib import Path

from drake_biped.analysis.cost_of_transport import format_cost, format_cost_interval
from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M
from drake_biped.analysis.series import signed_percent
from drake_biped.legacy import clock_of_record
from drake_biped.params import SimulationParams
from drake_biped.records import save_figure


def label(window) -> str:
    return "no window" if window is None else f"window {window[0]:g}–{window[1]:g} s"


def halving(steps: list[float]) -> bool:
    """Whether the three finest steps halve (Richardson's estimate needs them)."""
    fine = sorted(steps)[:3]
    return len(fine) == 3 and all(abs(fine[i + 1] / fine[i] - 2.0) <= 1e-9 for i in range(2))


def _walks_of(rec: dict) -> list:
    """The record's walks."""
    return [tuple(w) if w else None for w in rec["walks"]]


def _contact_text(config: dict) -> str:
    c = config.get("contact")
    if c is None:
        return "Drake's defaults with the near-rigid regime on (a record from before the contact was recorded)"
    return (f"{c['stiffness_npm']:g} N/m, relaxation time {c['relaxation_time_s']:g} s per geometry, SAP's "
            f"near-rigid threshold {c['sap_near_rigid_threshold']:g}")


def markdown(rec: dict) -> str:
    steps = rec["steps"]
    head = "| walk | " + " | ".join(f"{h * 1e3:g} ms" for h in steps) + " |"
    sep = "|---" * (len(steps) + 1) + "|"
    by = {(r["time_step_s"], tuple(r["window"] or ())): r for r in rec["rows"]}

    def table(fmt) -> list[str]:
        out = [head, sep]
        for w in _walks_of(rec):
            cells = [fmt(by[(h, tuple(w or ()))]) for h in steps]
            out.append(f"| {label(w)} | " + " | ".join(cells) + " |")
        return out

    def cmt(r):
        if not r["walked"]:
            return f"{r['termination']} at {r['distance_m']:.1f} m"
        if r["cost_of_transport"] is None:
            return "too short"
        dev = r["cmt_deviation"]
        noise = r.get("deviation_noise") or 0.0
        mark = ("" if dev is None or abs(dev) <= rec["tolerance"]
                else " ≈" if abs(dev) <= noise else " ✗")
        text = (format_cost(r["cost_of_transport"]) if r.get("half_width") is None
                else format_cost_interval(r["cost_of_transport"], r["half_width"]))
        return f"{text} ({signed_percent(dev)}){mark}" if dev is not None else text

    chosen = rec["chosen_step_s"]
    rich = rec.get("richardson", {})
    rich_lines = ["| walk | limit (h → 0) | order | " + " | ".join(f"error at {h * 1e3:g} ms" for h in steps) + " |",
                  "|---|---|---" + "|---" * len(steps) + "|"]
    for w in _walks_of(rec):
        e = rich.get(json.dumps(list(w) if w else None), {})
        if not e or e.get("limit") is None:
            rich_lines.append(f"| {label(w)} | — | — |" + " — |" * len(steps))
            continue
        order = f"{e['order']:.2f}" + ("" if e["order_observed"] else " (assumed)")
        errs = [signed_percent(e["errors"].get(f"{h:g}"), 2) for h in steps]
        limit = f"{e['limit']:.4f}" + (" (noise-dominated)" if e.get("noise_dominated") else "")
        rich_lines.append(f"| {label(w)} | {limit} | {order} | " + " | ".join(errs) + " |")
    control = sorted({(r["time_step_s"], r.get("control_period_s")) for r in rec["rows"]})
    reading = clock_of_record(rec["config"]["sim"])[0]
    if reading == SimulationParams.PLANT_STEP_CLOCK:
        clock = ("The controller acts at every plant step (the paper's reading), so plant and controller are refined "
                 "together: " + ", ".join(f"{h * 1e3:g} ms" for h, c in control) + ".")
    else:
        clock = ("The controller is a fixed-rate loop, part of the robot, so the plant step alone is refined under it; "
                 "control period at each step: " + ", ".join(f"{h * 1e3:g} ms → {c * 1e3:g} ms" for h, c in control
                                                              if c is not None) + ".")
    long_run = rec.get("measure", "long-run") == "long-run"
    measured = (f"C_mt is the long-run mean after the first {TRANSIENT_M:g} m, with its 95 % interval (batch means over "
                "steps)" if long_run else "C_mt is the whole walk's, the initiation included (no interval: the walks "
                f"are too short for a long-run mean, which needs {TRANSIENT_M + LONG_RUN_M:g} m)")
    what = "long-run C_mt" if long_run else "whole walk's C_mt"
    lines = [
        f"# Time-step study: the {'long-run ' if long_run else ''}cost of transport as the plant step is halved",
        "",
        f"{rec.get('gait', 'Default gait')}, {rec['distance_m']:g} m walks from the paper's initiation; {measured}; "
        f"reference {rec['reference_s'] * 1e3:g} ms. {clock} Contact: {_contact_text(rec['config'])}. Commit {rec['versions']['git_commit']}, "
        f"Drake {rec['versions']['drake']}, {rec['date']}.",
        "",
        f"**Chosen step: {chosen * 1e3:g} ms**, the coarsest with the {what} of every walk that walks at "
        f"the reference within {100 * rec['tolerance']:g} % of it"
        + (", or within the 95 % interval of the difference (≈: indistinguishable at this length)" if long_run else "")
        + ", and every finer step too." if chosen else
        "**No step passes** the tolerance for every walk.",
        "",
        *([f"Not judged (they fall at the reference step): {', '.join(label(w) for w in rec['not_judged'])}.", ""]
          if rec["not_judged"] else []),
        "## Long-run C_mt ± 95 % (change from the reference)" if long_run else
        "## The whole walk's C_mt (change from the reference)",
        "",
        *table(cmt),
        "",
        "## Richardson's estimate from the three finest steps",
        "",
        *(["Noise-dominated: a difference between two of the three finest steps lies within its 95 % interval, "
           "so the estimate extrapolates the walks' scatter, not the discretisation.", "", *rich_lines]
          if halving(steps) else
          ["Not computed: it needs three finest steps that halve (h, h/2, h/4); the study has "
           + ", ".join(f"{h * 1e3:g} ms" for h in sorted(steps)) + "."]),
        "",
        "## The episode's C_mt (whole walk, initiation included)",
        "",
        *table(lambda r: format_cost(r.get("episode_cost_of_transport") or None, "—")),
        "",
        "## Step period after the transient (mean ± standard deviation, s)",
        "",
        *table(lambda r: (f"{r['long_run']['step_period_mean_s']:.4f} ± {r['long_run']['step_period_std_s']:.4f}"
                          if r.get("long_run") and r["long_run"]["step_period_mean_s"] else "—")),
        "",
        "## Real-time factor",
        "",
        *table(lambda r: f"{r['real_time_factor']:.1f}×"),
        "",
    ]
    return "\n".join(lines)


def figure(rec: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.0))
    steps_ms = [h * 1e3 for h in rec["steps"]]
    for w in _walks_of(rec):
        rows = [r for r in rec["rows"] if tuple(r["window"] or ()) == tuple(w or ())]
        ys = [100 * r["cmt_deviation"] if r["cmt_deviation"] is not None else float("nan") for r in rows]
        ax.plot(steps_ms, ys, "o-", label=label(w))
        for x, r in zip(steps_ms, rows):
            if not r["walked"]:
                ax.plot([x], [0], "kx", ms=9)
    band = 100 * rec["tolerance"]
    ax.axhspan(-band, band, color="0.9", zorder=0)
    ax.set_xscale("log")
    ax.set_xticks(steps_ms, [f"{x:g}" for x in steps_ms])
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax.set_xlabel("time step (ms)")
    ax.set_ylabel(f"long-run C_mt change from {rec['reference_s'] * 1e3:g} ms (%)")
    ax.set_title(f"Time-step study (×: a fall; grey: ±{100 * rec['tolerance']:g} %)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)
