"""Is a walk's step dependence in the contact? The time-step study under several contact models.

    python benchmarks/contact_ladder.py --out DIR                      # 16 walks of 110 m, about 4 min on 2 workers
    python benchmarks/contact_ladder.py --out DIR --windows 0.3-0.6 --steps 0.001,0.0005

Runs `drake-biped time-step-study`'s study (the default gait without a window and with each of `--windows`, at
each of `--steps`, control period kept) once under each contact in CONTACTS: the shipped one (SAP, 1e6 N/m,
relaxation time 0.1 s), SAP with a tenth of the relaxation time, SAP with a fifth of the stiffness, and Drake's
"similar" approximation (Hunt & Crossley, 50 s/m). Each study is written as a time-step study of its own
(DIR/<contact>/time_step_study.json, .md, .png); DIR/contact_ladder.md sets their changes from the finest step
side by side.
"""

import argparse
import dataclasses
import json
import time
from pathlib import Path

from drake_biped.analysis import time_step_report
from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M
from drake_biped.common.executor import dask_client
from drake_biped.experiments import time_step
from drake_biped.records import write_text_atomic
from drake_biped.resources import load_gait
from drake_biped.versions import versions

# (folder, name, ContactParams fields replaced, contact approximation)
CONTACTS = (
    ("shipped", "shipped (SAP)", {}, "sap"),
    ("sap-relaxation-0.01", "SAP, relaxation time 0.01 s", {"relaxation_time_s": 0.01}, "sap"),
    ("sap-2e5", "SAP, 2e5 N/m", {"stiffness_npm": 2e5}, "sap"),
    ("similar", "similar (Hunt & Crossley)", {}, "similar"),
)


def window_arg(text: str) -> tuple[float, float]:
    t1, t2 = (float(x) for x in text.split("-"))
    return t1, t2


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--gait", default="fast_servo", help="the shipped gait walked (default: fast_servo, whose learned "
                   "window is the default --windows; the committed records measured it as the default gait)")
    p.add_argument("--windows", default="0.3672-0.8629", help="comma-separated t1-t2 windows (s)")
    p.add_argument("--steps", default="0.001,0.00025", help="comma-separated plant steps (s)")
    p.add_argument("--distance", type=float, default=TRANSIENT_M + LONG_RUN_M)
    p.add_argument("--workers", type=int, default=2)
    args = p.parse_args()
    windows = [window_arg(w) for w in args.windows.split(",") if w]
    steps = sorted(float(h) for h in args.steps.split(","))
    base = load_gait(args.gait)
    records = []
    with dask_client(workers=args.workers) as client:
        for folder, name, fields, approximation in CONTACTS:
            config = base.replace(sim=dataclasses.replace(base.sim, contact_approximation=approximation),
                                  contact=dataclasses.replace(base.contact, **fields))
            t0 = time.perf_counter()
            rec = time_step.study(steps, steps[0], args.distance, client, True, config, windows)
            rec.update(gait=f"{args.gait}, contact: {name}", date=time.strftime("%Y-%m-%d %H:%M:%S %Z"),
                       versions=versions(), wall_s=time.perf_counter() - t0)
            (args.out / folder).mkdir(parents=True, exist_ok=True)
            write_text_atomic(args.out / folder / "time_step_study.json", json.dumps(rec, indent=2) + "\n")
            time_step.replot(args.out / folder)
            records.append((name, rec))
    text = markdown(records)
    write_text_atomic(args.out / "contact_ladder.md", text)
    print(text)


def markdown(records: list[tuple[str, dict]]) -> str:
    """Each contact's walks: long-run C_mt ± 95 % and the change from the finest step, at every step."""
    steps = records[0][1]["steps"]
    head = " | ".join(f"{1e3 * h:g} ms" for h in reversed(steps))
    lines = [f"# The time-step study under four contact models ({records[0][1]['distance_m']:g} m walks)", "",
             f"Long-run C_mt ± 95 %, change from the finest step ({1e3 * steps[0]:g} ms) in brackets. Each contact's "
             "own study (step periods, real-time factors): its folder.", "",
             f"| contact | walk | {head} |", "|---|---|" + "---|" * len(steps)]
    for name, rec in records:
        for w in rec["walks"]:
            by = {r["time_step_s"]: r for r in rec["rows"] if r["window"] == w}
            ref = by[steps[0]]["cost_of_transport"]
            cells = []
            for h in reversed(steps):
                r = by[h]
                if not r["walked"] or r["cost_of_transport"] is None:
                    cells.append(f"falls at {r['distance_m']:.1f} m")
                    continue
                change = f" ({100 * (r['cost_of_transport'] / ref - 1):+.1f} %)" if ref else ""
                cells.append(f"{r['cost_of_transport']:.4f} ± {r['half_width']:.4f}{change}")
            lines.append(f"| {name} | {time_step_report.label(w)} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
