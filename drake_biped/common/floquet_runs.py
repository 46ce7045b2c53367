"""The gait's periodic orbit and its Floquet multipliers through Drake (`drake-biped floquet`).

The full-state step map on the mid-stance section (drake_biped/step_map.py) is evaluated on Dask: the fixed
point by Newton's method from the steady walk, the central-difference Jacobian for a sweep of the
perturbation over several decades, the multipliers at the converged ε with their eigenvectors by name, and
two cross-checks: the linearisation's prediction of a small perturbation's next steps against the map
iterated, and against the simulation continued without restarting (the controller is a sampled-data
system: the map restarts the 1 ms update grid at the section, a continued walk keeps its own grid phase, and
the difference between them is measured as the gait's sensitivity to the sampling phase).

Each task's evaluations of the map are kept in OUT/step_map/ as it finishes (`kept_batch`): a rerun into the
same folder evaluates only the points not kept, and writes the record an uninterrupted run writes.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from drake_biped.analysis import floquet as fq
from drake_biped.analysis.floquet_report import figure, markdown
from drake_biped.analysis.return_map import complex_list
from drake_biped.common.options import (
    check_size,
)
from drake_biped.params import EpisodeConfig, ParameterError, check_settings
from drake_biped.records import write_record
from drake_biped.versions import versions

__all__ = ["FloquetSettings", "analyse", "kept_batch", "run"]

DEFAULT_EPSILONS = tuple(float(10.0 ** e) for e in np.arange(-8.0, -2.49, 0.5))
# The regression's perturbation sizes, relative to each coordinate's scale: from well inside a walker's
# step-to-step spread to where its perturbed steps begin to fall.
DEFAULT_REGRESSION_SIZES = (1e-3, 3e-3, 1e-2, 2e-2, 3e-2)


# The most step-map evaluations of one kind a Floquet run is given (settling steps, Newton's iterations, the
# transient of the period search, the decay check), and the most perturbation sizes swept (each a Jacobian).
MAX_MAP_STEPS = 1000
MAX_EPSILONS = 40


@dataclass(frozen=True)
class FloquetSettings:
    """The gait (its window included), the start of the search, the perturbation sweep and the checks."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    settle_steps: int = 8
    epsilons: tuple[float, ...] = DEFAULT_EPSILONS
    newton_epsilon: float = 1e-6
    newton_tolerance: float = fq.NEWTON_TOLERANCE
    newton_iterations: int = 6
    plateau_tolerance: float = 0.05
    decay_steps: int = 5
    # The perturbation of the decay check (`decay_size()`): the largest that keeps J^k delta inside the
    # sweep's plateau (the linear range) over the decay_steps; decay_size without a plateau; at least
    # decay_floor.
    decay_size: float = 1e-6
    decay_floor: float = 1e-10
    # The orbit's period: the map iterated period_transient times from the settled section, then the smallest
    # k <= 8 with which its iterates repeat to within period_tolerance (relative; `floquet.periodic_orbit`).
    period_transient: int = 60
    period_tolerance: float = 1e-6
    # The regression's Jacobians (`regression`): `regression_samples` perturbations per size (0: none), each
    # coordinate by `size` x its scale (`regression_scales`), for each of `regression_sizes`.
    regression_samples: int = 0
    regression_sizes: tuple[float, ...] = DEFAULT_REGRESSION_SIZES

    def __post_init__(self) -> None:
        if not isinstance(self.settle_steps, int) or self.settle_steps < 1:
            raise ParameterError(f"settle_steps {self.settle_steps!r}: must be an integer >= 1")
        if len(self.epsilons) < 3 or any(not (math.isfinite(e) and e > 0) for e in self.epsilons):
            raise ParameterError(f"epsilons {self.epsilons!r}: need at least three positive sizes")
        for name in ("newton_epsilon", "newton_tolerance", "plateau_tolerance", "decay_size", "decay_floor"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0):
                raise ParameterError(f"{name} {value!r}: must be a positive number")
        if not isinstance(self.decay_steps, int) or self.decay_steps < 1:
            raise ParameterError(f"decay_steps {self.decay_steps!r}: must be an integer >= 1")
        if not isinstance(self.regression_samples, int) or self.regression_samples < 0:
            raise ParameterError(f"regression_samples {self.regression_samples!r}: must be an integer >= 0")
        if self.regression_samples and self.regression_samples < 20:
            raise ParameterError(f"regression_samples {self.regression_samples}: a fit of the 14 section coordinates "
                                 "needs at least 20")
        if len(self.regression_sizes) < 3 or any(not (math.isfinite(e) and e > 0) for e in self.regression_sizes):
            raise ParameterError(f"regression_sizes {self.regression_sizes!r}: need at least three positive sizes")
        for name in ("newton_iterations", "period_transient"):
            if not isinstance(getattr(self, name), int) or getattr(self, name) < 0:
                raise ParameterError(f"{name} {getattr(self, name)!r}: must be an integer >= 0")
        # every one of these is a walk of steps (each a step map's evaluation, 2 x 14 per Jacobian)
        check_size(f"--settle-steps {self.settle_steps}", self.settle_steps, MAX_MAP_STEPS, "steps", None)
        check_size(f"--epsilons ({len(self.epsilons)} sizes)", len(self.epsilons), MAX_EPSILONS, "Jacobians", None)
        for name in ("newton_iterations", "period_transient", "decay_steps"):
            check_size(f"{name} {getattr(self, name)}", getattr(self, name), MAX_MAP_STEPS, "steps", None)
        check_size(f"--regression-samples {self.regression_samples}", self.regression_samples, MAX_MAP_STEPS,
                   "steps", None)
        check_size(f"--regression-sizes ({len(self.regression_sizes)} sizes)", len(self.regression_sizes),
                   MAX_EPSILONS, "Jacobians", None)

    def to_dict(self) -> dict[str, Any]:
        return {"settle_steps": self.settle_steps, "epsilons": list(self.epsilons),
                "newton_epsilon": self.newton_epsilon, "newton_tolerance": self.newton_tolerance,
                "newton_iterations": self.newton_iterations, "plateau_tolerance": self.plateau_tolerance,
                "decay_steps": self.decay_steps, "decay_size": self.decay_size, "decay_floor": self.decay_floor,
                "period_transient": self.period_transient, "period_tolerance": self.period_tolerance,
                **({"regression_samples": self.regression_samples, "regression_sizes": list(self.regression_sizes)}
                   if self.regression_samples else {})}


