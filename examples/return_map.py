"""A Poincare return map fitted from walks: section states (hip angle, rate) at each touchdown, x_{n+1} - x* =
A (x_n - x*) by least squares, and its eigenvalues (the paper's Table VI).

    python examples/return_map.py [--walks 4] [--distance 10] [--t1 0.2 --t2 0.5]

Each walk starts from a slightly different initiation, so the deviations span both directions.
"""

import argparse

import numpy as np

import drake_biped as db

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--walks", type=int, default=4)
parser.add_argument("--distance", type=float, default=10.0)
parser.add_argument("--t1", type=float, default=0.0, help="torque-free start (s); with --t2 > --t1")
parser.add_argument("--t2", type=float, default=0.0)
args = parser.parse_args()

base = db.EpisodeConfig(window=db.TorqueFreeWindow(args.t1, args.t2)).override({"sim.distance_m": args.distance})
rng = np.random.default_rng(0)
sequences = []
for k in range(args.walks):
    scale = 1.0 + 0.15 * rng.uniform(-1, 1, 2)  # initial hip angle and speed within +-15 %
    config = base.override({"hip_angle": base.initial.hip_angle_rad * scale[0],
                            "speed": base.initial.speed_mps * scale[1]})
    result = db.run_episode(config)
    sequences.append(result.sections[2:])  # from the third touchdown on: the gait, not the initiation
    print(f"walk {k}: {result.distance_m:.2f} m, {len(result.steps)} touchdowns")

fit = db.fit_return_map(sequences, bootstrap=200)
print("A =", np.array2string(fit.a_matrix, precision=3))
print("eigenvalues:", ", ".join(f"{complex(e):.3f}" for e in fit.eigenvalues),
      f"spectral radius {fit.spectral_radius:.3f} (95 % interval {fit.spectral_radius_ci}), {fit.n_pairs} pairs")
