"""Closed-loop real-time factor of two source trees of drake-biped, measured interleaved on one machine.

    python benchmarks/compare_rtf.py BEFORE_TREE AFTER_TREE [--rounds 5] [--episodes 3] [--distance 10]

Each round runs, for each tree in turn, a fresh process (PYTHONPATH = the tree) that walks the default gait
`--episodes` times and reports the real-time factor of each walk (simulated time / wall time of
Simulator.AdvanceTo; the first walk of a process also builds its diagram, which is not timed). Rounds
alternate the trees, so a change of machine load affects both alike; the table gives medians and the ratio.
A tree is any checkout of the project (e.g. `git worktree add /tmp/before COMMIT`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

CHILD = """
import json, sys
from drake_biped.episode import run_episode
from drake_biped.params import EpisodeConfig, SimulationParams
config = EpisodeConfig(sim=SimulationParams(distance_m={distance}))
print(json.dumps([run_episode(config).real_time_factor for _ in range({episodes})]))
"""


def measure(tree: Path, episodes: int, distance: float) -> list[float]:
    env = dict(os.environ, PYTHONPATH=str(tree))
    code = CHILD.format(episodes=episodes, distance=distance)
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tree, capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--episodes", type=int, default=3)
    p.add_argument("--distance", type=float, default=10.0)
    args = p.parse_args(argv)
    samples: dict[str, list[float]] = {"before": [], "after": []}
    for r in range(args.rounds):
        order = ("before", "after") if r % 2 == 0 else ("after", "before")
        for name in order:
            samples[name] += measure(getattr(args, name), args.episodes, args.distance)
        print(f"round {r + 1}: " + ", ".join(f"{k} {statistics.median(v):.3f}" for k, v in samples.items()),
              file=sys.stderr)
    med = {k: statistics.median(v) for k, v in samples.items()}
    print(json.dumps({"samples": samples, "median": med, "after_over_before": med["after"] / med["before"]}))
    print(f"| tree | episodes | median real-time factor |\n|---|---|---|\n"
          f"| before ({args.before}) | {len(samples['before'])} | {med['before']:.3f} |\n"
          f"| after ({args.after}) | {len(samples['after'])} | {med['after']:.3f} |\n\n"
          f"after / before = {med['after'] / med['before']:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