# Where a run keeps its step map's evaluations as they finish (`kept_batch`), inside its output folder.
KEPT_EVALUATIONS = "step_map"

# A batch's evaluations not yet known, in groups: run_chunks(groups) yields (index of a group, its images: a
# list of numbers each, None for a fall) as each group finishes, in any order.
ChunkRunner = Callable[[list[list[list[float]]]], Iterator[tuple[int, list[list[float] | None]]]]


def kept_batch(run_chunks: ChunkRunner, chunks: int, identity: dict[str, Any], keep: Path | None = None) -> fq.Batch:
    """A batch evaluator of a map that evaluates each point once: a point already evaluated (in this run, or
    kept in `keep` by an earlier one of the same map, `identity`) is read back; the others go to `run_chunks`
    in at most `chunks` groups, and each group is kept in `keep` (one file, atomically) as it finishes. An
    interrupted run, rerun, resumes: its Newton iterates, Jacobian columns and checks ask for the same points
    and find the finished ones, so the map is never evaluated twice at a point and the record is the one an
    uninterrupted run writes. An image that is not finite is not kept (it fails the analysis as it comes)."""
    from drake_biped.records import read_kept, write_atomic

    digest = hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()
    known: dict[bytes, list[float] | None] = {}

    def key(point: list[float]) -> bytes:
        return np.asarray(point, dtype=float).tobytes()

    if keep is not None:
        for path in sorted(Path(keep).glob("*.json")):
            saved = read_kept(path)
            if isinstance(saved, dict) and saved.get("map") == digest:
                known.update((key(p), y) for p, y in zip(saved["points"], saved["images"]))

    def evaluate(points):
        points = [np.asarray(p, dtype=float).tolist() for p in points]
        todo = list({key(p): p for p in points if key(p) not in known}.values())
        size = max(1, math.ceil(len(todo) / chunks))
        groups = [todo[i : i + size] for i in range(0, len(todo), size)]
        for index, images in run_chunks(groups):
            group = groups[index]
            known.update((key(p), y) for p, y in zip(group, images))
            finite = all(np.all(np.isfinite(p)) and (y is None or np.all(np.isfinite(y)))
                         for p, y in zip(group, images))
            if keep is not None and finite:
                name = hashlib.sha256(json.dumps([digest, group]).encode()).hexdigest()[:24]
                Path(keep).mkdir(parents=True, exist_ok=True)
                write_atomic(Path(keep) / f"{name}.json", {"map": digest, "points": group, "images": list(images)})
        return [None if known[key(p)] is None else np.array(known[key(p)]) for p in points]

    return evaluate


