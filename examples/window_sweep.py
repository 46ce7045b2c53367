"""Sweep torque-free windows through the Python API: which walk, and how much each saves against none.

    python examples/window_sweep.py [--distance 10]

The same sweep as `drake-biped window-map`, serially and in a dozen lines; see dask_sweep.py for it on a
cluster.
"""

import drake_biped as db
from drake_biped.cli import number, run_script, script_parser, windows  # the commands' option checks

parser = script_parser(__doc__)
parser.add_argument("--distance", type=number("positive"), default=10.0, help="walk this far (m)")
parser.add_argument("--windows", type=windows, default="0.1-0.2,0.1-0.3,0.5-0.6,0.2-0.5",
                    help="T1-T2 pairs (s, T1 < T2), comma-separated")
args = parser.parse_args()


def main() -> None:
    base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
    none = db.run_episode(base)
    print(f"no window: {none.distance_m:.2f} m, C_mt {none.cost_of_transport or float('nan'):.4f}")
    for t1, t2 in args.windows:
        r = db.run_episode(base.override({"t1": t1, "t2": t2}))
        walked = not r.fell and r.distance_m >= args.distance - 1e-6
        change = (r.cost_of_transport / none.cost_of_transport - 1.0
                  if r.cost_of_transport and none.cost_of_transport else float("nan"))
        print(f"window {t1:g}-{t2:g} s: {'walks' if walked else 'falls'} {r.distance_m:.2f} m, "
              f"C_mt {r.cost_of_transport or float('nan'):.4f} ({100 * change:+.1f} % vs none)")


run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
