"""Time-step study: C_mt, speed and step period of a gait (the default one unless given), with no window
and with a set of windows (the default gait's acceptance windows unless given), against the plant (and
control) time step. The default step is the largest whose
C_mt stays within 2 % of the 0.5 ms reference for every walk that walks at the reference step.

`drake-biped time-step-study --out DIR` (or `python benchmarks/time_step_study.py --out DIR`) writes
DIR/time_step_study.json (every episode, versions), .md and .png. As with `drake-biped walk --time-step`,
the controller runs at the time step. Episodes run on Dask (a LocalCluster, or a scheduler's address).
"""

from __future__ import annotations

import dataclasses
import json
import time
from dataclasses import dataclass
from pathlib import Path

from drake_biped.analysis.series import signed_percent
from drake_biped.experiments.executor import episode_task, map_ordered
from drake_biped.params import EpisodeConfig, ParameterError, TorqueFreeWindow
from drake_biped.records import read_json, save_figure, write_text_atomic
from drake_biped.versions import versions

WALKS = [None, (0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.35, 0.65), (0.2, 0.7)]
TOLERANCE = 0.02


def label(window) -> str:
    return "no window" if window is None else f"window {window[0]:g}–{window[1]:g} s"


def study(steps: list[float], reference: float, distance: float, client, progress: bool = True,
          config: EpisodeConfig | None = None, windows=None) -> dict:
    base = config if config is not None else EpisodeConfig()
    walk_list = WALKS if windows is None else [None, *map(tuple, windows)]
    jobs = []
    for h in steps:
        for w in walk_list:
            sim = dataclasses.replace(base.sim, time_step_s=h, control_period_s=h, distance_m=distance,
                                      max_time_s=max(base.sim.max_time_s, 6.0 * distance))
            window = TorqueFreeWindow(*w) if w else TorqueFreeWindow(0.0, 0.0)
            jobs.append((h, w, base.replace(sim=sim, window=window).to_dict()))
    from tqdm import tqdm

    with tqdm(total=len(jobs), desc="time-step study", unit="episode", disable=not progress) as bar:
        results = map_ordered(client, episode_task, [j[2] for j in jobs], lambda n, r: bar.update(1))
    rows = []
    for (h, w, _), r in zip(jobs, results):
        rows.append({
            "time_step_s": h,
            "window": list(w) if w else None,
            "walked": not r["fell"] and r["distance_m"] >= distance - 1e-6,
            "distance_m": r["distance_m"],
            "cost_of_transport": r["cost_of_transport"],
            "mean_speed_mps": r["mean_speed_mps"],
            "step_period_s": r["step_period_s"],
            "real_time_factor": r["real_time_factor"],
        })
    return {"steps": steps, "reference_s": reference, "distance_m": distance, "tolerance": TOLERANCE,
            "walks": [list(w) if w else None for w in walk_list], "config": base.to_dict(),
            "rows": rows, **choose_step(rows, steps, reference, TOLERANCE)}


def _walks_of(rec: dict) -> list:
    """The record's walks (records written before walks were recorded used WALKS)."""
    return [tuple(w) if w else None for w in rec["walks"]] if "walks" in rec else WALKS


