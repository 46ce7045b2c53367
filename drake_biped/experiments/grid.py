"""Grid search over CPG parameters and the initiation (the paper's Table IV), on Dask.

Every grid point is one episode (walk until a fall or the distance) of the base configuration with the
point's values put in. The axes are dotted EpisodeConfig fields (`cpg.u_a`, `initial.speed_mps`,
`gait.torso_pitch_rad`, ...) or the short names of Table IV (alpha, u_a, u_eta, u_r, kappa) and of the
initiation (hip_angle, speed). A range of K points is split into K equal cells with a point at the centre
of each (K = 1: the middle), so no point sits on an edge where the CPG stops (u_r = 0). Without a spec
the grid is Table IV's five ranges and the initiation's (`INITIATION_RANGES`), K points each.

The best point walks furthest (to the centimetre); among points that go equally far, the lowest C_mt wins.
It is written as a parameter file that every command accepts (`--params DIR/best_params.json`).

Nothing lost: each finished point is appended to OUT/points.jsonl (and flushed) as it arrives; a rerun with
the same base configuration reads them back and runs only the points missing. A line that does not read (a run
killed while writing, or damage) sets the file aside as points.jsonl.broken, with a warning, and its point runs
again.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import hashlib
import io
import itertools
import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drake_biped.analysis.cost_of_transport import format_cost
from drake_biped.analysis.grid_ranking import better
from drake_biped.common.options import (
    EPISODE_RECORD_BYTES,
    add_episode_options,
    add_resumable_run_options,
    check_memory,
    cluster,
    count,
    episode_config,
    print_lines,
    why_unchanged,
)
from drake_biped.paper import TABLE_IV as PAPER_TABLE_IV
from drake_biped.params import SHORT_NAMES, EpisodeConfig, ParameterError, check_settings, walked_the_distance
from drake_biped.records import read_kept_lines, write_atomic, write_text_atomic
from drake_biped.versions import versions

__all__ = ["MAX_GRID_POINTS", "Axis", "GridSettings", "check_size", "load_spec", "parse_spec", "point_count", "run",
           "run_grid", "summary_lines", "table_iv_axes"]

TABLE_IV = PAPER_TABLE_IV  # the grid search's ranges of the CPG parameters
# The initiation's ranges (the paper searched it too but prints no range): from standing still with the
# legs together to twice the paper's 7.6 deg and 0.175 m/s.
INITIATION_RANGES: dict[str, tuple[float, float]] = {
    "hip_angle": (0.0, 2 * math.radians(7.6)),
    "speed": (0.0, 2 * 0.175),
}
_SECTIONS = ("cpg", "gait", "initial", "window", "ground", "sim")
# The most points a grid may have without force: 4 per axis of Table IV's seven (16 384 points, about a day
# of 10 m episodes on 2 cores) fits; 5 per axis (78 125) does not. Every point is held in memory (its
# EpisodeConfig, a few kB) before the first runs, so a grid of 1000 per axis (1e21) is refused, not built.
MAX_GRID_POINTS = 20_000
RESULT_FIELDS = ("distance_m", "fell", "fall_reason", "duration_s", "cost_of_transport", "mean_speed_mps",
                 "step_period_s", "steps")


@dataclass(frozen=True)
class Axis:
    """One grid axis: a dotted EpisodeConfig field and the values it takes."""

    name: str
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        if not self.values:
            raise ParameterError(f"grid axis {self.name}: no values")
        for v in self.values:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ParameterError(f"grid axis {self.name}: value {v!r} is not a finite number")
        twice = [v for k, v in enumerate(self.values) if v in self.values[:k]]
        if twice:  # every point with it would be walked, and listed, twice
            raise ParameterError(f"grid axis {self.name}: value {twice[0]!r} is given twice; give each value once")


def field_name(name: str) -> str:
    """The dotted EpisodeConfig field of an axis name (short or dotted, as `EpisodeConfig.override` takes
    them); ParameterError if it is not a numeric field of a section the grid may vary."""
    dotted = SHORT_NAMES.get(name, name)
    section, _, attr = dotted.partition(".")
    base = EpisodeConfig()
    if section not in _SECTIONS or not attr or "." in attr or not hasattr(getattr(base, section), attr) \
            or not isinstance(getattr(getattr(base, section), attr), float):
        raise ParameterError(f"grid axis {name!r}: not a numeric EpisodeConfig field; use one of "
                             f"{sorted(SHORT_NAMES)} or section.field with section in {list(_SECTIONS)}")
    return dotted


def cell_centres(lo: float, hi: float, points: int) -> tuple[float, ...]:
    """`points` values at the centres of `points` equal cells of [lo, hi], rounded to 1e-9."""
    if isinstance(points, bool) or not isinstance(points, int) or points < 1:
        raise ParameterError(f"points per axis {points!r}: must be an integer >= 1")
    if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
        raise ParameterError(f"range [{lo!r}, {hi!r}]: need finite lo <= hi")
    width = (hi - lo) / points
    return tuple(round(lo + (k + 0.5) * width, 9) for k in range(points))


def table_iv_axes(points_per_axis: int, initiation_points: int | None = None) -> list[Axis]:
    """Table IV's five CPG ranges, `points_per_axis` cell centres each, and the initiation's two,
    `initiation_points` each (default: as many)."""
    k = points_per_axis if initiation_points is None else initiation_points
    return ([Axis(field_name(n), cell_centres(lo, hi, points_per_axis)) for n, (lo, hi) in TABLE_IV.items()]
            + [Axis(field_name(n), cell_centres(lo, hi, k)) for n, (lo, hi) in INITIATION_RANGES.items()])


def parse_spec(spec: Any, source: str = "grid spec") -> list[Axis]:
    """Axes from a spec mapping: {"axes": {name: {"min": lo, "max": hi, "points": K} | {"values": [...]}}}.

    The order of the axes is the file's; a point's values are applied in that order."""
    if not isinstance(spec, dict) or not isinstance(spec.get("axes"), dict) or not spec["axes"]:
        raise ParameterError(f"{source}: expected a mapping with a non-empty 'axes' mapping")
    unknown = sorted(set(spec) - {"axes"})
    if unknown:
        raise ParameterError(f"{source}: unknown key(s) {unknown}; a grid spec has 'axes' only")
    axes = []
    for name, entry in spec["axes"].items():
        dotted = field_name(str(name))
        if isinstance(entry, dict) and set(entry) == {"values"} and isinstance(entry["values"], list):
            values = tuple(entry["values"])
        elif isinstance(entry, dict) and set(entry) == {"min", "max", "points"}:
            try:
                values = cell_centres(float(entry["min"]), float(entry["max"]), entry["points"])
            except ParameterError as exc:
                raise ParameterError(f"{source}: axis {name}: {exc}") from None
            except (TypeError, ValueError):
                raise ParameterError(f"{source}: axis {name}: min and max must be numbers, got {entry}") from None
        else:
            raise ParameterError(f"{source}: axis {name}: expected {{min, max, points}} or {{values: [...]}}, "
                                 f"got {entry!r}")
        try:
            axes.append(Axis(dotted, values))
        except ParameterError as exc:
            raise ParameterError(f"{source}: {exc}") from None
    if len({a.name for a in axes}) != len(axes):
        raise ParameterError(f"{source}: an axis is given twice (short and dotted names of one field)")
    return axes


def load_spec(path: Path | str) -> list[Axis]:
    """Axes from a YAML (or JSON) spec file, or a shipped spec by name (`slope_2deg`, ...); see
    `parse_spec`."""
    import yaml

    from drake_biped.resources import grid_spec_names, grid_spec_path

    path = grid_spec_path(path) if str(path) in grid_spec_names() else Path(path)
    if not path.is_file():
        raise ParameterError(f"--spec: no such file: {path}")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as exc:
        raise ParameterError(f"--spec {path}: not valid YAML ({exc})") from None
    return parse_spec(data, f"--spec {path}")


def point_count(axes: list[Axis] | tuple[Axis, ...]) -> int:
    """How many points the axes span (the product of their sizes), without building them."""
    return math.prod(len(a.values) for a in axes)


def check_axes(config: EpisodeConfig, axes, source: str = "GridSettings.axes") -> None:
    """ParameterError naming `source` and the axis when an axis is given twice, or when its values, each set
    alone in `config`, all walk the same episode (`EpisodeConfig.as_walked`): an axis that changes nothing."""
    names = [field_name(a.name) for a in axes]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ParameterError(f"{source}: axis {twice[0]} is given twice")
    for axis, name in zip(axes, names):
        if len(set(axis.values)) < 2:
            continue
        walked = [config.override({name: float(v)}, sampled=True).as_walked() for v in axis.values]
        if all(w == walked[0] for w in walked):
            raise ParameterError(f"{source}: axis {axis.name} ({min(axis.values):g} to {max(axis.values):g}) "
                                 f"changes nothing: {why_unchanged(config, name, axis.values)}")


def check_size(axes: list[Axis] | tuple[Axis, ...], force: bool = False, source: str = "GridSettings.axes",
               insist: str = "force=True") -> None:
    """ParameterError naming `source`, the point count and MAX_GRID_POINTS when the grid is larger, unless
    `force`; nothing is built either way."""
    n = point_count(axes)
    if n > MAX_GRID_POINTS and not force:
        sizes = " x ".join(str(len(a.values)) for a in axes)
        raise ParameterError(f"{source}: the grid has {n:,} points ({sizes}), more than the limit of "
                             f"{MAX_GRID_POINTS:,} (each point is an episode, all held in memory before the "
                             f"first runs); give fewer points, or {insist} to run it anyway")
    check_memory(f"{source}: {n:,} points", n * EPISODE_RECORD_BYTES, "give fewer points")


def grid_points(axes: list[Axis]) -> list[dict[str, float]]:
    """Every combination of the axes' values (the last axis varies fastest)."""
    names = [a.name for a in axes]
    return [dict(zip(names, combo)) for combo in itertools.product(*(a.values for a in axes))]