def _batch(client, config: dict[str, Any], template: dict[str, Any], keep: Path | None = None) -> fq.Batch:
    """A batch evaluator of the step map on `client`: the points not yet evaluated split evenly over its
    workers, each task's evaluations kept in `keep` as it finishes (`kept_batch`)."""
    from distributed import as_completed

    from drake_biped.common.executor import DrakeGuarded
    from drake_biped.step_map import evaluate_task

    workers = max(1, len(client.scheduler_info()["workers"]))

    def run_chunks(groups):
        futures = {client.submit(DrakeGuarded(evaluate_task), config, template, group, pure=False): i
                   for i, group in enumerate(groups)}
        for future in as_completed(list(futures)):
            yield futures[future], future.result()

    return kept_batch(run_chunks, 2 * workers, {"config": config, "template": template}, keep)


def decay_size(settings: FloquetSettings, plateau: dict[str, Any], radius: float) -> float:
    """The decay check's perturbation: the largest for which the map is still linear over the check, so
    that the deviations stay above the map's rounding for as long as they can: the top of the plateau,
    divided by radius**decay_steps when the mode grows (so the deviation stays below it for
    settings.decay_steps steps); settings.decay_size without a plateau; never below settings.decay_floor."""
    size = settings.decay_size
    if plateau.get("plateau"):
        size = plateau["plateau"][1] / max(1.0, radius) ** settings.decay_steps
    return max(size, settings.decay_floor)


def orbit_radius(config: EpisodeConfig, settle_steps: int = 8, epsilon: float = 1e-6,
                 iterations: int = 4) -> dict[str, Any]:
    """The spectral radius of `config`'s period-1 orbit in one process, for searches (no Dask, no sweep):
    Newton from the section after `settle_steps` touchdowns, then one central-difference Jacobian at
    `epsilon` at the fixed point. Raises ParameterError when the gait falls before its section, StepFailed
    when a perturbed step falls."""
    from drake_biped.step_map import SectionMap

    section_map = SectionMap(config)
    z0, template = section_map.start(settle_steps)
    evaluate = fq.serial(lambda z: section_map.step(z, template))
    fixed = fq.newton_fixed_point(evaluate, z0, epsilon, tolerance=fq.NEWTON_TOLERANCE,
                                  max_iterations=iterations)
    jac = fq.difference_jacobian(evaluate, fixed.state, epsilon)
    mult = fq.multipliers(jac, section_map.section_normal())
    return {"spectral_radius": mult.nontrivial_radius(), "fixed_point_residual": fixed.residual}


