"""Where a walker's step-to-step spread at its plant step comes from: the touchdown's place on the plant's grid.

A discrete plant meets the ground at the first step after the heel reaches it, so the heel lands already sunk into
the ground by up to its descent speed times the step (its first overlap), and where inside a plant step the
touchdown falls (its grid phase, (touchdown time / h) mod 1) varies from step to step. Each walk, without a window,
at each plant step:

- 110 m (the first 10 m dropped): every step's period and the grid phase of its touchdown; how much of the periods'
  variance the grid phase explains (the step periods binned by phase in BINS bins; by chance the bins explain
  (BINS - 1) / (steps - 1) of it), and the binned means;
- 30 m with the trajectory recorded (steps after 3 s): the new stance foot's overlap at its first contacting plant
  step (the deeper of heel and toe), its correlation with the step's period, and the swing foot's least clearance
  between 25 % and 75 % of the step (negative: it scuffs the ground in mid-swing).

    python benchmarks/touchdown_grid.py --gait paper --out benchmarks/results/paper-walker/touchdown-grid --h-ms 0.5 0.25

Any other change, named in the files: `--override '{"gait.motor_solve": "plant"}' --tag plant`. One JSON file per
walker and step, kept as it finishes (a rerun skips those written), and a table of all of them in `touchdown_grid.md`. A folder
holding a `touchdown_grid.md` or `.png` the script did not write is refused (exit 2); other files are left alone.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from paper_motor_clock import parse_with_change

from drake_biped.episode import run_episode
from drake_biped.kinematics import leg_points
from drake_biped.model import joint_index
from drake_biped.params import EpisodeConfig, walked_the_distance
from drake_biped.resources import load_gait
from drake_biped.versions import versions

BINS = 8
TRANSIENT_M, AFTER_S = 10.0, 3.0
MID_SWING = (0.25, 0.75)


def _sole(q: np.ndarray, leg: str) -> tuple[float, float]:
    """Heights (m) of a leg's heel and toe sphere bottoms above level ground, at configuration q."""
    i = 3 + joint_index(leg, "hip")
    p = leg_points(q[0], q[1], q[2], q[i], q[i + 1], q[i + 2])
    return p.heel_z, p.toe_z


def grid_phase_rows(config, distance_m: float) -> dict:
    """A walk's step periods after the transient, their touchdowns' grid phases, and the binned means."""
    h = config.sim.time_step_s
    r = run_episode(config.override({"sim.distance_m": distance_m, "sim.max_time_s": 6.0 * distance_m}))
    td = r.touchdowns
    t, x = td["touchdown_time_s"], td["com_x_m"]
    k = int(np.searchsorted(x - x[0], TRANSIENT_M))
    periods = np.diff(t[k:])
    phases = (t[k:-1] / h) % 1.0
    out = {"walked": walked_the_distance(r.fell, r.distance_m, distance_m), "termination": r.termination,
           "distance_m": r.distance_m, "steps": int(periods.size)}
    if periods.size < 2 * BINS:
        return out
    explained, chance, means = variance_explained_by_phase(periods, phases, BINS)
    out.update({"step_period_mean_s": float(periods.mean()), "step_period_std_s": float(periods.std(ddof=1)),
                "lag1_autocorrelation": float(np.corrcoef(periods[:-1], periods[1:])[0, 1]),
                "variance_explained_by_grid_phase": explained, "variance_explained_by_chance": chance,
                "period_by_grid_phase_s": means, "periods_s": periods.tolist(), "grid_phases": phases.tolist()})
    return out


def variance_explained_by_phase(values, phases, bins: int = BINS) -> tuple[float | None, float, list]:
    """The share of `values`' variance that their phases in [0, 1) explain, binned into `bins` equal bins
    (1 - within-bin sum of squares / total); the share bins explain by chance, (bins - 1) / (n - 1); and each
    bin's mean (None for an empty bin)."""
    values, phases = np.asarray(values, float), np.asarray(phases, float)
    which = np.minimum((phases * bins).astype(int), bins - 1)
    means = [float(values[which == b].mean()) if np.any(which == b) else None for b in range(bins)]
    within = sum(float(((values[which == b] - values[which == b].mean()) ** 2).sum())
                 for b in range(bins) if np.any(which == b))
    total = float(((values - values.mean()) ** 2).sum())
    explained = 1.0 - within / total if np.ptp(values) > 0 else None
    return explained, (bins - 1) / (values.size - 1), means