def point_config(base: EpisodeConfig, point: dict[str, float]) -> EpisodeConfig:
    """`base` with the point's values put in; ParameterError naming the point if a value is out of range."""
    data = base.to_dict()
    for name, value in point.items():
        section, attr = name.split(".")
        data[section][attr] = float(value)
    try:
        return EpisodeConfig.from_dict(data)
    except ParameterError as exc:
        raise ParameterError(f"grid point {point}: {exc}") from None


def _key(config: dict[str, Any]) -> str:
    return hashlib.sha1(json.dumps(config, sort_keys=True).encode()).hexdigest()[:16]


def read_points(path: Path) -> dict[str, dict[str, Any]]:
    """Finished rows of OUT/points.jsonl by key. A line that does not read (a write cut short by a kill, or
    damage) sets the file aside as points.jsonl.broken with a warning naming the line; the rows that read carry
    over and its point is computed again (records.read_kept_lines)."""
    rows = read_kept_lines(path, "a grid point record", lambda r: isinstance(r, dict) and isinstance(r["key"], str))
    return {row["key"]: row for row in rows}


def run_grid(out: Path, base: EpisodeConfig, axes: list[Axis], client,
             progress: Callable[[int, int], None] | None = None, in_flight: int | None = None) -> dict[str, Any]:
    """Run (or finish) every point of the grid on Dask; write points.jsonl, grid.csv, grid.json,
    best_params.json and the slice figure; return the grid record."""
    from distributed import as_completed

    from drake_biped.common.executor import episode_task

    code = versions()
    out.mkdir(parents=True, exist_ok=True)
    points = grid_points(axes)
    configs = [point_config(base, p).to_dict() for p in points]  # every point validated before any runs
    keys = [_key(c) for c in configs]
    store = out / "points.jsonl"
    done = read_points(store)
    first = {k: i for i, k in reversed(list(enumerate(keys)))}  # a point given twice runs once
    todo = sorted(i for k, i in first.items() if k not in done)
    total = len(first)
    finished = total - len(todo)
    if progress:
        progress(finished, total)
    if todo:
        limit = in_flight or 4 * max(1, len(client.scheduler_info().get("workers", {})) or 1)
        pending = iter(todo)
        futures = {}
        for i in itertools.islice(pending, limit):
            futures[client.submit(episode_task, configs[i], pure=False)] = i
        queue = as_completed(list(futures))
        with open(store, "a") as f:
            if f.tell() > 0 and not store.read_bytes().endswith(b"\n"):
                f.write("\n")  # a killed write left half a line: start the next on its own
            for future in queue:
                i = futures.pop(future)
                r = future.result()
                row = {"key": keys[i], "point": points[i], **{k: r[k] for k in RESULT_FIELDS if k != "steps"},
                       "steps": len(r["steps"])}
                f.write(json.dumps(row) + "\n")
                f.flush()
                os.fsync(f.fileno())
                done[keys[i]] = row
                finished += 1
                if progress:
                    progress(finished, total)
                nxt = next(pending, None)
                if nxt is not None:
                    fut = client.submit(episode_task, configs[nxt], pure=False)
                    futures[fut] = nxt
                    queue.add(fut)
    rows = [done[k] for k in keys]
    return write_outputs(out, base, axes, points, configs, rows, code)