def orbit_period(settings: FloquetSettings, evaluate: fq.Batch, z0: np.ndarray, normal: np.ndarray) -> dict[str, Any]:
    """The period of the orbit the section map settles on (`floquet.periodic_orbit`): {"period": k, "multipliers"
    of the k-fold map (non-trivial, [re, im], largest first), "residual", "spread"} or, where no period up to 8
    repeats, {"period": None, "spread"}; "spread": the largest coordinate range over the last 16 iterates."""
    def step(z):
        (y,) = evaluate([z])
        if y is None:
            raise fq.StepFailed("the walker falls on the map's iterates")
        return y

    try:
        orbit = fq.periodic_orbit(step, z0, transient=settings.period_transient,
                                  detect_tolerance=settings.period_tolerance, epsilon=settings.newton_epsilon,
                                  tolerance=settings.newton_tolerance, max_iterations=settings.newton_iterations)
    except fq.NoPeriodicOrbit as exc:
        tail = exc.iterates[-16:]
        return {"period": None, "spread": float(np.max(np.ptp(tail, axis=0)))}
    except fq.StepFailed as exc:
        return {"period": None, "spread": None, "error": str(exc)}
    mult = fq.multipliers(orbit.jacobian, normal)
    keep = [v for v, t in zip(mult.values, mult.trivial) if t is None]
    return {"period": orbit.period, "multipliers": complex_list(np.array(keep)), "residual": orbit.residual,
            "spectral_radius": float(max(abs(v) for v in keep)) if keep else None,
            "spread": float(np.max(np.ptp(orbit.points, axis=0)))}


def regression_scales(z: np.ndarray) -> np.ndarray:
    """Each section coordinate's scale for the regression's perturbations: its own size, and at least a
    tenth of the coordinates' root-mean-square (so that a coordinate that is 0 on the orbit, as the section's
    own angle is, is still perturbed)."""
    z = np.asarray(z, dtype=float)
    return np.maximum(np.abs(z), 0.1 * float(np.sqrt(np.mean(z ** 2))))


def regression(settings: FloquetSettings, evaluate: fq.Batch, z: np.ndarray, normal: np.ndarray,
               names: list[str]) -> dict[str, Any]:
    """The multipliers at the scale of the walker's own disturbances (`floquet.regression_jacobian`): an
    affine fit of the map for each of settings.regression_sizes around Newton's point `z`; the sizes whose
    bootstraps fix the radius and agree (`floquet.regression_plateau`); at the plateau's size, the fitted
    map's fixed point, a fit there, and its multipliers. "established" when a plateau exists and the fit's
    residual at its fixed point, |image − x*| / |x*|, is within the map's evaluation noise there (the fit's
    residual spread)."""
    scales = regression_scales(z)
    samples, tolerance = settings.regression_samples, settings.plateau_tolerance
    rows, fits = [], []
    for k, size in enumerate(settings.regression_sizes):
        try:
            fit = fq.regression_jacobian(evaluate, z, scales, size, samples, seed=k, section_normal=normal)
        except fq.StepFailed as exc:
            rows.append({"size": float(size), "radius": None, "interval": None, "noise": None, "samples": 0,
                         "falls": samples, "error": str(exc)})
            continue
        fits.append(fit)
        rows.append({"size": fit.size, "radius": fit.radius, "interval": list(fit.interval), "noise": fit.noise,
                     "samples": fit.samples, "falls": fit.falls})
    plateau = fq.regression_plateau(fits, tolerance)
    out: dict[str, Any] = {"samples": samples, "scales": {n: float(v) for n, v in zip(names, scales)},
                           "rows": rows, "plateau": plateau, "verdict": "not established: no two sizes agree "
                           f"to {100 * tolerance:g} % with bootstraps that fix them"}
    if plateau["index"] is None:
        return out
    chosen = fits[plateau["index"]]
    x_star = fq.affine_fixed_point(chosen, z)
    try:
        at = fq.regression_jacobian(evaluate, x_star, scales, chosen.size, samples,
                                    seed=len(settings.regression_sizes), section_normal=normal)
    except fq.StepFailed as exc:
        out["verdict"] = f"not established: the fit at the fitted fixed point failed ({exc})"
        return out
    residual = float(np.linalg.norm(at.image - x_star) / max(np.linalg.norm(x_star), 1e-300))
    mult = fq.multipliers(at.jacobian, normal)
    dominant = [{"multiplier": [float(mult.values[k].real), float(mult.values[k].imag)],
                 "modulus": float(abs(mult.values[k])),
                 "components": fq.named_components(mult.vectors[:, k], names)}
                for k in range(min(4, len(mult.values))) if mult.trivial[k] is None]
    if residual > at.noise:
        verdict = f"not established: the fitted fixed point's residual {residual:.1e} is above the noise {at.noise:.1e}"
    elif not at.resolved(tolerance):
        verdict = (f"not established: at the fixed point the radius's bootstrap range {at.interval[0]:.3g}–"
                   f"{at.interval[1]:.3g} is wider than {100 * tolerance:g} %")
    else:
        verdict = "stable" if at.radius < 1.0 else "unstable"
    out.update(fixed_point={n: float(v) for n, v in zip(names, x_star)}, fixed_point_residual=residual,
               noise=at.noise, radius=at.radius, interval=list(at.interval), falls=at.falls,
               multipliers=complex_list(mult.values), trivial=mult.trivial, dominant_modes=dominant,
               jacobian=at.jacobian.tolist(), verdict=verdict)
    return out


