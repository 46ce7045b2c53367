"""Sweep torque-free windows through the Python API: which walk, and how much each saves against none.

    python examples/window_sweep.py [--distance 10]

The same sweep as `drake-biped window-map`, serially and in a dozen lines; see dask_sweep.py for it on a
cluster.
"""

import argparse

import drake_biped as db

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--distance", type=float, default=10.0, help="walk this far (m)")
parser.add_argument("--windows", default="0.1-0.4,0.2-0.5,0.3-0.6", help="t1-t2 pairs (s), comma-separated")
args = parser.parse_args()

base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
none = db.run_episode(base)
print(f"no window: {none.distance_m:.2f} m, C_mt {none.cost_of_transport:.4f}")
for pair in args.windows.split(","):
    t1, t2 = (float(x) for x in pair.split("-"))
    r = db.run_episode(base.override({"t1": t1, "t2": t2}))
    walked = not r.fell and r.distance_m >= args.distance - 1e-6
    change = r.cost_of_transport / none.cost_of_transport - 1.0
    print(f"window {t1:g}-{t2:g} s: {'walks' if walked else 'falls'} {r.distance_m:.2f} m, "
          f"C_mt {r.cost_of_transport:.4f} ({100 * change:+.1f} % vs none)")
