"""Time-step study: the convergence of a gait's long-run cost of transport as the plant step is halved.

Each walk (no window and each window given; by default the gait's own window, the one its file declares, and
on the paper's walker one late in its step) goes LONG_WALK_M from the paper's initiation at every plant step. The controller's clock is the
gait's: under the paper's reading (the controller acts at every plant step) plant and controller are refined
together; a fixed-rate loop (`--control-period`) is part of the robot and kept, the plant step alone refined
under it (steps that do not divide it are refused). A walk's C_mt is
its long-run mean after the initiation's transient (analysis.long_run: the first 10 m dropped, the next 100 m
measured, with a 95 % interval from batch means). From the three finest steps, a Richardson estimate gives
each walk's limit as the step goes to 0 and each step's error. The shipped step is the coarsest whose long-run
C_mt, for every walk that walks at the finest step, is within TOLERANCE of it (and every finer step too).

`drake-biped time-step-study --out DIR` writes DIR/time_step_study.json (every episode, versions), .md and
.png. Episodes run on Dask (a LocalCluster, or a scheduler's address).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path

from drake_biped.analysis.long_run import LONG_RUN_M, TRANSIENT_M, has_long_run, long_run_of_record
from drake_biped.analysis.time_step_report import figure, halving, markdown
from drake_biped.common.executor import map_episodes
from drake_biped.common.options import (
    add_clock_option,
    add_cluster_options,
    add_model_option,
    check_walks,
    cluster,
    default_window,
    gait_line,
    number,
    out_folder,
    steps,
    window_line,
    windows,
    with_clock,
    with_model,
)
from drake_biped.legacy import STUDY_WALKS_BEFORE_RECORDED, clock_of_record
from drake_biped.params import (
    DEFAULT_WINDOW_S,
    GRAVITY_MPS2,
    EpisodeConfig,
    ParameterError,
    TorqueFreeWindow,
    check_settings,
    walked_the_distance,
    with_time_step,
)
from drake_biped.records import read_json, write_text_atomic
from drake_biped.versions import versions

# The default configuration's (the paper's walker's) windows: the one its gait file declares (its window map's
# cheapest) and one late in its step, where the map's windows save (its story's study window).
WALKS = [None, DEFAULT_WINDOW_S, (0.5, 0.6)]
TOLERANCE = 0.01
LONG_WALK_M = TRANSIENT_M + LONG_RUN_M
STEPS = (0.002, 0.001, 0.0005, 0.00025, 0.000125)
# What a study compares at each step: the long-run mean after the transient (with its 95 % interval), or, for walks
# too short for one, the whole walk's C_mt (initiation included, no interval).
MEASURES = ("long-run", "episode")




def study(steps: list[float], reference: float, distance: float, client, progress: bool = True,
          config: EpisodeConfig | None = None, windows=None, measure: str = "long-run", keep: Path | None = None
          ) -> dict:
    """The walks at each step (each kept in the folder `keep` as it finishes, when one is given: a rerun
    resumes) and what they choose."""
    base = config if config is not None else EpisodeConfig()
    walk_list = WALKS if windows is None else [None, *map(tuple, windows)]
    jobs = []
    for h in steps:
        for w in walk_list:
            sim = dataclasses.replace(with_time_step(base.sim, h, "--steps"), distance_m=distance,
                                      max_time_s=max(base.sim.max_time_s, 6.0 * distance))
            window = TorqueFreeWindow(*w) if w else TorqueFreeWindow(0.0, 0.0)
            jobs.append((h, w, base.replace(sim=sim, window=window).to_dict()))
    from tqdm import tqdm

    paths = None if keep is None else [Path(keep) / f"{1e3 * h:g}ms-{_walk_name(w)}.json" for h, w, _ in jobs]
    with tqdm(total=len(jobs), desc="time-step study", unit="episode", disable=not progress) as bar:
        results = map_episodes(client, [j[2] for j in jobs], paths, lambda n, total: bar.update(n - bar.n))
    rows = []
    for (h, w, c), r in zip(jobs, results):
        long_run = _long_run(r)
        rows.append({
            "time_step_s": h,
            "control_period_s": clock_of_record(c["sim"])[1],
            "window": list(w) if w else None,
            "walked": walked_the_distance(r["fell"], r["distance_m"], distance),
            "termination": r["termination"],
            "distance_m": r["distance_m"],
            "episode_cost_of_transport": r["cost_of_transport"],
            "cost_of_transport": long_run["cost_of_transport"] if measure == "long-run" else r["cost_of_transport"],
            "half_width": long_run["half_width"] if measure == "long-run" else None,
            "long_run": long_run,
            "mean_speed_mps": r["mean_speed_mps"],
            "step_period_s": long_run["step_period_mean_s"],
            "real_time_factor": r["real_time_factor"],
        })
    rec = {"steps": steps, "reference_s": reference, "distance_m": distance, "tolerance": TOLERANCE, "measure": measure,
           "walks": [list(w) if w else None for w in walk_list], "config": base.to_dict(), "rows": rows,
           **choose_step(rows, steps, reference, TOLERANCE)}
    rec["richardson"] = {json.dumps(w): richardson(rows, steps, w) for w in rec["walks"]}
    return rec


def _walk_name(window) -> str:
    """A walk's name in a kept file's: "no_window", or the window's times ("0.1-0.2s")."""
    return "no_window" if not window else f"{window[0]:g}-{window[1]:g}s"


