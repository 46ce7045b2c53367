"""Walk the paper's walker with a torque-free hip period and plot the hip angles, shading the torque-free time.

    python examples/walk_and_plot.py --out out/example-walk [--distance 10] [--t1 0.2 --t2 0.5]
"""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import drake_biped as db  # noqa: E402
from drake_biped.analysis.cost_of_transport import format_cost  # noqa: E402
from drake_biped.cli import number, run_script, script_parser  # noqa: E402  (the commands' option checks)

parser = script_parser(__doc__)
parser.add_argument("--distance", type=number("positive"), default=10.0, help="walk this far (m)")
parser.add_argument("--t1", type=number("nonnegative"), default=0.1, help="torque-free start after each step start (s)")
parser.add_argument("--t2", type=number("nonnegative"), default=0.2, help="torque-free end (s)")
parser.add_argument("--out", type=Path, default=Path("out/example-walk"))
args = parser.parse_args()


def main() -> None:
    config = db.EpisodeConfig(window=db.TorqueFreeWindow(args.t1, args.t2)).override({"sim.distance_m": args.distance})
    result = db.run_episode(config, record_trajectory=True)
    print(f"walked {result.distance_m:.2f} m in {result.duration_s:.2f} s, fell: {result.fell}, "
          f"{len(result.steps)} steps, C_mt {format_cost(result.cost_of_transport)}, "
          f"real-time factor {result.real_time_factor:.1f}")

    traj = result.trajectory  # arrays: time, positions (x, z, pitch, then JOINT_NAMES), torque_free, ...
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for name in ("left_hip", "right_hip"):
        ax.plot(traj["time"], traj["positions"][:, 3 + db.JOINT_NAMES.index(name)], label=name)
    ax.fill_between(traj["time"], -1, 1, where=traj["torque_free"] > 0.5, color="0.85", label="swing hip torque-free")
    ax.set(xlabel="time (s)", ylabel="hip angle (rad)", ylim=(-0.8, 0.8))
    ax.legend(loc="upper right", fontsize=8)
    args.out.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out / "hip_angles.png", dpi=110, bbox_inches="tight")
    result.to_json(args.out / "result.json")
    print(f"wrote {args.out}/hip_angles.png, result.json")


run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
