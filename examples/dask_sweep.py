"""The window sweep on a Dask cluster: an embedded LocalCluster, or a running scheduler given its address.

    python examples/dask_sweep.py [--workers 2 | --scheduler tcp://HOST:8786] [--distance 10]

Workers get numbers (EpisodeConfig dictionaries), never Drake objects, and build their own diagrams, so the
toolkit must be installed on every worker. The `if __name__ == "__main__":` guard is needed: a LocalCluster
spawns worker processes that import this file.
"""

import argparse

import drake_biped as db
from drake_biped.experiments.executor import dask_client, episode_task

WINDOWS = [(0.0, 0.0), (0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.1, 0.6), (0.2, 0.7)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=None, help="local workers (default: one per core)")
    parser.add_argument("--scheduler", default=None, help="a running scheduler, e.g. tcp://HOST:8786")
    parser.add_argument("--distance", type=float, default=10.0)
    args = parser.parse_args()

    base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
    configs = [base.override({"t1": t1, "t2": t2}).to_dict() for t1, t2 in WINDOWS]
    with dask_client(workers=args.workers, scheduler=args.scheduler) as client:
        results = client.gather(client.map(episode_task, configs, pure=False))
    none = results[0]["cost_of_transport"]
    for (t1, t2), r in zip(WINDOWS, results):
        label = "no window" if t2 <= t1 else f"window {t1:g}-{t2:g} s"
        print(f"{label}: {r['distance_m']:.2f} m, fell {r['fell']}, C_mt {r['cost_of_transport']:.4f} "
              f"({100 * (r['cost_of_transport'] / none - 1):+.1f} %), worker wall {r['task_wall_time_s']:.1f} s")


if __name__ == "__main__":
    main()
