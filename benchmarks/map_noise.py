"""How noisy a walker's step map is at its plant step, and how that noise falls as the step is refined.

The Floquet multipliers need a map that is linear over some range of perturbations. A discrete plant meets and
leaves the ground at whole plant steps, so each contact's onset or release moves a step's image by a jump, and
these jumps are far narrower than any perturbation a Jacobian needs (`floquet.md`'s central-difference sweeps).
At each plant step this measures, on the mid-stance section (drake_biped/step_map.py):

- the map iterated ITERATES times from the section after touchdown 8: the range of each coordinate over the
  iterates after the first 10 (the walker's own step-to-step spread, in the coordinates' units);
- at the iterates' mean, the least-squares affine fit of the map over --samples random perturbations of each
  relative size given (`analysis.floquet.regression_jacobian`, each coordinate by the size times
  `floquet_runs.regression_scales`): the fit's residual spread (the map's noise, absolute and relative to |x|),
  the spectral radius with its bootstrap 5-95 % range, and the perturbed steps that fail.

    python benchmarks/map_noise.py --gait G --out benchmarks/results/paper-walker/map-noise --h-ms 0.35 0.175 0.0875

One JSON file per walker and step, kept as it finishes (a rerun skips those written), and a table of all of them
in `map_noise.md`. A folder holding a `map_noise.md` the script did not write is refused (exit 2).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from paper_motor_clock import parse_with_change
from touchdown_grid import own_records, pending_steps

from drake_biped.analysis import floquet as fq
from drake_biped.common.floquet_runs import regression_scales
from drake_biped.step_map import SectionMap
from drake_biped.versions import versions

COMMAND = "python benchmarks/map_noise.py"
ITERATES, SETTLE = 30, 10
SUMMARY = "map_noise.md"
HEADER = ("| walker | step | spread of the iterates (largest coordinates) | size | noise (relative) | spectral radius "
          "(5–95 %) | falls |\n|---|---|---|---|---|---|---|\n")


def measure(config, sizes: list[float], samples: int) -> dict:
    """The map's iterates' spread and its least-squares fits at `sizes` (see the module's docstring)."""
    section_map = SectionMap(config)
    z, template = section_map.start(8)
    names = list(section_map.names)

    def step(x):
        return section_map.step(x, template)

    iterates = [z]
    for _ in range(ITERATES):
        y = step(iterates[-1])
        if y is None:
            return {"iterates_fell_after": len(iterates) - 1}
        iterates.append(y)
    iterates = np.array(iterates)
    centre = iterates[SETTLE:].mean(axis=0)
    spread = np.ptp(iterates[SETTLE:], axis=0)
    fits = []
    for k, size in enumerate(sizes):
        try:
            fit = fq.regression_jacobian(fq.serial(step), centre, regression_scales(centre), size, samples, seed=k,
                                         section_normal=section_map.section_normal())
        except fq.StepFailed as exc:
            fits.append({"size": size, "error": str(exc)})
            continue
        fits.append({"size": size, "noise_relative": fit.noise,
                     "noise_absolute": fit.noise * float(np.linalg.norm(centre)), "radius": fit.radius,
                     "interval": list(fit.interval), "samples": fit.samples, "falls": fit.falls})
    return {"coordinates": names, "centre": centre.tolist(), "spread": dict(zip(names, spread.tolist())),
            "fits": fits}


def row_text(name: str, record: dict) -> list[str]:
    m = record["map"]
    step = f"{record['time_step_s'] * 1e3:g} ms"
    if "fits" not in m:
        return [f"| {name} | {step} | falls after {m['iterates_fell_after']} iterates | | | | |"]
    top = sorted(m["spread"].items(), key=lambda kv: -kv[1])[:3]
    spread = ", ".join(f"{k} {v:.3g}" for k, v in top)
    rows = []
    for f in m["fits"]:
        if "error" in f:
            rows.append(f"| {name} | {step} | {spread} | {f['size']:g} | {f['error']} | | |")
            continue
        rows.append(f"| {name} | {step} | {spread} | {f['size']:g} | {f['noise_absolute']:.2e} ({f['noise_relative']:.1e}) "
                    f"| {f['radius']:.3g} ({f['interval'][0]:.3g}–{f['interval'][1]:.3g}) | {f['falls']} of "
                    f"{f['samples'] + f['falls']} |")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--gait", default="paper", help="a shipped gait's name or a parameter file")
    parser.add_argument("--h-ms", type=float, nargs="+", default=[0.5, 0.25])
    parser.add_argument("--sizes", type=float, nargs="+", default=[1e-3, 1e-2])
    parser.add_argument("--samples", type=int, default=56)
    args = parse_with_change(parser)
    summary = args.out / SUMMARY
    if summary.exists() and not summary.read_text().startswith(HEADER):
        print(f"map_noise.py: --out {args.out} holds {SUMMARY}, which this script did not write; choose another "
              "folder", file=sys.stderr)
        raise SystemExit(2)
    for h_ms, path, config in pending_steps(args):
        start = time.perf_counter()
        record = {"gait": args.gait, "override": args.override, "time_step_s": h_ms * 1e-3,
                  "map": measure(config, args.sizes, args.samples), "wall_time_s": None,
                  "config": config.to_dict(), "versions": versions(),
                  "command": f"{COMMAND} " + " ".join(
                      [f"--gait {args.gait}", f"--out {args.out}", f"--h-ms {h_ms:g}",
                       "--sizes " + " ".join(f"{s:g}" for s in args.sizes), f"--samples {args.samples}"]
                      + ([f"--override '{json.dumps(args.override)}' --tag {args.tag}"] if args.tag else []))}
        record["wall_time_s"] = time.perf_counter() - start
        path.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n")
        print("\n".join(row_text(path.stem, record)), flush=True)
    rows = [line for name, record in own_records(args.out, COMMAND).items() for line in row_text(name, record)]
    summary.write_text(HEADER + "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
