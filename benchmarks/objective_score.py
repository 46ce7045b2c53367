"""One walker scored by a search objective at chosen plant steps: what `drake-biped gait-search` would give it there.

A search scores its walkers at the step of its start; a walker it found may be judged at others before it ships
(its robust checks then walk that step and half of it, the pushes and the speeds at that step):

    python benchmarks/objective_score.py --gait benchmarks/results/paper-walker/converged-best/paper_plant_g9.json --objective converged --h-ms 0.35 --out benchmarks/results/paper-walker/converged-best/scores

One JSON file per step (the score, what the objective measured, the configuration, the versions and the command),
kept as it finishes: a rerun skips the steps already written.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from drake_biped.experiments.objectives import OBJECTIVES, score
from drake_biped.resources import load_gait
from drake_biped.versions import versions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--gait", default="paper", help="a shipped gait's name or a parameter file")
    parser.add_argument("--objective", default="converged", choices=sorted(OBJECTIVES))
    parser.add_argument("--h-ms", type=float, nargs="+", default=[0.5])
    parser.add_argument("--distance", type=float, default=100.0, help="the search's --distance (m)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for h_ms in args.h_ms:
        path = args.out / f"{Path(args.gait).stem}-{args.objective}-h{h_ms:g}ms.json"
        if path.exists():
            continue
        config = load_gait(args.gait).override({"sim.time_step_s": h_ms * 1e-3, "sim.distance_m": args.distance,
                                                "sim.max_time_s": 6.0 * args.distance})
        start = time.perf_counter()
        value, detail = score(config, objective=args.objective)
        record = {"gait": args.gait, "objective": args.objective, "time_step_s": h_ms * 1e-3, "score": value,
                  "detail": detail, "wall_time_s": time.perf_counter() - start, "config": config.to_dict(),
                  "versions": versions(),
                  "command": (f"python benchmarks/objective_score.py --gait {args.gait} --objective {args.objective} "
                              f"--h-ms {h_ms:g} --distance {args.distance:g} --out {args.out}")}
        path.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n")
        checks = {k: (r["walked"], r.get("termination")) for k, r in detail.get("checks", {}).items()}
        print(path.name, f"score {value:+.4f}", detail.get("converged"), checks, flush=True)


if __name__ == "__main__":
    main()
