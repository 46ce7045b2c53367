"""Speed of the walking episode: plant alone vs closed loop per time step for each gait (the paper's walker,
`paper`, and our own faster gait, `fast_servo`), episodes per minute, Dask 1 vs 2 workers, import and build time,
peak memory per worker.

    python benchmarks/bench.py --out out/bench            # about 10 minutes on 2 cores
    python benchmarks/bench.py --out out/bench --quick    # one repeat, two time steps, 2 m, small Dask run

Writes OUT/benchmarks.json (every sample, with the versions and the machine) and OUT/benchmarks.md (tables).

Plant alone: the same MultibodyPlant with the same contact, driven by a zero-order hold of the closed
loop's logged torques (a built-in TrajectorySource; no Python during the simulation). From the same initial
state at the same time step it retraces the closed-loop walk exactly, so both see the same contacts.
Real-time factor = simulated time / wall time of Simulator.AdvanceTo (building the diagram excluded).
Episodes per minute counts the whole `run_episode` call (build, simulate, summarise).
The measurements of the different time steps are interleaved within each repeat, so a change in machine
load affects all of them alike; tables give medians.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from pydrake.systems.framework import LeafSystem

from drake_biped.common.executor import dask_client, episode_task, map_ordered, peak_rss_mb
from drake_biped.control_kernel import N_STATE
from drake_biped.controller import CpgWalkingController
from drake_biped.diagram import build_replay_diagram, initial_state
from drake_biped.episode import run_episode
from drake_biped.kinematics import center_of_mass
from drake_biped.model import build_plant
from drake_biped.params import EpisodeConfig, SimulationParams, TorqueFreeWindow
from drake_biped.resources import load_gait
from drake_biped.versions import versions

DASK_WINDOWS = [None, (0.1, 0.4), (0.2, 0.5), (0.3, 0.6), (0.1, 0.5), (0.2, 0.6), (0.1, 0.3), (0.2, 0.4)]


def config_at(step: float | None, distance: float, window: tuple[float, float] | None = None,
              gait: str = "paper") -> EpisodeConfig:
    """The shipped gait `gait` at plant and control step `step` (None: its own), walking `distance` metres."""
    base = load_gait(gait)
    step = base.sim.time_step_s if step is None else step
    sim = SimulationParams(time_step_s=step, control_period_s=step, distance_m=distance,
                           max_time_s=max(base.sim.max_time_s, 6.0 * distance))
    w = TorqueFreeWindow(*window) if window else TorqueFreeWindow(0.0, 0.0)
    return base.replace(sim=sim, window=w)


def time_import(module: str, repeats: int) -> list[float]:
    code = f"import time; t = time.perf_counter(); import {module}; print(time.perf_counter() - t)"
    out = []
    for _ in range(repeats):
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        out.append(float(run.stdout.strip().splitlines()[-1]))
    return out


def time_build(config: EpisodeConfig, repeats: int) -> list[float]:
    from pydrake.systems.analysis import Simulator

    from drake_biped.diagram import build_diagram

    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        parts = build_diagram(config)
        Simulator(parts.diagram).Initialize()
        out.append(time.perf_counter() - t)
    return out


class EmptyUpdate(LeafSystem):
    """A Python system with a periodic discrete update that does nothing: the cost of the call itself."""

    def __init__(self, period: float, io: bool = False):
        super().__init__()
        self._input = self.DeclareVectorInputPort("plant_state", 18)
        self._torques = self.DeclareDiscreteState(6)
        self._state = self.DeclareDiscreteState(N_STATE)
        self.DeclareStateOutputPort("actuation", self._torques)
        self._io = io
        self.DeclarePeriodicDiscreteUpdateEvent(period, 0.0, self._update)

    def _update(self, context, discrete_state):
        if self._io:  # the controller's input and output traffic, with no computation
            self._input.Eval(context)
            s = context.get_discrete_state(self._state).value().copy()
            discrete_state.set_value(self._torques, s[:6])
            discrete_state.set_value(self._state, s)


def replay(config: EpisodeConfig, times: np.ndarray, torques: np.ndarray, duration: float,
           observer: LeafSystem | None = None) -> tuple[float, np.ndarray]:
    """Wall time of the plant alone (plus an observer, if given) over `duration`, and its final positions."""
    from pydrake.systems.analysis import Simulator

    diagram, plant = build_replay_diagram(config, times, torques, observer)
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(root)
    q0, v0, stance_right, liftoff = initial_state(config)
    plant.SetPositions(plant_context, q0)
    plant.SetVelocities(plant_context, v0)
    if isinstance(observer, CpgWalkingController):
        observer.set_initial_state(observer.GetMyMutableContextFromRoot(root), q0[3:], center_of_mass(q0)[0],
                                   stance_right=stance_right, liftoff_angle=liftoff)
    simulator.Initialize()
    t = time.perf_counter()
    simulator.AdvanceTo(duration)
    return time.perf_counter() - t, plant.GetPositions(plant_context)


def replay_directly(config: EpisodeConfig, times: np.ndarray, torques: np.ndarray, duration: float) -> tuple[float, np.ndarray]:
    """Wall time of the plant alone over `duration`, stepped by a Python loop (its forced update, as
    episode._step_directly steps it) instead of the Simulator, and its final positions: the floor of the
    directly stepped closed loop."""
    diagram, plant = build_replay_diagram(config, times, torques)
    root = diagram.CreateDefaultContext()
    plant_context = plant.GetMyMutableContextFromRoot(root)
    q0, v0, _, _ = initial_state(config)
    plant.SetPositions(plant_context, q0)
    plant.SetVelocities(plant_context, v0)
    h = config.sim.time_step_s
    step, set_time = plant.ExecuteForcedEvents, root.SetTime
    k = 0
    t = time.perf_counter()
    while k * h < duration:
        set_time(k * h)
        step(plant_context, False)
        k += 1
    return time.perf_counter() - t, plant.GetPositions(plant_context)


def plant_share_in_loop(config: EpisodeConfig) -> tuple[float, float, int, float]:
    """One closed-loop episode of `config` with the wall time of every plant step counted: (the time in the
    plant's steps, the episode loop's wall time, the plant's steps, the episode's C_mt). Their ratio is the closed loop against the plant alone on the
    very same walk, every contact and every motor constraint as the closed loop met them: the measure for a
    gait whose replayed plant does not retrace its walk (the plant's hip motors, whose gains the controller
    changes between steps; a replay of their torques falls within 2 m). The timer's own cost (two clock reads a
    step) is counted in the loop's time only, so the ratio errs low."""
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.systems.framework import System

    step = System.ExecuteForcedEvents
    spent = [0.0, 0]
    clock = time.perf_counter

    def timed(self, *args):
        t = clock()
        try:
            return step(self, *args)
        finally:
            spent[0] += clock() - t
            spent[1] += 1

    MultibodyPlant.ExecuteForcedEvents = timed
    try:
        r = run_episode(config)
    finally:
        del MultibodyPlant.ExecuteForcedEvents
    return spent[0], r.wall_time_s, spent[1], r.cost_of_transport