def _long_run(result: dict) -> dict:
    return long_run_of_record(result, GRAVITY_MPS2)


def richardson(rows: list[dict], steps: list[float], window) -> dict:
    """Richardson's estimate of a walk's long-run C_mt as the step goes to 0, from its three finest steps
    (h, h/2, h/4 when the steps halve): the observed order p = log2((C_h - C_h/2) / (C_h/2 - C_h/4)) where the
    two differences share a sign and 0.5 <= p <= 3, else p = 1 (SAP's first-order step); the limit
    C_h/4 + (C_h/4 - C_h/2) / (2^p - 1); each step's error C_h / limit - 1. None where a walk falls or the
    finest three do not halve."""
    by = {r["time_step_s"]: r for r in rows if tuple(r["window"] or ()) == tuple(window or ())}
    fine = sorted(steps)[:3]
    out = {"order": None, "order_observed": False, "limit": None, "errors": {}}
    if not halving(steps):
        return out
    values = [by[h]["cost_of_transport"] if by[h]["walked"] else None for h in fine]
    if any(v is None for v in values):
        return out
    c4, c2, c1 = values  # h/4, h/2, h
    d_coarse, d_fine = c1 - c2, c2 - c4
    p = 1.0
    if d_fine != 0.0 and d_coarse * d_fine > 0.0:
        observed = math.log2(d_coarse / d_fine)
        if 0.5 <= observed <= 3.0:
            p, out["order_observed"] = observed, True
    limit = c4 + (c4 - c2) / (2.0 ** p - 1.0)
    hw = [by[h].get("half_width") or 0.0 for h in fine]
    # the differences the estimate rests on, against their own 95 % intervals: below them it extrapolates noise
    out["noise_dominated"] = bool(abs(d_fine) <= math.hypot(hw[0], hw[1]) or abs(d_coarse) <= math.hypot(hw[1], hw[2]))
    out.update(order=p, limit=limit,
               errors={f"{h:g}": (by[h]["cost_of_transport"] / limit - 1.0
                                  if by[h]["walked"] and by[h]["cost_of_transport"] else None) for h in steps})
    return out






