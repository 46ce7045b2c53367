"""Which discretization leaves the paper walker's long-run C_mt unconverged at its 0.5 ms step: the plant's (its
contact) or the controller's (its hip motor and touchdown detection). Each walk is `paper` without a window, 110 m,
with the plant step h and the control period c changed one at a time from the converged 0.125 / 0.125 ms walk:

    python benchmarks/paper_clock_split.py --out benchmarks/results/paper-walker/clock-split

One JSON file per walk (kept as it finishes: a rerun skips the walks already written)."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from drake_biped.episode import run_episode
from drake_biped.resources import load_gait
from drake_biped.versions import versions

# (plant step, control period) in ms
CLOCKS = ((0.125, 0.5), (0.5, 0.5), (0.125, 0.25), (0.25, 0.5))  # 0.125 / 0.125: benchmarks/results/paper-walker/motor-clock


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--gait", default="paper")
    parser.add_argument("--distance", type=float, default=110.0)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for h, c in CLOCKS:
        path = args.out / f"h{h:g}ms-c{c:g}ms.json"
        if path.exists():
            continue
        config = load_gait(args.gait).override({"sim.time_step_s": h * 1e-3, "sim.control_period_s": c * 1e-3,
                                                "sim.distance_m": args.distance, "sim.max_time_s": 6 * args.distance})
        start = time.time()
        result = run_episode(config)
        lr = result.long_run() if not result.fell else None
        record = {"gait": args.gait, "time_step_ms": h, "control_period_ms": c, "distance_m": result.distance_m,
                  "fell": result.fell, "cost_of_transport": result.cost_of_transport, "long_run": lr,
                  "wall_s": time.time() - start, "config": config.to_dict(), "versions": versions()}
        path.write_text(json.dumps(record, indent=1) + "\n")
        print(path.name, result.distance_m, lr and lr["cost_of_transport"], lr and lr["step_period_std_s"], flush=True)


if __name__ == "__main__":
    main()
