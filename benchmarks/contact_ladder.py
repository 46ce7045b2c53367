"""Is a walk's step dependence in the contact? The same walks at two plant steps under several contact models.

    python benchmarks/contact_ladder.py --out DIR                      # 16 walks of 110 m, about 3 min on 2 workers
    python benchmarks/contact_ladder.py --out DIR --windows 0.3-0.6 --steps 0.001,0.0005

Walks the default gait without a window and with each of `--windows`, at each of `--steps` (control period
kept), under each contact in CONTACTS: the shipped one (SAP, 1e6 N/m, relaxation time 0.1 s), SAP with a
tenth of the relaxation time, SAP with a fifth of the stiffness, and Drake's "similar" approximation
(Hunt & Crossley, 50 s/m). Prints and writes (DIR/contact_ladder.json, .md) each walk's long-run C_mt with its
95 % interval and its step periods, and for each contact and walk the change from the finest step.
"""

import argparse
import dataclasses
import json
import time
from pathlib import Path

from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M, long_run_of_record
from drake_biped.experiments.executor import dask_client, episode_task, map_ordered
from drake_biped.params import GRAVITY_MPS2, EpisodeConfig, TorqueFreeWindow, with_time_step
from drake_biped.versions import versions

# (name, ContactParams fields replaced, contact approximation)
CONTACTS = (
    ("shipped (SAP)", {}, "sap"),
    ("SAP, relaxation time 0.01 s", {"relaxation_time_s": 0.01}, "sap"),
    ("SAP, 2e5 N/m", {"stiffness_npm": 2e5}, "sap"),
    ("similar (Hunt & Crossley)", {}, "similar"),
)


def window_arg(text: str) -> tuple[float, float]:
    t1, t2 = (float(x) for x in text.split("-"))
    return t1, t2


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--windows", default="0.3672-0.8629", help="comma-separated t1-t2 windows (s)")
    p.add_argument("--steps", default="0.001,0.00025", help="comma-separated plant steps (s)")
    p.add_argument("--distance", type=float, default=TRANSIENT_M + LONG_RUN_M)
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args()
    windows = [None, *(window_arg(w) for w in args.windows.split(",") if w)]
    steps = sorted(float(h) for h in args.steps.split(","))
    base = EpisodeConfig()
    jobs = []
    for name, fields, approximation in CONTACTS:
        for h in steps:
            for w in windows:
                sim = dataclasses.replace(with_time_step(base.sim, h, "--steps"), distance_m=args.distance,
                                          max_time_s=6.0 * args.distance, contact_approximation=approximation)
                config = base.replace(sim=sim, contact=dataclasses.replace(base.contact, **fields),
                                      window=TorqueFreeWindow(*w) if w else TorqueFreeWindow(0.0, 0.0))
                jobs.append((name, h, w, config.to_dict()))
    t0 = time.perf_counter()
    with dask_client(workers=args.workers) as client:
        results = map_ordered(client, episode_task, [j[3] for j in jobs])
    rows = []
    for (name, h, w, config), r in zip(jobs, results):
        lr = long_run_of_record(r, GRAVITY_MPS2) if not r["fell"] else {}
        rows.append({"contact": name, "time_step_s": h, "window": list(w) if w else None, "fell": r["fell"],
                     "distance_m": r["distance_m"], "long_run": {k: v for k, v in lr.items()
                                                                 if not isinstance(v, (list, dict))},
                     "config": config})
    args.out.mkdir(parents=True, exist_ok=True)
    record = {"steps": steps, "windows": [list(w) if w else None for w in windows], "distance_m": args.distance,
              "rows": rows, "versions": versions(), "wall_s": time.perf_counter() - t0,
              "date": time.strftime("%Y-%m-%d %H:%M:%S %Z")}
    (args.out / "contact_ladder.json").write_text(json.dumps(record, indent=1) + "\n")
    text = markdown(record)
    (args.out / "contact_ladder.md").write_text(text)
    print(text)


def markdown(record: dict) -> str:
    steps = record["steps"]
    finest = steps[0]
    head = " | ".join(f"{1e3 * h:g} ms" for h in reversed(steps))
    lines = [f"# The same walks under four contact models ({record['distance_m']:g} m, long-run C_mt ± 95 %)", "",
             f"Change from the finest step ({1e3 * finest:g} ms) in brackets; step period mean ± standard deviation "
             f"below each. Drake {record['versions'].get('drake')}, commit {record['versions'].get('git_commit')}.", "",
             f"| contact | walk | {head} |", "|---|---|" + "---|" * len(steps)]
    for name in dict.fromkeys(r["contact"] for r in record["rows"]):
        for w in record["windows"]:
            by = {r["time_step_s"]: r for r in record["rows"] if r["contact"] == name and r["window"] == w}
            ref = by[finest]["long_run"].get("cost_of_transport")
            cells = []
            for h in reversed(steps):
                lr = by[h]["long_run"]
                c = lr.get("cost_of_transport")
                if by[h]["fell"] or c is None:
                    cells.append(f"falls at {by[h]['distance_m']:.1f} m")
                    continue
                change = f" ({100 * (c / ref - 1):+.1f} %)" if ref else ""
                cells.append(f"{c:.4f} ± {lr['half_width']:.4f}{change}<br>"
                             f"{lr['step_period_mean_s']:.3f} ± {lr['step_period_std_s']:.3f} s")
            walk = "no window" if w is None else f"{w[0]:g}–{w[1]:g} s"
            lines.append(f"| {name} | {walk} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