def choose_step(rows: list[dict], steps: list[float], reference: float, tolerance: float) -> dict:
    """Judge each step against the reference and choose the default.

    rows: one per (time_step_s, window) with "walked" and "cost_of_transport"; each gains "cmt_deviation"
    (relative to the same walk at the reference step, None when either fell). A walk that falls at the
    reference has no reference C_mt: it is listed in "not_judged". A step passes when every judged walk
    walks there with |deviation| <= tolerance, or within the 95 % interval of the difference (rows that carry
    their long-run "half_width": an irregular gait's 100 m mean scatters by about 2 %, and a step whose walk is
    indistinguishable from the reference's at that length is not failed by the scatter). The chosen step is
    the largest one at or above the reference (the finest step, by default) such that it and every step
    between it and the reference pass.
    """
    ref = {tuple(r["window"] or ()): r for r in rows if r["time_step_s"] == reference}
    for r in rows:
        base = ref.get(tuple(r["window"] or ()))
        ok = (r["walked"] and base is not None and base["walked"] and r["cost_of_transport"] is not None
              and base["cost_of_transport"] is not None)
        r["cmt_deviation"] = (r["cost_of_transport"] / base["cost_of_transport"] - 1.0) if ok else None
        # the 95 % interval of the difference, where the rows carry their long-run intervals
        r["deviation_noise"] = (math.hypot(r.get("half_width") or 0.0, base.get("half_width") or 0.0)
                                / base["cost_of_transport"]) if ok else None
    judged = {key for key, r in ref.items() if r["walked"]}

    def agrees(r) -> bool:
        dev = r["cmt_deviation"]
        return dev is not None and (abs(dev) <= tolerance or abs(dev) <= r["deviation_noise"])

    passing = [h for h in steps
               if all(agrees(r) for r in rows if r["time_step_s"] == h and tuple(r["window"] or ()) in judged)]
    chosen = None
    for h in sorted(x for x in steps if x >= reference):
        if h not in passing:
            break
        chosen = h
    return {"passing_steps": passing, "chosen_step_s": chosen,
            "not_judged": [list(k) or None for k in ref if k not in judged]}








@dataclass(frozen=True)
class TimeStepSettings:
    """The time steps compared (s), the reference among them, the distance walked, the gait (None: the
    default one; its own time step is replaced by each of `steps`), its name for the report, and the
    windows (t1, t2) compared with none (None: those of WALKS)."""

    steps: tuple[float, ...] = STEPS
    reference_s: float = min(STEPS)
    distance_m: float = LONG_WALK_M
    config: EpisodeConfig | None = None
    gait: str = "Default gait"
    windows: tuple[tuple[float, float], ...] | None = None
    force: bool = False  # more than MAX_WALKS walks
    measure: str = "long-run"  # what is compared: the long-run mean (MEASURES)

    def __post_init__(self) -> None:
        sim = (self.config or EpisodeConfig()).sim
        for h in self.steps:  # a fixed-rate loop is refined over the plant step alone: each step must divide it
            with_time_step(sim, h, "--steps")
        if self.reference_s not in self.steps:
            raise ParameterError(f"--reference {self.reference_s!r} must be one of --steps {sorted(self.steps)}")
        for t1, t2 in self.windows or ():
            if not 0.0 <= t1 < t2:
                raise ParameterError(f"--windows {t1:g}-{t2:g}: need 0 <= t1 < t2")
        if self.measure not in MEASURES:
            raise ParameterError(f"--measure {self.measure!r} is not one of {list(MEASURES)}")
        if self.measure == "long-run" and not has_long_run(self.distance_m):
            raise ParameterError(f"--distance {self.distance_m:g}: the study compares long-run means, which need "
                                 f"walks of at least {TRANSIENT_M + LONG_RUN_M:g} m (the first {TRANSIENT_M:g} m "
                                 f"dropped, {LONG_RUN_M:g} m measured); give --measure episode to compare the whole "
                                 "walks' C_mt instead")
        if len(set(self.steps)) != len(self.steps):
            raise ParameterError(f"--steps {','.join(f'{h:g}' for h in self.steps)}: a step is given twice")
        check_walks(f"--steps ({len(self.steps)}) x walks ({1 + len(self.windows or WALKS[1:])})",
                    len(self.steps) * (1 + len(self.windows or WALKS[1:])), self.force)


def run(settings: TimeStepSettings, out: Path, client=None, progress: bool = True) -> dict:
    """Run the study on `client` (a LocalCluster when None); write time_step_study.json, .md and .png into
    `out` (each walk kept in `out`/walks as it finishes: a rerun resumes); return the record."""
    check_settings(settings, TimeStepSettings, "time_step.run")
    from drake_biped.common.executor import client_or_local

    out = Path(out)
    steps = sorted(settings.steps)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    with client_or_local(client) as c:
        rec = study(steps, settings.reference_s, settings.distance_m, c, progress, settings.config,
                    settings.windows, settings.measure, keep=out / "walks")
    rec.update(gait=settings.gait, date=time.strftime("%Y-%m-%d %H:%M:%S %Z"), versions=versions(), wall_s=time.perf_counter() - t0)
    write_text_atomic(out / "time_step_study.json", json.dumps(rec, indent=2) + "\n")
    replot(out)
    return rec