def contact_rows(config, distance_m: float = 30.0) -> dict:
    """Per step after AFTER_S: the new stance foot's first overlap (m, positive into the ground), the swing
    foot's least clearance in mid-swing (m), and the step's period."""
    r = run_episode(config.override({"sim.distance_m": distance_m, "sim.max_time_s": 6.0 * distance_m}),
                    record_trajectory=True)
    tr = r.trajectory
    t, q, right, start = tr["time"], tr["positions"], tr["stance_right"] > 0.5, tr["step_start"]
    starts = np.unique(start)
    overlap, clearance, periods = [], [], []
    for a, b in zip(starts[:-1], starts[1:]):
        idx = np.flatnonzero(start == a)
        if t[idx[0]] < AFTER_S:
            continue
        stance, swing = ("right", "left") if right[idx[0]] else ("left", "right")
        soles = np.array([_sole(q[j], stance) for j in idx])
        deepest = -soles.min(axis=1)
        touching = np.flatnonzero(deepest > 0.0)
        if touching.size == 0:
            continue
        s = (t[idx] - t[idx[0]]) / (b - a)
        mid = idx[(s > MID_SWING[0]) & (s < MID_SWING[1])]
        overlap.append(float(deepest[touching[0]]))
        clearance.append(float(min(min(_sole(q[j], swing)) for j in mid)))
        periods.append(float(b - a))
    overlap, clearance, periods = map(np.array, (overlap, clearance, periods))
    if periods.size < 3:
        return {"steps": int(periods.size)}
    return {"steps": int(periods.size),
            "first_overlap_m": {"min": float(overlap.min()), "max": float(overlap.max())},
            "period_vs_first_overlap_correlation": float(np.corrcoef(overlap, periods)[0, 1]),
            "mid_swing_clearance_m": {"min": float(clearance.min()), "median": float(np.median(clearance)),
                                      "max": float(clearance.max())},
            "mid_swing_scuffs": int((clearance < 0.0).sum())}


def _row_text(name: str, d: dict) -> str:
    g, c = d["grid"], d["contact"]
    if not g["walked"] or "step_period_std_s" not in g:
        return f"| {name} | {g.get('termination', 'fell')} at {g['distance_m']:.1f} m ({g['steps']} steps) | | | | |"
    return (f"| {name} | {1e3 * g['step_period_std_s']:.2f} ms | {g['variance_explained_by_grid_phase']:.2f} "
            f"(chance {g['variance_explained_by_chance']:.2f}) | "
            f"{1e3 * (max(v for v in g['period_by_grid_phase_s'] if v) - min(v for v in g['period_by_grid_phase_s'] if v)):.1f} ms | "
            f"{1e3 * c['first_overlap_m']['min']:.2f}–{1e3 * c['first_overlap_m']['max']:.2f} mm, "
            f"r {c['period_vs_first_overlap_correlation']:+.2f} | "
            f"{1e3 * c['mid_swing_clearance_m']['median']:+.2f} mm, {c['mid_swing_scuffs']} of {c['steps']} |")