def analyse(settings: FloquetSettings, client, keep: Path | None = None) -> dict[str, Any]:
    """The fixed point, the sweep, the multipliers and the cross-checks of `settings.config`'s gait; each step
    map evaluation kept in `keep` as it finishes, and read back from there by a rerun (`kept_batch`)."""
    from drake_biped.step_map import SectionMap

    wall0 = time.perf_counter()
    section_map = SectionMap(settings.config)  # raises ParameterError for a ground or push it cannot take
    z0, template = section_map.start(settings.settle_steps)
    names = list(section_map.names)
    cfg, tmpl = settings.config.to_dict(), template.to_dict()
    evaluate = _batch(client, cfg, tmpl, keep)
    period = orbit_period(settings, evaluate, z0, section_map.section_normal())

    fixed = fq.newton_fixed_point(evaluate, z0, settings.newton_epsilon, tolerance=settings.newton_tolerance,
                                  max_iterations=settings.newton_iterations, max_halvings=8)
    z = fixed.state
    # The map's own noise on the scale of Newton's last residual (at most 1e-6: a larger residual is no fixed
    # point whatever the noise): a residual within it is a fixed point found.
    try:
        noise = fq.evaluation_noise(evaluate, z, min(max(fixed.residual, settings.newton_tolerance), 1e-6))
    except fq.StepFailed:
        noise = None
    floor = fq.newton_floor(settings.newton_tolerance, noise)
    sweep = fq.epsilon_sweep(evaluate, z, settings.epsilons)
    chosen = fq.converged_epsilon(sweep, settings.plateau_tolerance)
    # without a plateau, the sweep's Jacobian nearest Newton's perturbation among those whose steps all walked
    walked = [i for i, r in enumerate(sweep) if r["jacobian"] is not None]
    if not walked:
        raise RuntimeError("every perturbation of the sweep made the walker fall: the gait has no orbit to linearise")
    index = chosen["index"] if chosen["index"] is not None else min(walked, key=lambda i: abs(
        math.log10(settings.epsilons[i]) - math.log10(settings.newton_epsilon)))
    jac = sweep[index]["jacobian"]
    mult = fq.multipliers(jac, section_map.section_normal())
    dominant = []
    for k in range(min(4, len(mult.values))):
        if mult.trivial[k] is None:
            dominant.append({"multiplier": [float(mult.values[k].real), float(mult.values[k].imag)],
                             "modulus": float(abs(mult.values[k])),
                             "components": fq.named_components(mult.vectors[:, k], names)})

    # Cross-checks: a perturbation along the dominant eigenvector (real part), predicted and simulated.
    lead = next(k for k, t in enumerate(mult.trivial) if t is None)
    direction = mult.vectors[:, lead].real
    direction = direction / np.linalg.norm(direction)
    size = decay_size(settings, chosen, mult.nontrivial_radius())
    delta = size * direction
    predicted = fq.predicted_deviations(jac, delta, settings.decay_steps)
    iterated, pair = [], [z + delta, z]
    for _ in range(settings.decay_steps):
        pair = evaluate(pair)
        if pair[0] is None or pair[1] is None:
            break
        iterated.append(pair[0] - pair[1])
    base_run = section_map.trajectory(z, settings.decay_steps, template)
    perturbed_run = section_map.trajectory(z + delta, settings.decay_steps, template)

    def norms(rows):
        return [float(np.linalg.norm(r)) for r in rows]

    decay = {
        "size": size,
        "direction": {n: float(v) for n, v in zip(names, direction)},
        "predicted": norms(predicted),
        "map_iterated": norms(iterated),
        "continued": (norms([a - b for a, b in zip(perturbed_run, base_run)])
                      if perturbed_run and base_run else None),
    }
    decay["map_iterated_ratio"] = [m / p for m, p in zip(decay["map_iterated"], decay["predicted"])]
    if decay["continued"]:
        decay["continued_ratio"] = [c / p for c, p in zip(decay["continued"], decay["predicted"])]
    # The sampling phase: the fixed point continued on its own update grid, against the map's restarts.
    phase = norms([b - z for b in base_run]) if base_run else None

    fitted = (regression(settings, evaluate, z, section_map.section_normal(), names)
              if settings.regression_samples else None)

    return {
        "coordinates": names,
        "multipliers": complex_list(mult.values),
        "trivial": mult.trivial,
        "spectral_radius": mult.spectral_radius,
        "nontrivial_spectral_radius": mult.nontrivial_radius(),
        "dominant_modes": dominant,
        "fixed_point": {n: float(v) for n, v in zip(names, z)},
        "fixed_point_residual": fixed.residual,
        "evaluation_noise": noise,
        "newton_floor": floor,
        "newton_residuals": fixed.residuals,
        "newton_iterations": fixed.iterations,
        "start_residual": fixed.residuals[0],
        "epsilon_sweep": [{"epsilon": r["epsilon"], "spectral_radius": r["spectral_radius"]} for r in sweep],
        "converged_epsilon": chosen["epsilon"],
        "plateau": chosen,
        "jacobian": jac.tolist(),
        "decay": decay,
        "sampling_phase_drift": phase,
        "template": tmpl,
        "orbit_period": period,
        **({"regression": fitted} if fitted is not None else {}),
        "wall_time_s": time.perf_counter() - wall0,
    }








def run(settings: FloquetSettings, out: Path, client=None) -> dict[str, Any]:
    """Compute on `client` (a LocalCluster when None); write floquet.json, floquet.md, floquet.png into
    `out`, the step map's evaluations kept in `out`/step_map as they finish (a rerun resumes). The record."""
    check_settings(settings, FloquetSettings, "floquet.run")
    from drake_biped.common.executor import client_or_local

    out = Path(out)
    with client_or_local(client) as c:
        record = analyse(settings, c, out / KEPT_EVALUATIONS)
    record.update(config=settings.config.to_dict(), settings=settings.to_dict(), seed=settings.config.seed,
                  versions=versions())
    write_record(out, "floquet", record, markdown, figure)
    return record
