"""The expected reward GARB climbs, from a measured window map (`analysis.landscape`): landscape.json and
landscape.png, for the policy variances asked. Reads records only; simulates nothing."""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from drake_biped.analysis.landscape import WindowRewards, landscape
from drake_biped.analysis.series import signed_percent
from drake_biped.common.options import (
    check_memory,
    check_size,
    check_writable,
    count,
    number,
    out_folder,
    print_lines,
    seed_type,
    steps,
)
from drake_biped.params import ParameterError, check_settings
from drake_biped.records import write_atomic
from drake_biped.versions import versions

__all__ = ["LandscapeSettings", "run", "summary_lines"]

# Each sample is drawn at every policy mean of the landscape's grid (t1 0-0.8 s x t2 0-1 s by 0.025 s), and
# held in memory while a mean is evaluated (about DRAW_BYTES each). MAX_DRAWS, over all variances, is about
# three minutes on one core.
LANDSCAPE_MEANS = 33 * 41
DRAW_BYTES = 100
MAX_DRAWS = 600_000


@dataclass(frozen=True)
class LandscapeSettings:
    """The window map (a window-map folder or its window_map.json), the variances (s^2), the policy
    starts to evaluate, and the Monte Carlo samples per mean with their seed."""

    window_map: str
    variances: tuple[float, ...] = (0.04, 0.01, 0.0025)
    starts: tuple[tuple[float, float], ...] = ((0.5, 0.5),)
    samples: int = 2000
    seed: int = 0
    force: bool = False  # draw more than MAX_DRAWS

    def __post_init__(self) -> None:
        if not isinstance(self.samples, int) or isinstance(self.samples, bool) or self.samples < 1:
            raise ParameterError(f"--samples {self.samples!r}: must be an integer >= 1")
        if not self.variances or not all(math.isfinite(v) and v > 0 for v in self.variances):
            raise ParameterError(f"--variance {list(self.variances)!r}: each must be a positive number")
        if not all(len(s) == 2 and all(math.isfinite(x) and x >= 0 for x in s) for s in self.starts):
            raise ParameterError(f"--start {list(self.starts)!r}: each start is two times >= 0 (s)")
        check_memory(f"--samples {self.samples:,}", DRAW_BYTES * self.samples)
        check_size(f"--samples {self.samples:,} x {len(self.variances)} variances",
                   self.samples * len(self.variances), MAX_DRAWS,
                   f"draws at each of the {LANDSCAPE_MEANS:,} policy means", self.force)

    def path(self) -> Path:
        source = Path(self.window_map)
        return source / "window_map.json" if source.is_dir() else source


def run(settings: LandscapeSettings, out: Path | None = None, client=None, progress: bool = True) -> dict[str, Any]:
    """Write landscape.json and landscape.png into `out` (default: the window map's folder); the record."""
    check_settings(settings, LandscapeSettings, "landscape.run")
    from drake_biped.analysis.figures import landscape_figure

    path = settings.path()
    if not path.is_file():
        raise ParameterError(f"no window map at {settings.window_map} (run drake-biped window-map first)")
    from drake_biped.records import read_json

    try:
        rewards = WindowRewards.from_window_map(read_json(path, "landscape: window map"))
    except (KeyError, TypeError) as exc:
        raise ParameterError(f"{path} is not a window map ({exc})") from None
    out = Path(out) if out is not None else path.parent
    check_writable(out, f"landscape: {'--out' if out != path.parent else 'the window map folder'} {str(out)!r}")
    record = landscape(rewards, list(settings.variances), samples=settings.samples, seed=settings.seed,
                       starts=[tuple(s) for s in settings.starts])
    record.update(window_map=str(path), samples=settings.samples, seed=settings.seed, versions=versions())
    write_atomic(out / "landscape.json", record)
    landscape_figure(record, out / "landscape.png")
    return record


def summary_lines(record: dict[str, Any]) -> list[str]:
    lines = [f"no window: reward {record['no_window_reward']:.3f}"]
    for cell in record["variances"]:
        s = cell["starts"][0]
        lines.append(f"variance {cell['variance']:g}: best policy mean ({cell['best_mean'][0]:.3f}, "
                     f"{cell['best_mean'][1]:.3f}) expected reward {signed_percent(cell['best_gain'])} vs no window; "
                     f"at the start {tuple(s['mean'])} {signed_percent(s['gain'])}")
    return lines


COMMAND = "landscape"
PARSER = dict(help="the expected reward GARB climbs, from a window map, for given variances")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped landscape`'s options."""
    p.add_argument("window_map", help="a window-map output folder or its window_map.json")
    p.add_argument("--variance", type=steps, default=[0.04, 0.01, 0.0025],
                   help="policy variances (s^2), comma-separated; default 0.04,0.01,0.0025")
    p.add_argument("--start", type=number("nonnegative"), nargs=2, metavar=("T1", "T2"),
                   help="a policy start to evaluate (default 0.5 0.5)")
    p.add_argument("--samples", type=count, default=2000, help="Monte Carlo samples per mean")
    p.add_argument("--seed", type=seed_type, default=0, help="random seed")
    p.add_argument("--force", action="store_true", help=f"draw more than {MAX_DRAWS:,} samples over all variances")
    p.add_argument("--out", default=None, type=out_folder, help="output folder (default: the window map's)")


def settings_from_args(args: argparse.Namespace) -> LandscapeSettings:
    """The landscape's settings from the command's options."""
    return LandscapeSettings(args.window_map, tuple(args.variance),
                             (tuple(args.start),) if args.start else ((0.5, 0.5),), samples=args.samples,
                             seed=args.seed, force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    settings = settings_from_args(args)
    record = run(settings, Path(args.out) if args.out else None)
    print_lines(summary_lines(record))
    out = Path(args.out) if args.out else settings.path().parent
    print(f"wrote {out}/landscape.json, landscape.png")
    return 0
