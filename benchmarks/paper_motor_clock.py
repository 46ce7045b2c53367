"""The paper walker's hip motor against its plant step, each walked 110 m without a window at several plant steps:
the long-run C_mt (first 10 m dropped), the step period's spread, and how often the swing hip's torque changes sign
after 3 s (a 10 m walk with its trajectory recorded). The motor solved by the controller (GaitParams.motor_solve
"controller"), per update (motor_time_constant_s 0) or with a time constant:

    python benchmarks/paper_motor_clock.py --solve controller --out benchmarks/results/paper-walker/motor-clock --tau-ms 0 2 --h-ms 0.5 0.25 0.125

or solved in the plant's step (motor_solve "plant", as shipped) at the given velocity gains:

    python benchmarks/paper_motor_clock.py --solve plant --out benchmarks/results/paper-walker/motor-plant --gain 1000 --h-ms 0.5 0.25 0.125

Any other change, named in the files: `--override '{"contact.stiffness_npm": 5e5}' --tag k5e5`.

One JSON file per walk, kept as it finishes: a rerun skips the walks already written."""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from drake_biped.analysis.series import swing_hip_sign_changes_per_s
from drake_biped.episode import run_episode
from drake_biped.model import joint_index
from drake_biped.resources import load_gait
from drake_biped.versions import versions


def swing_hip_torque_sign_changes(trajectory: dict, after_s: float = 3.0) -> tuple[float, float]:
    """How often the swing hip's applied torque changes sign (per second, from `after_s`: analysis.series.
    swing_hip_sign_changes_per_s), and the part of the updates it sits within 1 % of its largest (the motor's
    limit when it saturates)."""
    t, act, right = trajectory["time"], trajectory["actuation"], trajectory["stance_right"] > 0.5
    tau = np.where(right, act[:, joint_index("left", "hip")], act[:, joint_index("right", "hip")])[t >= after_s]
    return swing_hip_sign_changes_per_s(trajectory, after_s), float(np.mean(np.abs(tau) >= 0.99 * np.abs(tau).max()))


def parse_with_change(parser: argparse.ArgumentParser) -> argparse.Namespace:
    """`parser`'s arguments with --override (more changes to every walk) and --tag (naming them in the files'
    names), which go together; --out made."""
    parser.add_argument("--override", type=json.loads, default={},
                        help="more changes to every walk, as EpisodeConfig.override takes them (JSON)")
    parser.add_argument("--tag", default="", help="added to the files' names (with --override)")
    args = parser.parse_args()
    if bool(args.override) != bool(args.tag):
        parser.error("--override and --tag go together")
    args.out.mkdir(parents=True, exist_ok=True)
    return args


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--gait", default="paper")
    parser.add_argument("--solve", choices=("plant", "controller"), default="plant")
    parser.add_argument("--tau-ms", type=float, nargs="+", default=[0.0],
                        help="the controller's motor's time constants (ms; --solve controller)")
    parser.add_argument("--gain", type=float, nargs="+", default=[1000.0],
                        help="the plant's motor's velocity gains (N*m*s/rad; --solve plant)")
    parser.add_argument("--h-ms", type=float, nargs="+", default=[0.5, 0.25, 0.125])
    parser.add_argument("--distance", type=float, default=110.0)
    args = parse_with_change(parser)
    if args.solve == "controller":
        motors = [(f"tau{tau:g}ms", {"gait.motor_solve": "controller", "gait.motor_time_constant_s": tau * 1e-3})
                  for tau in args.tau_ms]
    else:
        motors = [(f"gain{gain:g}", {"gait.motor_solve": "plant", "gait.motor_gain_nms": gain}) for gain in args.gain]
    for name, motor in motors:
        for h in args.h_ms:
            path = args.out / f"{name}{'-' + args.tag if args.tag else ''}-h{h:g}ms.json"
            if path.exists():
                continue
            base = load_gait(args.gait).override({**motor, **args.override, "sim.time_step_s": h * 1e-3})
            start = time.time()
            short = run_episode(base, record_trajectory=True)
            flips, saturated = swing_hip_torque_sign_changes(short.trajectory) if short.duration_s > 4.0 else (None, None)
            config = base.override({"sim.distance_m": args.distance, "sim.max_time_s": 6 * args.distance})
            result = run_episode(config)
            lr = None if result.fell else result.long_run()
            record = {"gait": args.gait, "motor": motor, "override": args.override, "time_step_ms": h,
                      "distance_m": result.distance_m, "fell": result.fell, "fall_reason": result.fall_reason,
                      "cost_of_transport": result.cost_of_transport,
                      "long_run": lr, "sign_changes_per_s_10m": flips, "saturated_part_10m": saturated,
                      "walked_10m": {"fell": short.fell, "distance_m": short.distance_m,
                                     "cost_of_transport": short.cost_of_transport, "wall_s": short.wall_time_s},
                      "wall_s": time.time() - start, "config": config.to_dict(), "versions": versions()}
            path.write_text(json.dumps(record, indent=1) + "\n")
            print(path.name, result.fell, round(result.distance_m, 2), lr and lr["cost_of_transport"],
                  lr and lr["step_period_std_s"], flips, flush=True)


if __name__ == "__main__":
    main()
