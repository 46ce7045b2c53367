"""Wall time of one learning run in two source trees of drake-biped, measured interleaved on one machine.

    python benchmarks/compare_learning.py BEFORE_TREE AFTER_TREE [--rounds 2] [--trials 2] [--episodes 60]
                                          [--workers 2] [--params NAME] [--json PATH]

Each round runs, for each tree in turn, `drake-biped learn` (GARB with the paper's settings on the default
gait, or `--params`) in a fresh process and output folder, and reads its run.json: the learning's wall time
and episodes per minute (the final policies' re-walks are not counted there). The trials' records of the two
trees must be the same to the byte (a change of speed, not of results); the table gives medians and the ratio.
A tree is any checkout of the project (e.g. `git worktree add /tmp/before COMMIT`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def learn(tree: Path, out: Path, args: argparse.Namespace) -> dict:
    command = [sys.executable, "-m", "drake_biped", "learn", "--trials", str(args.trials), "--episodes",
               str(args.episodes), "--workers", str(args.workers), "--out", str(out)]
    if args.params:
        command += ["--params", args.params]
    t0 = time.perf_counter()
    subprocess.run(command, cwd=tree, env={**os.environ, "PYTHONPATH": str(tree)}, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    run = json.loads((out / "run.json").read_text())
    return {"process_wall_s": wall, "learning_wall_s": run["learning_wall_s"],
            "episodes_per_min": run["episodes_per_min"]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--trials", type=int, default=2)
    parser.add_argument("--episodes", type=int, default=60)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--params", default=None)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    trees = {"before": args.before.resolve(), "after": args.after.resolve()}
    rows: dict[str, list[dict]] = {name: [] for name in trees}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for name, tree in trees.items():
                rows[name].append(learn(tree, Path(tmp) / f"{name}-{r}", args))
                print(f"round {r}: {name} {rows[name][-1]}", flush=True)
        trials = sorted(p.name for p in (Path(tmp) / "before-0" / "trials").glob("trial_*.json"))
        same = all((Path(tmp) / "before-0" / "trials" / t).read_bytes()
                   == (Path(tmp) / "after-0" / "trials" / t).read_bytes() for t in trials)
    med = {name: {k: statistics.median(x[k] for x in rs) for k in rs[0]} for name, rs in rows.items()}
    ratio = med["after"]["episodes_per_min"] / med["before"]["episodes_per_min"]
    print("| tree | learning wall (s) | episodes/min |\n|---|---:|---:|")
    for name in trees:
        print(f"| {name} ({trees[name]}) | {med[name]['learning_wall_s']:.1f} | {med[name]['episodes_per_min']:.1f} |")
    print(f"after / before: {ratio:.2f} x episodes per minute; trial records the same to the byte: {same}")
    if args.json:
        args.json.write_text(json.dumps({"settings": {**vars(args), "before": str(trees["before"]),
                                                      "after": str(trees["after"]), "json": str(args.json)},
                                         "rounds": rows, "medians": med, "ratio": ratio,
                                         "trial_records_identical": same}, indent=1) + "\n")
    if not same:
        sys.exit(1)


if __name__ == "__main__":
    main()
