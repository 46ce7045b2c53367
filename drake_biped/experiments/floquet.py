"""`drake-biped floquet`: the gait's periodic orbit and its Floquet multipliers through Drake, for the gait as
given or with a torque-free window. The analysis itself (Newton on the full-state step map, the Jacobian's sweep,
the cross-checks, the report) is `drake_biped.common.floquet_runs`, which the stability experiment and the gait
search share."""

from __future__ import annotations

import argparse

from drake_biped.common.floquet_runs import FloquetSettings, run
from drake_biped.common.options import (
    add_cluster_options,
    add_episode_options,
    add_window_options,
    chosen_window,
    count,
    episode_config,
    out_folder,
    positive_list,
    run_command,
)

COMMAND = "floquet"
# Rerunning the command on the same --out resumes it: the step map's evaluations are kept as they finish.
RESUMABLE = True


PARSER = dict(help="the gait's periodic orbit (Newton on the full-state step map) and its "
              "Floquet multipliers by central differences through Drake, on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped floquet`'s options."""
    add_episode_options(p)
    add_window_options(p, default="gait")
    p.add_argument("--settle-steps", type=count, default=8,
                   help="touchdowns walked from the initiation before the search starts (default 8)")
    p.add_argument("--epsilons", type=positive_list, default=None,
                   help="perturbation sizes of the sweep, comma-separated (default 1e-8 to 3e-3, half decades)")
    p.add_argument("--regression-samples", type=count, default=0,
                   help="also fit the map's Jacobian by least squares over this many random perturbations per "
                        "size (for a map whose contacts make it jump at small perturbations; default 0: no fit)")
    p.add_argument("--regression-sizes", type=positive_list, default=None,
                   help="the fit's perturbation sizes, relative to each coordinate's scale, comma-separated "
                        "(default 1e-3,3e-3,1e-2,2e-2,3e-2)")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder (rerun the same command to resume)")


def settings_from_args(args: argparse.Namespace) -> FloquetSettings:
    """The analysis's settings from the command's options: the gait's window, or --t1/--t2 or --policy."""
    from drake_biped.params import TorqueFreeWindow

    config = episode_config(args)
    if args.policy is not None or args.t1 is not None or args.t2 is not None:
        config = config.replace(window=TorqueFreeWindow(*chosen_window(args)))
    return FloquetSettings(config, settle_steps=args.settle_steps, regression_samples=args.regression_samples,
                           **({"epsilons": tuple(args.epsilons)} if args.epsilons else {}),
                           **({"regression_sizes": tuple(args.regression_sizes)} if args.regression_sizes else {}))


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    record = run_command(args, settings_from_args, run)
    from drake_biped.analysis.floquet import record_verdict

    epsilon = record["converged_epsilon"]
    print(f"spectral radius {record['spectral_radius']:.4f}, fixed-point residual "
          f"{record['fixed_point_residual']:.1e}, "
          + ("no perturbation converged" if epsilon is None else f"converged at epsilon {epsilon:g}")
          + f": {record_verdict(record)}")
    fit = record.get("regression")
    if fit is not None:
        plateau = fit["plateau"]
        print("least-squares fit: " + (f"spectral radius {fit['radius']:.4f} (5-95 % {fit['interval'][0]:.4f}-"
                                       f"{fit['interval'][1]:.4f}), fixed-point residual "
                                       f"{fit['fixed_point_residual']:.1e}, noise {fit['noise']:.1e}, plateau "
                                       f"{plateau['decades']:.1f} decades: " if "radius" in fit else "")
              + fit["verdict"])
    print(f"wrote {args.out}/floquet.json, floquet.md, floquet.png")
    return 0
