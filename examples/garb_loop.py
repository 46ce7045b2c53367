"""GARB learning the torque-free period in about twenty lines: sample a window, walk, reward, update.

    python examples/garb_loop.py [--episodes 20] [--distance 10] [--variance 0.01]

This is what `drake-biped learn` runs for each trial (there on Dask, with records kept and resumable).
"""

import drake_biped as db
from drake_biped.analysis.series import window_text  # a sample as the window it walks
from drake_biped.cli import integer, number, run_script, script_parser  # the commands' option checks

parser = script_parser(__doc__)
parser.add_argument("--episodes", type=integer(1), default=20)
parser.add_argument("--distance", type=number("positive"), default=10.0, help="each episode walks this far or falls (m)")
parser.add_argument("--variance", type=number("positive"), default=0.01,
                    help="policy variance per time (s^2); paper: 0.04")
parser.add_argument("--seed", type=integer(0), default=0)
args = parser.parse_args()


def main() -> None:
    base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
    # from the paper walker's cheapest window (its window map; the paper starts at 0.5, 0.5 s); beta 0.8, Table II
    learner = db.GarbLearner(mean=(0.1, 0.2), variance=args.variance, seed=args.seed)
    for episode in range(1, args.episodes + 1):
        t1, t2 = learner.sample()
        window = db.TorqueFreeWindow(max(0.0, t1), max(0.0, t2))  # times below 0 act as 0; t2 <= t1: none
        result = db.run_episode(base.replace(window=window))
        r = db.reward(result.cost_of_transport, result.distance_m, args.distance)  # eq. 13 with the fall rule
        learner.update((t1, t2), r)
        print(f"episode {episode:3d}: window {window_text(t1, t2)}, {result.distance_m:5.2f} m, reward {r:.3f}, "
              f"policy mean ({learner.mean[0]:.3f}, {learner.mean[1]:.3f})")


run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