def write_outputs(out: Path, base: EpisodeConfig, axes: list[Axis], points: list[dict[str, float]],
                  configs: list[dict[str, Any]], rows: list[dict[str, Any]], code: dict[str, Any]) -> dict[str, Any]:
    from drake_biped.analysis.figures import grid_slices_figure

    best = None
    for i, row in enumerate(rows):
        if better(row, rows[best] if best is not None else None):
            best = i
    names = [a.name for a in axes]
    text = io.StringIO(newline="")
    writer = csv.writer(text)
    writer.writerow([*names, *RESULT_FIELDS])
    for p, row in zip(points, rows):
        writer.writerow([p[n] for n in names] + [row[k] for k in RESULT_FIELDS])
    write_text_atomic(out / "grid.csv", text.getvalue())
    best_config = configs[best]
    write_atomic(out / "best_params.json", best_config)
    walked = [r for r in rows if walked_the_distance(r["fell"], r["distance_m"], base.sim.distance_m)]
    record = {
        "base_config": base.to_dict(),
        "axes": [{"name": a.name, "values": list(a.values)} for a in axes],
        "points": len(rows),
        "walked_the_distance": len(walked),
        "best": {"point": points[best], **{k: rows[best][k] for k in RESULT_FIELDS}},
        "versions": code,
    }
    write_atomic(out / "grid.json", record)
    grid_slices_figure(axes, points, rows, points[best], out / "grid_slices.png", base.sim.distance_m)
    return record