def choose_step(rows: list[dict], steps: list[float], reference: float, tolerance: float) -> dict:
    """Judge each step against the reference and choose the default.

    rows: one per (time_step_s, window) with "walked" and "cost_of_transport"; each gains "cmt_deviation"
    (relative to the same walk at the reference step, None when either fell). A walk that falls at the
    reference has no reference C_mt: it is listed in "not_judged". A step passes when every judged walk
    walks there with |deviation| <= tolerance. The chosen step is the largest one at or above the
    reference such that it and every step between it and the reference pass; finer steps are shown as a
    convergence check of the reference itself.
    """
    ref = {tuple(r["window"] or ()): r for r in rows if r["time_step_s"] == reference}
    for r in rows:
        base = ref.get(tuple(r["window"] or ()))
        ok = r["walked"] and base is not None and base["walked"]
        r["cmt_deviation"] = (r["cost_of_transport"] / base["cost_of_transport"] - 1.0) if ok else None
    judged = {key for key, r in ref.items() if r["walked"]}
    passing = [h for h in steps
               if all(r["cmt_deviation"] is not None and abs(r["cmt_deviation"]) <= tolerance
                      for r in rows if r["time_step_s"] == h and tuple(r["window"] or ()) in judged)]
    chosen = None
    for h in sorted(x for x in steps if x >= reference):
        if h not in passing:
            break
        chosen = h
    return {"passing_steps": passing, "chosen_step_s": chosen,
            "not_judged": [list(k) or None for k in ref if k not in judged]}


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
            return f"fell at {r['distance_m']:.1f} m"
        dev = r["cmt_deviation"]
        mark = "" if dev is None or abs(dev) <= rec["tolerance"] else " ✗"
        return f"{r['cost_of_transport']:.4f} ({signed_percent(dev)}){mark}" if dev is not None else f"{r['cost_of_transport']:.4f}"

    chosen = rec["chosen_step_s"]
    lines = [
        "# Time-step study",
        "",
        f"{rec.get('gait', 'Default gait')}, {rec['distance_m']:g} m walks from the paper's initiation; plant and controller at the time "
        f"step; reference {rec['reference_s'] * 1e3:g} ms. Commit {rec['versions']['git_commit']}, "
        f"Drake {rec['versions']['drake']}, {rec['date']}.",
        "",
        f"**Chosen step: {chosen * 1e3:g} ms**, the largest with the C_mt of every walk that walks at the "
        f"reference within {100 * rec['tolerance']:g} % of it." if chosen else
        "**No step passes** the tolerance for every walk.",
        "",
        *([f"Not judged (they fall at the reference step): {', '.join(label(w) for w in rec['not_judged'])}.", ""]
          if rec["not_judged"] else []),
        "## C_mt (change from the reference)",
        "",
        *table(cmt),
        "",
        "## Speed (m/s)",
        "",
        *table(lambda r: f"{r['mean_speed_mps']:.3f}" if r["walked"] else "—"),
        "",
        "## Step period (s)",
        "",
        *table(lambda r: f"{r['step_period_s']:.3f}" if r["walked"] and r["step_period_s"] else "—"),
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
    ax.set_ylabel(f"C_mt change from {rec['reference_s'] * 1e3:g} ms (%)")
    ax.set_title("Time-step study (×: a fall; grey: ±2 %)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


@dataclass(frozen=True)
class TimeStepSettings:
    """The time steps compared (s), the reference among them, the distance walked, the gait (None: the
    default one; its own time step is replaced by each of `steps`), its name for the report, and the
    windows (t1, t2) compared with none (None: those of WALKS)."""

    steps: tuple[float, ...] = (0.00025, 0.0005, 0.001, 0.002, 0.005)
    reference_s: float = 0.0005
    distance_m: float = 10.0
    config: EpisodeConfig | None = None
    gait: str = "Default gait"
    windows: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self) -> None:
        if self.reference_s not in self.steps:
            raise ParameterError(f"--reference {self.reference_s!r} must be one of --steps {sorted(self.steps)}")
        for t1, t2 in self.windows or ():
            if not 0.0 <= t1 < t2:
                raise ParameterError(f"--windows {t1:g}-{t2:g}: need 0 <= t1 < t2")


def run(settings: TimeStepSettings, out: Path, client=None, progress: bool = True) -> dict:
    """Run the study on `client` (a LocalCluster when None); write time_step_study.json, .md and .png into
    `out`; return the record."""
    from drake_biped.experiments.executor import client_or_local

    out = Path(out)
    steps = sorted(settings.steps)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    with client_or_local(client) as c:
        rec = study(steps, settings.reference_s, settings.distance_m, c, progress, settings.config,
                    settings.windows)
    rec.update(gait=settings.gait, date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), versions=versions(), wall_s=time.perf_counter() - t0)
    write_text_atomic(out / "time_step_study.json", json.dumps(rec, indent=2) + "\n")
    replot(out)
    return rec


def replot(out: Path) -> dict:
    """Redraw the Markdown and the figure from out/time_step_study.json."""
    rec = read_json(out / "time_step_study.json", "--replot")
    write_text_atomic(out / "time_step_study.md", markdown(rec))
    figure(rec, out / "time_step_study.png")
    return rec
