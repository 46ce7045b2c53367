"""The window sweep on a Dask cluster: an embedded LocalCluster, or a running scheduler given its address.

    python examples/dask_sweep.py [--workers 2 | --scheduler tcp://HOST:8786] [--distance 10]

Workers get numbers (EpisodeConfig dictionaries), never Drake objects, and build their own diagrams, so the
toolkit must be installed on every worker. The `if __name__ == "__main__":` guard is needed: a LocalCluster
spawns worker processes that import this file.
"""

import drake_biped as db
from drake_biped.cli import integer, number, run_script, script_parser  # the commands' option checks
from drake_biped.common.executor import dask_client, episode_task

WINDOWS = [(0.0, 0.0), (0.1, 0.2), (0.1, 0.3), (0.5, 0.6), (0.1, 0.4), (0.2, 0.5)]


def main() -> None:
    parser = script_parser(__doc__)
    parser.add_argument("--workers", type=integer(1), default=None, help="local workers (default: one per core)")
    parser.add_argument("--scheduler", default=None, help="a running scheduler, e.g. tcp://HOST:8786")
    parser.add_argument("--distance", type=number("positive"), default=10.0, help="each walk's length (m)")
    args = parser.parse_args()

    base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
    configs = [base.override({"t1": t1, "t2": t2}).to_dict() for t1, t2 in WINDOWS]
    with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
        results = client.gather(client.map(episode_task, configs, pure=False))
    none = results[0]["cost_of_transport"]
    for (t1, t2), r in zip(WINDOWS, results):
        label = "no window" if t2 <= t1 else f"window {t1:g}-{t2:g} s"
        cmt = r["cost_of_transport"]
        change = 100 * (cmt / none - 1) if cmt and none else float("nan")
        print(f"{label}: {r['distance_m']:.2f} m, fell {r['fell']}, C_mt {cmt or float('nan'):.4f} "
              f"({change:+.1f} %), worker wall {r['task_wall_time_s']:.1f} s")


if __name__ == "__main__":
    run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
