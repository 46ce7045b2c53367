"""Where a coarse time step loses: the plant's time step and the control period, separated.

    python benchmarks/time_step_split.py [--distance 10]

Walks the default gait with no window and the windows 0.1-0.4 and 0.2-0.5 s at (plant, control) =
(0.5, 1), (1, 2), (0.5, 2) and (2, 2) ms and prints C_mt and whether each walked the distance (12 episodes,
serially, about 3 minutes on this machine). The time-step study (`drake-biped time-step-study`) moves both
together; this shows which of them a walk is sensitive to.
"""

import argparse

from drake_biped.episode import run_episode
from drake_biped.params import EpisodeConfig, SimulationParams, TorqueFreeWindow

PAIRS = ((5e-4, 1e-3), (1e-3, 2e-3), (5e-4, 2e-3), (2e-3, 2e-3))
WINDOWS = (None, (0.1, 0.4), (0.2, 0.5))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--distance", type=float, default=10.0)
    args = p.parse_args()
    print("| plant | control | " + " | ".join("no window" if w is None else f"{w[0]:g}-{w[1]:g} s" for w in WINDOWS)
          + " |\n|---|---|" + "---|" * len(WINDOWS))
    for h, c in PAIRS:
        cells = []
        for w in WINDOWS:
            config = EpisodeConfig(sim=SimulationParams(time_step_s=h, control_period_s=c, distance_m=args.distance),
                                   window=TorqueFreeWindow(*w) if w else TorqueFreeWindow())
            r = run_episode(config)
            cells.append(f"falls at {r.distance_m:.1f} m" if r.fell else f"{r.cost_of_transport:.4f}")
        print(f"| {h * 1e3:g} ms | {c * 1e3:g} ms | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
