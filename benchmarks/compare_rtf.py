"""Closed-loop real-time factor of two source trees of drake-biped, measured interleaved on one machine, and
the ceiling a Python controller can reach.

    python benchmarks/compare_rtf.py BEFORE_TREE AFTER_TREE [--rounds 5] [--episodes 3] [--distance 10]
                                     [--learning 40] [--gait NAME] [--after-gait NAME_OR_FILE]

Each round runs, for each tree in turn, a fresh process (PYTHONPATH = the tree) that walks the shipped gait
`--gait` (default `paper`; named, since trees differ in their default gait) at its own step (the after tree
`--after-gait` where given, a name or a parameter file its tree reads) `--episodes` times and reports the real-time factor of each walk (simulated time / wall time of
Simulator.AdvanceTo; the first walk of a process also builds its diagram, which is not timed) and its C_mt.
In the same round, a process of the after tree measures the ceiling on the same walk: the plant alone
replaying the walk's logged torques (no Python during the simulation), the same plant stepped by a Python
loop instead of the Simulator (the floor of an episode that steps the plant itself, episode._step_directly),
and the plant with an empty Python discrete update at the control rate (the cost of a Python system in the
Simulator's loop). Rounds alternate the trees, so a
change of machine load affects all of them alike; the table gives medians and the ratios.
`--learning N` also times N episodes as a learning run starts them (benchmarks/bench.py learning_mix) on a
2-worker Dask cluster, once per tree per round: episodes per minute.
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

HERE = Path(__file__).resolve().parent

CLOSED_LOOP = """
import json
from drake_biped.episode import run_episode
from drake_biped.resources import load_gait
gait = {gait!r}
config = load_gait(gait).override({{"sim.distance_m": {distance}}})
walks = [run_episode(config) for _ in range({episodes})]
print(json.dumps({{"rtf": [w.real_time_factor for w in walks], "cmt": [w.cost_of_transport for w in walks]}}))
"""

CEILING = """
import json, sys
sys.path.insert(0, {bench!r})
import bench
from drake_biped.episode import run_episode
from drake_biped.resources import load_gait
gait = {gait!r}
config = load_gait(gait).override({{"sim.distance_m": {distance}}})
ref = run_episode(config, record_trajectory=True)
times, torques = ref.trajectory["time"], ref.trajectory["actuation"]  # the torques the plant applied
end = float(times[-1])
period = config.sim.update_period_s
out = {{"plant": [], "direct": [], "empty": []}}
for _ in range({episodes}):
    out["plant"].append(end / bench.replay(config, times, torques, end)[0])
    out["direct"].append(end / bench.replay_directly(config, times, torques, end)[0])
    out["empty"].append(end / bench.replay(config, times, torques, end, bench.EmptyUpdate(period))[0])
print(json.dumps(out))
"""

LEARNING = """
import json, sys
sys.path.insert(0, {bench!r})
import bench
if __name__ == "__main__":
    print(json.dumps(bench.learning_mix({episodes}, 2)))
"""


def run_child(tree: Path, code: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree))
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tree, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"compare_rtf: the measurement in {tree} failed:\n{out.stderr[-2000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("before", type=Path)
    p.add_argument("after", type=Path)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--episodes", type=int, default=3)
    p.add_argument("--distance", type=float, default=10.0)
    p.add_argument("--learning", type=int, default=0, help="episodes of the learning mix per tree and round (0: none)")
    p.add_argument("--json", type=Path, help="also write every sample here")
    p.add_argument("--gait", default="paper", help="the shipped gait to walk, at its own step (default: paper; "
                   "fast_servo is named default in trees before the paper's walker became the default)")
    p.add_argument("--after-gait", default=None, help="what the after tree walks instead (a shipped name or a "
                   "parameter file), and its ceiling replays: a reading the before tree does not have")
    args = p.parse_args(argv)
    trees = {"before": args.before.resolve(), "after": args.after.resolve()}
    rtf: dict[str, list[float]] = {"before": [], "after": []}
    cmt: dict[str, list[float]] = {"before": [], "after": []}
    ceiling: dict[str, list[float]] = {"plant": [], "direct": [], "empty": []}
    learning: dict[str, list[float]] = {"before": [], "after": []}
    after_gait = args.gait if args.after_gait is None else str(Path(args.after_gait).resolve()) \
        if Path(args.after_gait).exists() else args.after_gait
    closed = {name: CLOSED_LOOP.format(episodes=args.episodes, distance=args.distance,
                                       gait=after_gait if name == "after" else args.gait) for name in trees}
    for r in range(args.rounds):
        order = ("before", "after") if r % 2 == 0 else ("after", "before")
        for name in order:
            got = run_child(trees[name], closed[name])
            rtf[name] += got["rtf"]
            cmt[name] += got["cmt"]
        got = run_child(trees["after"], CEILING.format(bench=str(HERE), episodes=args.episodes, distance=args.distance,
                                                       gait=after_gait))
        for k in ceiling:
            ceiling[k] += got[k]
        if args.learning:
            for name in order:
                learning[name].append(run_child(trees[name], LEARNING.format(bench=str(HERE), episodes=args.learning))
                                      ["episodes_per_min"])
        print(f"round {r + 1}: " + ", ".join(f"{k} {statistics.median(v):.3f}" for k, v in {**rtf, **ceiling}.items()),
              file=sys.stderr)
    med = {k: statistics.median(v) for k, v in {**rtf, **ceiling}.items()}
    record = {"trees": {k: str(v) for k, v in trees.items()}, "gait": args.gait,
              "after_gait": after_gait,
              "rounds": args.rounds, "episodes": args.episodes,
              "distance_m": args.distance, "closed_loop_rtf": rtf, "cost_of_transport": cmt, "ceiling_rtf": ceiling,
              "learning_episodes_per_min": learning, "median": med,
              "after_over_before": med["after"] / med["before"]}
    if args.json:
        args.json.write_text(json.dumps(record, indent=1) + "\n")
    print(json.dumps({"median": med, "after_over_before": record["after_over_before"]}))
    cmt_b, cmt_a = cmt["before"][0], cmt["after"][0]
    lines = [
        "| what | samples | median real-time factor | of the plant alone |",
        "|---|---|---|---|",
        f"| plant alone, replaying the walk's torques | {len(ceiling['plant'])} | {med['plant']:.3f} | 1.00 |",
        f"| plant alone, stepped by a Python loop (no Simulator) | {len(ceiling['direct'])} | {med['direct']:.3f} | "
        f"{med['direct'] / med['plant']:.2f} |",
        f"| plant + an empty Python update at the control rate | {len(ceiling['empty'])} | {med['empty']:.3f} | "
        f"{med['empty'] / med['plant']:.2f} |",
        f"| closed loop, before ({args.before}) | {len(rtf['before'])} | {med['before']:.3f} | "
        f"{med['before'] / med['plant']:.2f} |",
        f"| closed loop, after ({args.after}) | {len(rtf['after'])} | {med['after']:.3f} | "
        f"{med['after'] / med['plant']:.2f} |",
        "",
        f"after / before = {med['after'] / med['before']:.3f}; C_mt before {cmt_b!r}, after {cmt_a!r} "
        f"({'identical' if cmt_b == cmt_a else f'{100 * (cmt_a / cmt_b - 1):+.4f} %'})",
    ]
    if args.learning:
        lb, la = statistics.median(learning["before"]), statistics.median(learning["after"])
        lines.append(f"learning mix on 2 workers ({args.learning} episodes): before {lb:.1f}, after {la:.1f} "
                     f"episodes/min ({la / lb:.2f}x)")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