def real_time_factors(steps: list[float], distance: float, repeats: int, gaits: list[str]) -> dict:
    """Plant alone vs closed loop for each gait at each time step, interleaved, `repeats` rounds."""
    logged = {}
    runs = [(g, h) for g in gaits for h in steps]
    for g, h in runs:
        r = run_episode(config_at(h, distance, gait=g), record_trajectory=True)
        logged[g, h] = r
        print(f"  recorded {g} at {h * 1e3:g} ms: {r.duration_s:.2f} s simulated, {r.distance_m:.2f} m, fell={r.fell}")
    samples = {run: {"plant": [], "closed": [], "episode_wall": [], "in_loop": [], "replay_error_m": None}
               for run in runs}
    for k in range(repeats):
        for g, h in runs:
            ref = logged[g, h]
            cfg = config_at(h, distance, gait=g)
            end = float(ref.trajectory["time"][-1])  # the last logged state
            wall, q_end = replay(cfg, ref.trajectory["time"], ref.trajectory["actuation"], end)
            s = samples[g, h]
            s["plant"].append(end / wall)
            s["replay_error_m"] = float(np.max(np.abs(q_end[:2] - ref.trajectory["positions"][-1][:2])))
            t = time.perf_counter()
            r = run_episode(cfg)
            s["episode_wall"].append(time.perf_counter() - t)
            s["closed"].append(r.real_time_factor)
            in_plant, loop, _, _ = plant_share_in_loop(cfg)
            s["in_loop"].append(in_plant / loop)
            print(f"  round {k + 1}/{repeats} {g} {h * 1e3:g} ms: plant {s['plant'][-1]:.2f}x, "
                  f"closed loop {r.real_time_factor:.2f}x, the plant's steps {s['in_loop'][-1]:.2f} of the loop",
                  flush=True)
    rows = []
    for g, h in runs:
        s = samples[g, h]
        plant, closed = statistics.median(s["plant"]), statistics.median(s["closed"])
        rows.append({
            "gait": g,
            "time_step_s": h,
            "simulated_s": logged[g, h].duration_s,
            "distance_m": logged[g, h].distance_m,
            "fell": logged[g, h].fell,
            "plant_alone_rtf": plant,
            "closed_loop_rtf": closed,
            "ratio": closed / plant,
            "plant_share_in_loop": statistics.median(s["in_loop"]),
            "episode_wall_s": statistics.median(s["episode_wall"]),
            "episodes_per_min": 60.0 / statistics.median(s["episode_wall"]),
            "replay_max_position_error_m": s["replay_error_m"],
            "samples": {key: s[key] for key in ("plant", "closed", "episode_wall", "in_loop")},
        })
    return {"distance_m": distance, "repeats": repeats, "rows": rows}