@dataclass(frozen=True)
class GridSettings:
    """A grid: the base configuration and the axes (Table IV's ranges and the initiation's by default)."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    axes: tuple[Axis, ...] = field(default_factory=lambda: tuple(table_iv_axes(2)))
    force: bool = False  # run a grid of more than MAX_GRID_POINTS points

    def __post_init__(self) -> None:
        check_size(self.axes, self.force)
        check_axes(self.config, self.axes)

    def to_dict(self) -> dict[str, Any]:
        return {"config": self.config.to_dict(), "axes": [dataclasses.asdict(a) for a in self.axes]}


def run(settings: GridSettings, out: Path, client=None, progress: bool = True,
        workers: int | None = None, scheduler: str | None = None) -> dict[str, Any]:
    """Run or finish the grid on `client` (a LocalCluster when None), with a progress bar and the run log
    OUT/run.json; write points.jsonl, grid.csv, grid.json, grid_slices.png, best_params.json. The record."""
    check_settings(settings, GridSettings, "grid.run")
    from drake_biped.common.executor import client_or_local
    from drake_biped.common.progress import RunProgress

    out = Path(out)
    report = RunProgress(out, workers, scheduler, "grid", "point", bar=progress, command="grid")
    try:
        with client_or_local(client) as c:
            record = run_grid(out, settings.config, list(settings.axes), c, report)
    finally:
        report.close()
    report.log.update(report.new, finished=True)
    return record


def summary_lines(record: dict[str, Any], out: Path) -> list[str]:
    """The grid in two lines: how many points walk, and the best."""
    best = record["best"]
    cmt = format_cost(best["cost_of_transport"])
    distance = record["base_config"]["sim"]["distance_m"]
    return [f"{record['walked_the_distance']}/{record['points']} points walk {distance:g} m; best "
            f"{', '.join(f'{k}={v:.4g}' for k, v in best['point'].items())}: {best['distance_m']:.2f} m, C_mt {cmt}",
            f"wrote {out}/grid.csv, grid.json, grid_slices.png, best_params.json (use --params)"]


COMMAND = "grid"
# Rerunning the command on the same --out resumes it from its records.
RESUMABLE = True
PARSER = dict(help="grid search of CPG parameters and the initiation (Table IV), on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped grid`'s options."""
    from drake_biped.resources import grid_spec_names

    add_episode_options(p)
    p.add_argument("--points-per-axis", type=count, default=None,
                   help="points per range (cell centres) of Table IV's five CPG parameters and the "
                   "initial hip angle (0-15.2 deg) and speed (0-0.35 m/s); default 2 (128 points)")
    p.add_argument("--spec", default=None, help="a YAML grid spec: axes: {name: {min, max, points} | "
                   "{values: [...]}}, or a shipped one by name (" + ", ".join(grid_spec_names()) + ")")
    add_resumable_run_options(p)


def settings_from_args(args: argparse.Namespace) -> GridSettings:
    """The grid's settings from the command's options, its size checked before anything is built."""
    config = episode_config(args)
    if args.spec is not None and args.points_per_axis is not None:
        raise ParameterError("give either --spec or --points-per-axis, not both")
    axes = load_spec(args.spec) if args.spec is not None else table_iv_axes(args.points_per_axis or 2)
    source = f"--spec {args.spec}" if args.spec is not None else f"--points-per-axis {args.points_per_axis or 2}"
    check_size(axes, args.force, source, "--force")
    check_axes(config, axes, source)
    return GridSettings(config, tuple(axes), force=args.force)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.common.progress import check_run_log

    settings = settings_from_args(args)
    out = Path(args.out)
    check_run_log(out, "grid")  # before a cluster starts
    with cluster(args) as client:
        record = run(settings, out, client, workers=args.workers, scheduler=args.scheduler)
    print_lines(summary_lines(record, out))
    return 0
