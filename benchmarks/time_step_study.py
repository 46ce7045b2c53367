"""Time-step study: C_mt, speed and step period of the default gait, with no window and with the
acceptance windows, against the plant (and control) time step; the default step is the largest whose
C_mt stays within 2 % of the 0.5 ms reference for every walk.

    python benchmarks/time_step_study.py --out out/time-step-study       # about 2 minutes on 2 workers
    python benchmarks/time_step_study.py --out DIR --steps 0.00025,0.0005,0.001 --distance 5

Writes OUT/time_step_study.json (every episode, versions), OUT/time_step_study.md and
OUT/time_step_study.png. As with `drake-biped walk --time-step`, the controller runs at the time step.
Episodes run on a Dask LocalCluster (--workers) or an existing scheduler (--scheduler).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from drake_biped.parallel import dask_client, episode_task, map_ordered
from drake_biped.params import EpisodeConfig, SimulationParams, TorqueFreeWindow
from drake_biped.versions import versions

WALKS = [None, (0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.35, 0.65), (0.2, 0.7)]
TOLERANCE = 0.02


def label(window) -> str:
    return "no window" if window is None else f"window {window[0]:g}–{window[1]:g} s"


def study(steps: list[float], reference: float, distance: float, client) -> dict:
    jobs = []
    for h in steps:
        for w in WALKS:
            sim = SimulationParams(time_step_s=h, control_period_s=h, distance_m=distance)
            window = TorqueFreeWindow(*w) if w else TorqueFreeWindow(0.0, 0.0)
            jobs.append((h, w, EpisodeConfig(sim=sim, window=window).to_dict()))
    from tqdm import tqdm

    with tqdm(total=len(jobs), desc="time-step study", unit="episode") as bar:
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
    ref = {tuple(r["window"] or ()): r for r in rows if r["time_step_s"] == reference}
    for r in rows:
        base = ref.get(tuple(r["window"] or ()))
        ok = r["walked"] and base is not None and base["walked"]
        r["cmt_deviation"] = (r["cost_of_transport"] / base["cost_of_transport"] - 1.0) if ok else None
    # A walk that falls at the reference step has no reference C_mt: it is reported, not judged.
    judged = {key for key, r in ref.items() if r["walked"]}
    passing = [h for h in steps
               if all(r["cmt_deviation"] is not None and abs(r["cmt_deviation"]) <= TOLERANCE
                      for r in rows if r["time_step_s"] == h and tuple(r["window"] or ()) in judged)]
    # The largest step such that it, and every step between it and the reference, passes. Steps finer
    # than the reference are shown as a convergence check of the reference itself.
    chosen = None
    for h in sorted(x for x in steps if x >= reference):
        if h not in passing:
            break
        chosen = h
    return {"steps": steps, "reference_s": reference, "distance_m": distance, "tolerance": TOLERANCE,
            "rows": rows, "passing_steps": passing, "chosen_step_s": chosen,
            "not_judged": [list(k) or None for k in ref if k not in judged]}


def markdown(rec: dict) -> str:
    steps = rec["steps"]
    head = "| walk | " + " | ".join(f"{h * 1e3:g} ms" for h in steps) + " |"
    sep = "|---" * (len(steps) + 1) + "|"
    by = {(r["time_step_s"], tuple(r["window"] or ())): r for r in rec["rows"]}

    def table(fmt) -> list[str]:
        out = [head, sep]
        for w in WALKS:
            cells = [fmt(by[(h, tuple(w or ()))]) for h in steps]
            out.append(f"| {label(w)} | " + " | ".join(cells) + " |")
        return out

    def cmt(r):
        if not r["walked"]:
            return f"fell at {r['distance_m']:.1f} m"
        dev = r["cmt_deviation"]
        mark = "" if dev is None or abs(dev) <= rec["tolerance"] else " ✗"
        return f"{r['cost_of_transport']:.4f} ({100 * dev:+.1f} %){mark}" if dev is not None else f"{r['cost_of_transport']:.4f}"

    chosen = rec["chosen_step_s"]
    lines = [
        "# Time-step study",
        "",
        f"Default gait, {rec['distance_m']:g} m walks from the paper's initiation; plant and controller at the time "
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
    for w in WALKS:
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
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=Path("out/time-step-study"))
    p.add_argument("--steps", default="0.00025,0.0005,0.001,0.002,0.005", help="time steps (s), comma-separated")
    p.add_argument("--reference", type=float, default=0.0005, help="reference step (s), one of --steps")
    p.add_argument("--distance", type=float, default=10.0)
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--scheduler", default=None)
    p.add_argument("--replot", action="store_true", help="redraw the Markdown and figure from OUT's JSON")
    args = p.parse_args(argv)
    if args.replot:
        rec = json.loads((args.out / "time_step_study.json").read_text())
        (args.out / "time_step_study.md").write_text(markdown(rec))
        figure(rec, args.out / "time_step_study.png")
        return 0
    try:
        steps = sorted(float(s) for s in args.steps.split(","))
    except ValueError:
        p.error(f"--steps {args.steps!r}: expected comma-separated numbers")
    if any(h <= 0 for h in steps) or args.reference not in steps or args.distance <= 0:
        p.error("--steps must be positive and include --reference; --distance must be positive")
    args.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
        rec = study(steps, args.reference, args.distance, client)
    rec.update(date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), versions=versions(), wall_s=time.perf_counter() - t0)
    (args.out / "time_step_study.json").write_text(json.dumps(rec, indent=2) + "\n")
    text = markdown(rec)
    (args.out / "time_step_study.md").write_text(text)
    figure(rec, args.out / "time_step_study.png")
    print(text)
    print(f"wall time {rec['wall_s']:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