def python_floor(distance: float, repeats: int, gait: str = "paper") -> dict:
    """At the gait's own step: the plant alone, plus an empty Python update, plus one that only moves the
    controller's inputs and outputs, plus the real controller computing alongside (its torques unused):
    microseconds of wall time per simulated millisecond, medians of `repeats` interleaved rounds."""
    config = config_at(None, distance, gait=gait)
    h = config.sim.time_step_s
    ref = run_episode(config, record_trajectory=True)
    times, torques = ref.trajectory["time"], ref.trajectory["actuation"]
    duration = float(times[-1])
    variants = {
        "plant alone": lambda: None,
        "+ empty Python update": lambda: EmptyUpdate(h),
        "+ the controller's I/O only": lambda: EmptyUpdate(h, io=True),
        # the hip motor reads the plant's dynamics (through a context of its own): a plant of the same model
        "+ the controller": lambda: CpgWalkingController(config, plant=build_plant(
            config.ground, config.sim.time_step_s, config.model, config.contact)),
    }
    samples: dict[str, list[float]] = {name: [] for name in variants}
    error = 0.0
    for _ in range(repeats):
        for name, make in variants.items():
            wall, q_end = replay(config, times, torques, duration, make())
            samples[name].append(wall / duration * 1e3)  # us per simulated ms
            error = max(error, float(np.max(np.abs(q_end[:2] - ref.trajectory["positions"][-1][:2]))))
    rows = [{"variant": name, "us_per_ms": statistics.median(v), "samples": v} for name, v in samples.items()]
    base = rows[0]["us_per_ms"]
    for r in rows:
        r["ratio_to_plant"] = base / r["us_per_ms"]
    print("  " + ", ".join(f"{r['variant']}: {r['us_per_ms']:.0f} us/ms" for r in rows))
    return {"gait": gait, "time_step_s": h, "distance_m": distance, "simulated_s": duration, "repeats": repeats,
            "replay_max_position_error_m": error, "rows": rows}