def _figure(records: dict, path: Path) -> None:
    """Each walk's step periods against their touchdowns' grid phases, less the walk's mean, one panel a walk."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    walks = {k: r["grid"] for k, r in records.items() if r["grid"]["walked"] and "periods_s" in r["grid"]}
    if not walks:
        return
    columns = min(4, len(walks))
    rows = -(-len(walks) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(3.2 * columns, 2.6 * rows), sharey=True, squeeze=False)
    for ax, (name, g) in zip(axes.flat, walks.items()):
        periods = 1e3 * (np.array(g["periods_s"]) - g["step_period_mean_s"])
        ax.plot(g["grid_phases"], periods, ".", ms=4)
        ax.set_title(f"{name}\nsd {1e3 * g['step_period_std_s']:.2f} ms, grid phase "
                     f"{g['variance_explained_by_grid_phase']:.2f}", fontsize=8)
        ax.set_xlim(0, 1)
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(walks):]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("touchdown's phase on the plant's grid")
    for ax in axes[:, 0]:
        ax.set_ylabel("step period − mean (ms)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


TABLE_HEADER = ("| walk | step period sd | variance the grid phase explains | range of the phase-binned means | "
                "first overlap, its correlation with the period | mid-swing clearance (median), steps scuffing |\n"
                "|---|---|---|---|---|---|\n")
COMMAND = "python benchmarks/touchdown_grid.py"


def own_records(out: Path, command: str = COMMAND) -> dict:
    """The records a script wrote in `out` (by their `command`: this one's by default), by name; any other JSON
    file is left alone."""
    records = {}
    for path in sorted(out.glob("*.json")):
        try:
            record = json.loads(path.read_text())
        except (OSError, ValueError):
            continue
        if isinstance(record, dict) and str(record.get("command", "")).startswith(command):
            records[path.stem] = record
    return records


def foreign_summary(out: Path) -> Path | None:
    """A touchdown_grid.md in `out` this script did not write, or a touchdown_grid.png without its table: the
    summary would replace a file of the user's. None when there is none."""
    table, figure = out / "touchdown_grid.md", out / "touchdown_grid.png"
    ours = table.is_file() and table.read_text(errors="replace").startswith(TABLE_HEADER)
    return next((path for path in (table, figure) if path.exists() and not ours), None)


def pending_steps(args: argparse.Namespace) -> Iterator[tuple[float, Path, EpisodeConfig]]:
    """For each of args.h_ms (ms) whose record is not yet in args.out: the step, the record's path (the gait's file
    name, args.tag, the step) and the gait (args.gait with args.override) at that plant step."""
    base = load_gait(args.gait).override(args.override) if args.override else load_gait(args.gait)
    stem = Path(args.gait).stem + (f"-{args.tag}" if args.tag else "")
    for h_ms in args.h_ms:
        path = args.out / f"{stem}-h{h_ms:g}ms.json"
        if not path.exists():
            yield h_ms, path, base.override({"sim.time_step_s": h_ms * 1e-3})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--gait", default="paper", help="a shipped gait's name or a parameter file")
    parser.add_argument("--h-ms", type=float, nargs="+", default=[0.5, 0.25])
    parser.add_argument("--distance", type=float, default=110.0)
    args = parse_with_change(parser)
    foreign = foreign_summary(args.out)
    if foreign is not None:
        print(f"touchdown_grid.py: --out {args.out} holds {foreign.name}, which this script did not write; choose "
              "another folder", file=sys.stderr)
        raise SystemExit(2)
    for h_ms, path, config in pending_steps(args):
        start = time.perf_counter()
        record = {"gait": args.gait, "override": args.override, "time_step_s": h_ms * 1e-3,
                  "grid": grid_phase_rows(config, args.distance), "contact": contact_rows(config),
                  "wall_time_s": None, "config": config.to_dict(), "versions": versions(),
                  "command": f"{COMMAND} " + " ".join(
                      [f"--gait {args.gait}", f"--out {args.out}", f"--h-ms {h_ms:g}", f"--distance {args.distance:g}"]
                      + ([f"--override '{json.dumps(args.override)}' --tag {args.tag}"] if args.tag else []))}
        record["wall_time_s"] = time.perf_counter() - start
        path.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n")
        print(_row_text(path.stem, record), flush=True)
    records = own_records(args.out)
    rows = [_row_text(name, record) for name, record in records.items()]
    _figure(records, args.out / "touchdown_grid.png")
    (args.out / "touchdown_grid.md").write_text(TABLE_HEADER + "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