def replot(out: Path) -> dict:
    """Redraw the Markdown and the figure from out/time_step_study.json."""
    rec = read_json(out / "time_step_study.json", "--replot")
    missing = [k for k in ("steps", "rows", "reference_s") if not isinstance(rec, dict) or k not in rec]
    if missing:
        raise ParameterError(f"--replot {out / 'time_step_study.json'}: not a time-step study (no {missing[0]!r})")
    rec.setdefault("walks", STUDY_WALKS_BEFORE_RECORDED)
    write_text_atomic(out / "time_step_study.md", markdown(rec))
    figure(rec, out / "time_step_study.png")
    return rec


COMMAND = "time-step-study"
PARSER = dict(help="the long-run C_mt against the plant step (the controller's clock refined with it, or a "
              "fixed-rate loop kept), "
              "Richardson's limit, and the step they choose")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped time-step-study`'s options."""
    p.add_argument("--steps", type=steps, default=None,
                   help="plant steps (s), comma-separated (default 0.002,0.001,0.0005,0.00025,0.000125, or those of "
                   "them that divide a fixed-rate loop's period)")
    p.add_argument("--reference", type=number("positive"), default=None,
                   help="reference step (s), one of --steps (default: the finest)")
    p.add_argument("--distance", type=number("positive"), default=LONG_WALK_M,
                   help="walk this far (m); default 110: the first 10 m are the transient, the long-run C_mt is "
                   "over the rest")
    p.add_argument("--params", help="the gait (a shipped gait's name or a JSON file, as elsewhere); default: the "
                   "paper's walker. Its own time step is replaced by each of --steps")
    add_model_option(p)
    add_clock_option(p)
    p.add_argument("--windows", type=windows,
                   help="the windows compared with none, T1-T2 in s, comma-separated (default: the gait's own, the "
                   "one its file declares; without --params the paper walker's 0.1-0.2 and 0.5-0.6, late in its step)")
    p.add_argument("--measure", choices=MEASURES, default="long-run",
                   help="what is compared at each step: the long-run mean after the first 10 m (walks of 110 m or "
                   "more), or the whole walk's C_mt ('episode', any distance)")
    add_cluster_options(p)
    p.add_argument("--replot", action="store_true", help="redraw the table and figure from OUT's JSON")
    p.add_argument("--out", required=True, type=out_folder, help="output folder")


def settings_from_args(args: argparse.Namespace) -> TimeStepSettings:
    """The study's settings from the command's options."""
    from drake_biped.resources import load_gait

    config = None if args.params is None else load_gait(args.params)
    if args.model is not None:
        config = with_model(config or EpisodeConfig(), args.model)
    if args.control_period is not None:
        config = with_clock(config or EpisodeConfig(), None, args.control_period)
    chosen = args.steps
    if chosen is None:
        period = (config or EpisodeConfig()).sim.control_period_s
        chosen = [h for h in STEPS if period is None or abs(period / h - round(period / h)) <= 1e-6]
    reference = min(chosen) if args.reference is None else args.reference
    print(gait_line(config or EpisodeConfig()))
    compared = None if args.windows is None else tuple(args.windows)
    if compared is None and args.params is not None:  # the gait's own window, never another gait's
        window, source = default_window(config, args.params)
        print(window_line(window, source))
        compared = (window,)
    return TimeStepSettings(tuple(chosen), reference, args.distance, config,
                            "The paper's walker" if args.params is None else f"Gait {args.params}",
                            compared, force=args.force, measure=args.measure)


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    out = Path(args.out)
    if args.replot:
        rec = replot(out)
    else:
        settings = settings_from_args(args)
        with cluster(args) as client:
            rec = run(settings, out, client)
    print((out / "time_step_study.md").read_text())
    chosen = rec["chosen_step_s"]
    print(f"chosen step: {chosen * 1e3:g} ms" if chosen else "no step passes", f"; wrote {out}/")
    return 0