def contact_approximations(distance: float) -> list[dict]:
    """The closed loop under each of Drake's discrete contact approximations, with and without a window."""
    rows = []
    for approx in SimulationParams.CONTACT_APPROXIMATIONS:
        for window in (None, (0.1, 0.2)):
            base = config_at(None, distance, window)
            r = run_episode(base.replace(sim=dataclasses.replace(base.sim, contact_approximation=approx)))
            rows.append({"approximation": approx, "window": window, "walked": not r.fell,
                         "distance_m": r.distance_m, "cost_of_transport": r.cost_of_transport,
                         "real_time_factor": r.real_time_factor})
            print(f"  {approx} window={window}: {r.distance_m:.2f} m, C_mt {r.cost_of_transport}, "
                  f"{r.real_time_factor:.2f}x")
    return rows


def dask_runs(worker_counts: list[int], n_episodes: int, distance: float) -> list[dict]:
    """The same episodes on LocalClusters of each size, in the order 1, 2, 2, 1 (...), so that a drift in
    machine speed affects every size alike; one row per size with the mean wall time of its runs."""
    configs = [config_at(None, distance, DASK_WINDOWS[i % len(DASK_WINDOWS)]).to_dict() for i in range(n_episodes)]
    runs: dict[int, list[dict]] = {n: [] for n in worker_counts}
    for n in worker_counts + worker_counts[::-1]:
        t0 = time.perf_counter()
        with dask_client(workers=n) as client:
            started = time.perf_counter() - t0
            client.submit(sum, [1, 2]).result()  # workers are up and answering
            t1 = time.perf_counter()
            results = map_ordered(client, episode_task, configs)
            wall = time.perf_counter() - t1
        runs[n].append({"wall_s": wall, "cluster_start_s": started, "results": results})
        print(f"  dask {n} worker(s): {n_episodes} episodes in {wall:.1f} s ({60.0 * n_episodes / wall:.1f}/min)")
    out = []
    for n, rs in runs.items():
        wall = statistics.mean(r["wall_s"] for r in rs)
        results = [x for r in rs for x in r["results"]]
        out.append({
            "workers": n,
            "episodes": n_episodes,
            "runs": len(rs),
            "distance_m": distance,
            "cluster_start_s": statistics.mean(r["cluster_start_s"] for r in rs),
            "wall_s": wall,
            "wall_s_samples": [r["wall_s"] for r in rs],
            "episodes_per_min": 60.0 * n_episodes / wall,
            "peak_rss_mb_per_worker": max(x["worker_peak_rss_mb"] for x in results),
            "simulated_s": sum(x["duration_s"] for x in rs[0]["results"]),
            "same_results_in_every_run": len({tuple(x["cost_of_transport"] for x in r["results"]) for r in rs}) == 1,
        })
    costs = {tuple(x["cost_of_transport"] for x in rs[0]["results"]) for rs in runs.values()}
    for row in out:
        row["same_results_for_every_size"] = len(costs) == 1
    return out


def learning_mix(n_episodes: int, workers: int, seed: int = 0) -> dict:
    """Episodes as a learning run starts them: windows drawn from GARB's initial policy (mean (0.5, 0.5) s,
    variance 0.04 s^2 per component, negative times clipped to 0), 10 m or a fall, on `workers` workers."""
    rng = np.random.default_rng(seed)
    windows = np.clip(rng.normal(0.5, 0.2, size=(n_episodes, 2)), 0.0, None)
    configs = [config_at(None, 10.0, (float(a), float(b))).to_dict() for a, b in windows]
    with dask_client(workers=workers) as client:
        client.submit(sum, [1, 2]).result()
        t0 = time.perf_counter()
        results = map_ordered(client, episode_task, configs)
        wall = time.perf_counter() - t0
    falls = sum(r["fell"] for r in results)
    per_min = 60.0 * n_episodes / wall
    out = {"episodes": n_episodes, "workers": workers, "seed": seed, "wall_s": wall, "episodes_per_min": per_min,
           "falls": falls, "simulated_s": sum(r["duration_s"] for r in results),
           "experiment_1_minutes": 2500 / per_min}
    print(f"  learning mix: {n_episodes} episodes ({falls} falls) in {wall:.1f} s on {workers} workers = "
          f"{per_min:.1f}/min; Experiment 1 (2500 episodes) ~ {out['experiment_1_minutes']:.0f} min")
    return out


