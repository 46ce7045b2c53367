"""How smooth is the step-to-step map? Kicks of the swing hip and sub-millisecond shifts of a window.

    python benchmarks/kick_sweep.py --tree TREE --out sweep.json [--workers 2]
    python benchmarks/kick_sweep.py --compare BEFORE.json AFTER.json --md kick-sweep.md

The first form runs, with PYTHONPATH = TREE (any checkout of the project), the default gait's 6 m walk
and:
- 33 kicks of the swing hip's angle, -4 ... +4 mrad, 30 ms before touchdown 8: the section state at
  touchdown 8 (angle, rate) and touchdown 9's time, angle and rate, against the kick;
- 21 shifts of the window 0.2-0.5 s by 0 ... 2 ms in 0.1 ms steps (t1 and t2 moved together): C_mt
  against the shift.
For each response it reports the slope of a straight-line fit and its roughness: the RMS residual of a
cubic fit divided by the response's range over the sweep (0 for a smooth curve, about 0.3 for noise). The
second form puts two such files side by side in Markdown.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

KICKS = np.linspace(-4e-3, 4e-3, 33)
SHIFTS = np.arange(21) * 1e-4
STEP = 8
LEAD_S = 0.03
DISTANCE_M = 6.0

CHILD = r"""
import json, sys
from multiprocessing import Pool
from drake_biped.episode import Kick, run_episode
from drake_biped.params import EpisodeConfig, SimulationParams, TorqueFreeWindow

plan = json.loads(sys.argv[1])
base = EpisodeConfig(sim=SimulationParams(distance_m=plan["distance"]))

def steps(r):
    return {s.index: [s.touchdown_time_s, s.hip_angle_rad, s.hip_rate_radps] for s in r.steps}

def job(item):
    kind, value = item
    if kind == "reference":
        r = run_episode(base)
    elif kind == "kick":
        r = run_episode(base, kick=Kick(plan["kick_time"], hip_angle_rad=value))
    else:
        r = run_episode(base.replace(window=TorqueFreeWindow(0.2 + value, 0.5 + value)))
    return {"steps": steps(r), "cost_of_transport": r.cost_of_transport, "fell": r.fell}

items = [("reference", 0.0)] if plan["kick_time"] is None else (
    [("kick", k) for k in plan["kicks"]] + [("shift", s) for s in plan["shifts"]])
with Pool(plan["workers"]) as pool:
    print(json.dumps(pool.map(job, items, chunksize=1)))
"""


def _child(tree: Path, plan: dict) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(plan)], env=env, cwd=tree, capture_output=True,
                         text=True)
    if out.returncode != 0:
        raise SystemExit(f"kick_sweep: the run in {tree} failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def roughness(x: np.ndarray, y: np.ndarray) -> float:
    """RMS residual of a cubic fit of y(x), divided by the range of y (0: smooth)."""
    span = float(np.ptp(y))
    if span == 0.0:
        return 0.0
    fit = np.polyval(np.polyfit(x, y, 3), x)
    return float(np.sqrt(np.mean((y - fit) ** 2)) / span)


def distinct(y) -> int:
    """How many different values the response takes (to 1e-9): a staircase takes few."""
    return len({round(float(v), 9) for v in y if v is not None})


def response(x: np.ndarray, y: np.ndarray) -> dict:
    return {"slope": float(np.polyfit(x, y, 1)[0]), "range": float(np.ptp(y)), "roughness": roughness(x, y),
            "distinct": distinct(y)}


def sweep(tree: Path, workers: int) -> dict:
    plan = {"distance": DISTANCE_M, "kick_time": None, "kicks": [], "shifts": [], "workers": 1}
    reference = _child(tree, plan)[0]
    t8 = reference["steps"][str(STEP)][0]
    plan.update(kick_time=t8 - LEAD_S, kicks=KICKS.tolist(), shifts=SHIFTS.tolist(), workers=workers)
    runs = _child(tree, plan)
    kicks, shifts = runs[: len(KICKS)], runs[len(KICKS):]
    rows = {}
    for name, step, col in (("td8_angle", STEP, 1), ("td8_rate", STEP, 2), ("td9_time", STEP + 1, 0),
                            ("td9_angle", STEP + 1, 1), ("td9_rate", STEP + 1, 2)):
        y = np.array([r["steps"][str(step)][col] for r in kicks])
        rows[name] = {**response(KICKS, y), "values": y.tolist()}
    fell = [r["fell"] for r in shifts]
    cmt = np.array([r["cost_of_transport"] if not r["fell"] else np.nan for r in shifts], dtype=float)
    ok = np.isfinite(cmt)
    rows["cmt_vs_shift"] = {**(response(SHIFTS[ok], cmt[ok]) if ok.sum() > 4 else {}),
                            "values": [None if not np.isfinite(c) else float(c) for c in cmt], "falls": sum(fell)}
    return {"tree": str(tree), "kicks_rad": KICKS.tolist(), "shifts_s": SHIFTS.tolist(), "kick_time_s": t8 - LEAD_S,
            "responses": rows}


LABELS = {
    "td8_angle": "section angle at touchdown 8 (rad per rad of kick)",
    "td8_rate": "section rate at touchdown 8 (rad/s per rad)",
    "td9_time": "time of touchdown 9 (s per rad)",
    "td9_angle": "section angle at touchdown 9 (rad per rad)",
    "td9_rate": "section rate at touchdown 9 (rad/s per rad)",
    "cmt_vs_shift": "C_mt against a shift of the window 0.2-0.5 s (per s)",
}


def compare(before: dict, after: dict) -> str:
    lines = ["| response | before: slope | roughness | distinct values | after: slope | roughness | distinct values |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for key, label in LABELS.items():
        cells = []
        for rec in (before, after):
            r = rec["responses"][key]
            cells += [f"{r.get('slope', float('nan')):.4g}", f"{r.get('roughness', float('nan')):.3f}",
                      f"{distinct(r['values'])} of {len(r['values'])}"]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--tree", type=Path)
    p.add_argument("--out", type=Path)
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--compare", nargs=2, type=Path, metavar=("BEFORE", "AFTER"))
    p.add_argument("--md", type=Path)
    a = p.parse_args(argv)
    if a.compare:
        text = compare(*(json.loads(f.read_text()) for f in a.compare))
        if a.md:
            a.md.write_text(text)
        print(text, end="")
        return 0
    if a.tree is None or a.out is None:
        p.error("--tree and --out are required (or --compare)")
    result = sweep(a.tree.resolve(), a.workers)
    a.out.write_text(json.dumps(result, indent=1) + "\n")
    for key, row in result["responses"].items():
        print(f"{key:14s} slope {row.get('slope', float('nan')):+.4g}  roughness {row.get('roughness', float('nan')):.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
