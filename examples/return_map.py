"""A Poincare return map fitted from walks: section states (hip angle, rate) at each touchdown, x_{n+1} - x* =
A (x_n - x*) by least squares, and its eigenvalues (the paper's Table VI).

    python examples/return_map.py [--walks 4] [--distance 10] [--t1 0.1 --t2 0.2]

Each walk starts from a slightly different initiation, so the deviations span both directions.
"""

import numpy as np

import drake_biped as db
from drake_biped.cli import integer, number, run_script, script_parser  # the commands' option checks

parser = script_parser(__doc__)
parser.add_argument("--walks", type=integer(2), default=4,
                    help="walks from different initiations (at least 2, so the deviations span both directions)")
parser.add_argument("--distance", type=number("positive"), default=10.0, help="each walk's length (m)")
parser.add_argument("--t1", type=number("nonnegative"), default=0.0, help="torque-free start (s); with --t2 > --t1")
parser.add_argument("--t2", type=number("nonnegative"), default=0.0, help="torque-free end (s)")
args = parser.parse_args()


def main() -> None:
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


run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