def markdown(record: dict) -> str:
    lines = [
        "# drake-biped benchmarks",
        "",
        f"{record['machine']['cpus']} CPUs, {record['machine']['platform']}, Python {record['machine']['python']}, "
        f"Drake {record['versions']['drake']}, commit {record['versions']['git_commit']}, {record['date']}.",
        "",
        f"## Real-time factor, {record['rtf']['distance_m']:g} m walk (no window), "
        f"median of {record['rtf']['repeats']}",
        "",
        "| gait | time step | simulated | plant alone | closed loop | closed / plant | plant's steps / loop "
        "| episode wall | episodes/min |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in record["rtf"]["rows"]:
        share = f"{r['plant_share_in_loop']:.2f}" if "plant_share_in_loop" in r else "—"
        lines.append(
            f"| {r.get('gait', 'paper')} | {r['time_step_s'] * 1e3:g} ms | {r['simulated_s']:.2f} s{' (fell)' if r['fell'] else ''} | "
            f"{r['plant_alone_rtf']:.2f}× | {r['closed_loop_rtf']:.2f}× | {r['ratio']:.2f} | {share} | "
            f"{r['episode_wall_s']:.2f} s | {r['episodes_per_min']:.1f} |"
        )
    lines += ["", "Plant alone: the same plant replaying the closed loop's logged torques (largest final position "
              "difference from the closed loop: "
              + ", ".join(f"{r['replay_max_position_error_m']:.1e} m" for r in record["rtf"]["rows"]) + "; a "
              "replay that does not retrace its walk times another walk). The plant's steps / loop: the wall "
              "time spent in the plant's steps within the closed loop's own episode, over the loop's (the same "
              "walk, its contacts and motors as met; the timer's cost counted against the loop)."]
    for f in record.get("floors", []):
        lines += ["", f"## Where the closed loop's time goes: {f['gait']} at {1e3 * f['time_step_s']:g} ms "
                  f"({f['simulated_s']:.1f} simulated s, median of {f['repeats']})", "",
                  "Each variant replays the same logged torques; the systems added compute alongside the plant "
                  "without driving it."
                  + (f" The replay does not retrace this walk ({f['replay_max_position_error_m']:.1g} m off at its "
                     "end): these rows time another walk, and the real-time table's plant's steps / loop is the "
                     "measure." if f.get("replay_max_position_error_m", 0.0) > 1e-6 else ""), "",
                  "| variant | wall µs per simulated ms | plant alone / variant |", "|---|---|---|"]
        for r in f["rows"]:
            lines.append(f"| {r['variant']} | {r['us_per_ms']:.0f} | {r['ratio_to_plant']:.2f} |")
    if record.get("contact"):
        lines += ["", f"## Contact approximation, the paper's walker at its own step, {record['rtf']['distance_m']:g} m", "",
                  "| approximation | window | walked | distance | C_mt | real-time factor |", "|---|---|---|---|---|---|"]
        for r in record["contact"]:
            cmt = "—" if r["cost_of_transport"] is None else f"{r['cost_of_transport']:.4f}"
            lines.append(f"| {r['approximation']} | {r['window'] or 'none'} | {'yes' if r['walked'] else 'no'} | "
                         f"{r['distance_m']:.2f} m | {cmt} | {r['real_time_factor']:.2f}× |")
    if record.get("dask"):
        lines += ["", f"## Dask LocalCluster, the paper's walker at its own step, {record['dask'][0]['distance_m']:g} m "
                  "episodes with assorted windows", "",
                  "Sizes run in the order 1, 2, 2, 1; wall = mean of the two runs of a size. "
                  f"Same C_mt in every run and size: {record['dask'][0]['same_results_for_every_size']}.", "",
                  "| workers | episodes | wall | episodes/min | speed-up | cluster start | peak memory/worker |",
                  "|---|---|---|---|---|---|---|"]
        base = record["dask"][0]["episodes_per_min"]
        for d in record["dask"]:
            lines.append(
                f"| {d['workers']} | {d['episodes']} | {d['wall_s']:.1f} s | {d['episodes_per_min']:.1f} | "
                f"{d['episodes_per_min'] / base:.2f}× | {d['cluster_start_s']:.1f} s | {d['peak_rss_mb_per_worker']:.0f} MB |"
            )
    if record.get("learning"):
        m = record["learning"]
        lines += ["", "## Experiment 1 estimate", "",
                  f"{m['episodes']} episodes with windows drawn from GARB's initial policy (seed {m['seed']}; "
                  f"{m['falls']} fell) on {m['workers']} Dask workers: {m['wall_s']:.1f} s, "
                  f"**{m['episodes_per_min']:.1f} episodes/min**, so Experiment 1 (5 trials × 500 episodes) "
                  f"≈ **{m['experiment_1_minutes']:.0f} min** at this mix. With every episode walking 10 m "
                  f"(the Dask table's rate on 2 workers) it would take "
                  f"≈ {2500 / record['dask'][-1]['episodes_per_min']:.0f} min." if record.get("dask") else ""]
    imp, build = record["import_s"], record["build_s"]
    lines += [
        "",
        "## Start-up",
        "",
        f"- `import pydrake.all`: {statistics.median(imp['pydrake.all']):.2f} s; "
        f"`import drake_biped.episode`: {statistics.median(imp['drake_biped.episode']):.2f} s "
        f"(fresh interpreter, median of {len(imp['pydrake.all'])})",
        f"- build the diagram + Simulator.Initialize: {statistics.median(build):.3f} s (median of {len(build)})",
        f"- peak memory of this process: {record['peak_rss_mb_main']:.0f} MB",
        "",
    ]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=Path("out/bench"))
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--distance", type=float, default=10.0)
    p.add_argument("--steps", default="0.0005,0.001,0.002", help="time steps (s), comma-separated")
    p.add_argument("--gaits", default="paper,fast_servo", help="shipped gaits, comma-separated")
    p.add_argument("--dask-episodes", type=int, default=8, help="0 skips the Dask runs")
    p.add_argument("--quick", action="store_true", help="one repeat, 1 and 2 ms, 2 m, 2 Dask episodes")
    args = p.parse_args(argv)
    steps = [float(s) for s in args.steps.split(",")]
    repeats, distance, n_dask = args.repeats, args.distance, args.dask_episodes
    if args.quick:
        steps, repeats, distance, n_dask = [5e-4, 1e-3], 1, 2.0, 2
    if repeats < 1 or distance <= 0 or n_dask < 0 or any(h <= 0 for h in steps):
        p.error("--repeats >= 1, --distance > 0, --dask-episodes >= 0 and positive --steps are required")
    args.out.mkdir(parents=True, exist_ok=True)

    print("import and build times")
    record = {
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        "versions": versions(),
        "machine": {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()},
        "import_s": {m: time_import(m, 3) for m in ("pydrake.all", "drake_biped.episode")},
        "build_s": time_build(EpisodeConfig(), 5),
    }
    print("real-time factors")
    gaits = [g for g in args.gaits.split(",") if g]
    record["rtf"] = real_time_factors(steps, distance, repeats, gaits)
    print("where the time goes (each gait at its own step)")
    record["floors"] = [python_floor(distance, max(repeats, 3), g) for g in gaits]
    print("contact approximations")
    record["contact"] = contact_approximations(distance)
    if n_dask:
        print("dask")
        record["dask"] = dask_runs([1, 2], n_dask, 10.0 if not args.quick else distance)
        print("learning mix")
        record["learning"] = learning_mix(4 if args.quick else 24, 2)
    record["peak_rss_mb_main"] = peak_rss_mb()
    (args.out / "benchmarks.json").write_text(json.dumps(record, indent=2) + "\n")
    table = markdown(record)
    (args.out / "benchmarks.md").write_text(table)
    print(table)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
