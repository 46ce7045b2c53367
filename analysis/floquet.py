"""The algebra of a periodic orbit's stability: the fixed point of a step map by Newton's method, its
Jacobian by central differences, a sweep of the perturbation that shows where the Jacobian has converged,
the multipliers (Floquet multipliers of the orbit) and their eigenvectors, and the decay of a perturbation
the linearisation predicts. Plain numpy and scipy, on any map given as a function; nothing here knows about
Drake (drake_biped/step_map.py is the biped's map through the simulator).

The maps are evaluated in batches: `evaluate(points) -> outputs` takes a list of states and returns the
next states (None for a step that failed: a fall), so that a caller can run a Jacobian's 2n steps in
parallel. `serial(step)` turns a one-state function into such a batch function.

On a Poincaré section of an autonomous system one multiplier is trivial: a perturbation along the flow only
moves the crossing in time, and the map sends it back onto the section. In section coordinates that keep
every state variable (the section's constraint g(x) = 0 not eliminated), that multiplier is exactly 0 and
its left eigenvector is the section's normal ∇g (g(P(x)) = 0 for every x, so ∇g·DP = 0).

The `floquet` command (drake_biped/experiments/floquet.py) shares this module's name by design: it runs these
computations on the biped's step map; this module is their mathematics.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.linalg

# Newton's default tolerance on the relative residual |P(x) - x| / |x| of the gait's fixed point.
NEWTON_TOLERANCE = 1e-9
# A fixed point counts as found where Newton's residual is within this many times the map's own evaluation
# noise (evaluation_noise), when that is above NEWTON_TOLERANCE: no iterate can be told from the fixed point
# below the noise of the map that defines it.
NOISE_FACTOR = 10.0

Batch = Callable[[Sequence[np.ndarray]], Sequence[np.ndarray | None]]


class StepFailed(RuntimeError):
    """A step of the map failed (the walker fell, or the state left where the map is defined)."""


def serial(step: Callable[[np.ndarray], np.ndarray | None]) -> Batch:
    """A batch evaluator that calls `step` on each state in turn."""
    return lambda points: [step(np.asarray(p, dtype=float)) for p in points]


def check_outputs(outputs: Sequence[np.ndarray | None], points: Sequence[np.ndarray], dim: int) -> list[np.ndarray]:
    out = []
    for x, y in zip(points, outputs):
        if y is None:
            raise StepFailed(f"the step from state {np.asarray(x).tolist()} failed (a fall): use a smaller "
                             "perturbation")
        y = np.asarray(y, dtype=float).reshape(-1)
        if y.shape != (dim,) or not np.all(np.isfinite(y)):
            raise StepFailed(f"the step from {np.asarray(x).tolist()} returned {y.tolist()}, not {dim} finite "
                             "numbers")
        out.append(y)
    return out


def difference_jacobian(evaluate: Batch, x: np.ndarray, epsilon: float | Sequence[float],
                        central: bool = True, base: np.ndarray | None = None) -> np.ndarray:
    """The Jacobian of the map at `x` by finite differences, one batch of 2n (central) or n + 1 (forward,
    or n when `base` = the map at x is given) evaluations. `epsilon`: the perturbation of each coordinate
    (one number for all, or one per coordinate), in the coordinates' own units."""
    x = np.asarray(x, dtype=float).reshape(-1)
    dim = len(x)
    h = np.broadcast_to(np.asarray(epsilon, dtype=float), (dim,)).copy()
    if np.any(~np.isfinite(h)) or np.any(h <= 0):
        raise ValueError(f"epsilon must be positive, got {epsilon!r}")
    steps = np.diag(h)
    if central:
        points = [x + e for e in steps] + [x - e for e in steps]
        y = check_outputs(evaluate(points), points, dim)
        return np.column_stack([(y[j] - y[dim + j]) / (2 * h[j]) for j in range(dim)])
    points = [x + e for e in steps] + ([x] if base is None else [])
    y = check_outputs(evaluate(points), points, dim)
    y0 = np.asarray(base, dtype=float) if base is not None else y[dim]
    return np.column_stack([(y[j] - y0) / h[j] for j in range(dim)])


@dataclass(frozen=True)
class FixedPoint:
    """The result of `newton_fixed_point`: the state, the map there, |P(x) - x| / |x| after each iterate
    (the first is the start's), and the last Jacobian (at the second-to-last iterate)."""

    state: np.ndarray
    image: np.ndarray
    residuals: list[float]
    jacobian: np.ndarray
    iterations: int
    converged: bool

    @property
    def residual(self) -> float:
        return self.residuals[-1]


def relative_residual(x: np.ndarray, y: np.ndarray) -> float:
    """|P(x) - x| relative to |x|."""
    return float(np.linalg.norm(y - x) / max(np.linalg.norm(x), 1e-300))


def newton_fixed_point(evaluate: Batch, x0: np.ndarray, epsilon: float | Sequence[float],
                       tolerance: float = 1e-8, max_iterations: int = 6, max_halvings: int = 4) -> FixedPoint:
    """Solve P(x) = x by Newton's method: J = DP by central differences at each iterate, the step
    (J - I)⁻¹ (x - P(x)) by an LU solve (scipy), halved while it does not reduce the residual. Stops when
    the residual |P(x) - x| / |x| is below `tolerance`, after `max_iterations`, when no halving of the
    step helps (the map's own noise floor), or when a step of the Jacobian's perturbations fails (a fall);
    returns the best iterate, converged or not."""
    x = np.asarray(x0, dtype=float).reshape(-1)
    dim = len(x)
    (y,) = check_outputs(evaluate([x]), [x], dim)
    residuals = [relative_residual(x, y)]
    jac = np.full((dim, dim), np.nan)
    it = 0
    while residuals[-1] > tolerance and it < max_iterations:
        try:
            jac = difference_jacobian(evaluate, x, epsilon)
        except StepFailed:  # a perturbed step fell: the best iterate so far is the answer
            break
        step = scipy.linalg.lu_solve(scipy.linalg.lu_factor(jac - np.eye(dim)), x - y)
        accepted = False
        for _ in range(max_halvings + 1):
            trial = x + step
            try:
                (yt,) = check_outputs(evaluate([trial]), [trial], dim)
            except StepFailed:
                step = 0.5 * step
                continue
            r = relative_residual(trial, yt)
            if r < residuals[-1]:
                x, y, accepted = trial, yt, True
                residuals.append(r)
                break
            step = 0.5 * step
        it += 1
        if not accepted:
            break
    return FixedPoint(state=x, image=y, residuals=residuals, jacobian=jac, iterations=it,
                      converged=residuals[-1] <= tolerance)


def evaluation_noise(evaluate: Batch, x: np.ndarray, scale: float, samples: int = 3, seed: int = 0) -> float:
    """The map's own noise at x on the relative scale `scale`, relative to |x|: the largest half second
    difference |P(x + δ) + P(x - δ) - 2 P(x)| / (2 |x|) over `samples` random directions, |δ| = scale |x|.
    The second difference cancels the map's linear part; a smooth map leaves its curvature, about
    |P''| |δ|² (negligible at small scales), while a map computed through a solver with its own tolerances
    or with events placed on a time grid leaves its noise, whatever the scale. Measured at the scale of
    Newton's last residual, it says how far the map can be trusted there."""
    x = np.asarray(x, dtype=float).reshape(-1)
    rng = np.random.default_rng(seed)
    norm = max(float(np.linalg.norm(x)), 1e-300)
    deltas = [scale * norm * d / np.linalg.norm(d) for d in rng.standard_normal((samples, len(x)))]
    points = [x, *(x + d for d in deltas), *(x - d for d in deltas)]
    images = check_outputs(evaluate(points), points, len(x))
    centre, plus, minus = images[0], images[1:1 + samples], images[1 + samples:]
    return max(float(np.linalg.norm(p + m - 2.0 * centre)) for p, m in zip(plus, minus)) / (2.0 * norm)


def newton_floor(tolerance: float, noise: float | None) -> float:
    """The residual below which Newton has found the fixed point: `tolerance`, or NOISE_FACTOR times the
    map's evaluation noise where that is larger."""
    return max(tolerance, NOISE_FACTOR * noise) if noise is not None else tolerance


def spectral_radius(jacobian: np.ndarray) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(jacobian))))


def epsilon_sweep(evaluate: Batch, x: np.ndarray, epsilons: Sequence[float]) -> list[dict[str, Any]]:
    """The central-difference Jacobian at `x` for each perturbation size: rows {epsilon, spectral_radius,
    jacobian} (spectral_radius None where a perturbed step failed)."""
    rows = []
    for eps in epsilons:
        try:
            jac = difference_jacobian(evaluate, x, float(eps))
        except StepFailed:
            rows.append({"epsilon": float(eps), "spectral_radius": None, "jacobian": None})
            continue
        rows.append({"epsilon": float(eps), "spectral_radius": spectral_radius(jac), "jacobian": jac})
    return rows


def converged_epsilon(sweep: Sequence[dict[str, Any]], tolerance: float = 0.05) -> dict[str, Any]:
    """Where the sweep's Jacobian has converged: the longest run of consecutive perturbation sizes whose
    spectral radius changes by at most `tolerance` (relative) from one size to the next; the chosen ε is
    the run's middle size (its geometric middle for an even run, the larger of the two). Returns the
    chosen epsilon and its row's index, the plateau's bounds and its width in decades, and the largest
    relative change inside it (None values when no two neighbouring sizes agree)."""
    eps = [r["epsilon"] for r in sweep]
    rho = [r["spectral_radius"] for r in sweep]
    order = np.argsort(eps)
    best: tuple[int, int] | None = None
    start = None
    for k in range(len(order) - 1):
        a, b = rho[order[k]], rho[order[k + 1]]
        ok = a is not None and b is not None and abs(b - a) <= tolerance * max(abs(a), abs(b), 1e-300)
        if ok and start is None:
            start = k
        if start is not None and (not ok or k == len(order) - 2):
            end = k + 1 if ok else k
            if best is None or end - start > best[1] - best[0]:
                best = (start, end)
            start = None
    if best is None:
        return {"epsilon": None, "index": None, "plateau": None, "decades": 0.0, "max_change": None}
    run = [int(order[k]) for k in range(best[0], best[1] + 1)]
    mid = run[len(run) // 2]
    changes = [abs(rho[run[i + 1]] - rho[run[i]]) / max(abs(rho[run[i]]), 1e-300) for i in range(len(run) - 1)]
    lo, hi = eps[run[0]], eps[run[-1]]
    return {"epsilon": eps[mid], "index": mid, "plateau": [lo, hi], "decades": float(np.log10(hi / lo)),
            "max_change": float(max(changes))}


@dataclass(frozen=True)
class Multipliers:
    """The eigenvalues of a step map's Jacobian, largest modulus first, with right eigenvectors (columns,
    unit norm, largest component real and positive) and which ones are trivial."""

    values: np.ndarray
    vectors: np.ndarray
    trivial: list[str | None] = field(default_factory=list)

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.values)))

    def nontrivial_radius(self) -> float:
        keep = [abs(v) for v, t in zip(self.values, self.trivial) if t is None]
        return float(max(keep)) if keep else 0.0


def multipliers(jacobian: np.ndarray, section_normal: np.ndarray | None = None,
                alignment: float = 0.5) -> Multipliers:
    """The Jacobian's eigenvalues (largest modulus first) and eigenvectors. With the section's normal ∇g,
    the multiplier whose left eigenvector is most nearly parallel to it (|cos| ≥ `alignment`) is marked
    "section" (the trivial multiplier of a Poincaré section: a shift along the flow)."""
    values, left, right = scipy.linalg.eig(jacobian, left=True, right=True)
    order = np.lexsort((-values.real, -np.abs(values)))
    values, left, right = values[order], left[:, order], right[:, order]
    for k in range(right.shape[1]):
        v = right[:, k]
        i = int(np.argmax(np.abs(v)))
        v = v / np.linalg.norm(v)
        right[:, k] = v * (abs(v[i]) / v[i])
    trivial: list[str | None] = [None] * len(values)
    if section_normal is not None:
        n = np.asarray(section_normal, dtype=float)
        n = n / np.linalg.norm(n)
        cos = np.abs(n @ left) / np.linalg.norm(left, axis=0)
        k = int(np.argmax(cos))
        if cos[k] >= alignment:
            trivial[k] = "section"
    return Multipliers(values=values, vectors=right, trivial=trivial)


def named_components(vector: np.ndarray, names: Sequence[str], count: int = 4) -> list[dict[str, Any]]:
    """The largest components of a (unit) eigenvector, by name: [{name, re, im, magnitude}], largest first."""
    v = np.asarray(vector)
    order = np.argsort(-np.abs(v))[:count]
    return [{"name": names[i], "re": float(v[i].real), "im": float(v[i].imag), "magnitude": float(abs(v[i]))}
            for i in order]


def orbit_verdict(spectral_radius: float, converged_epsilon: float | None, fixed_point_residual: float,
                  tolerance: float, noise: float | None = None) -> str:
    """What multipliers establish: "stable" or "unstable" where Newton reached its floor (`tolerance`, or
    NOISE_FACTOR times the map's evaluation noise `noise` where that is larger; see newton_floor) and the
    perturbation sweep converged; otherwise "not established" and why."""
    if converged_epsilon is None:
        return "not established: the Jacobian did not converge"
    floor = newton_floor(tolerance, noise)
    if fixed_point_residual > floor:
        why = (f"{NOISE_FACTOR:g} x the map's evaluation noise {noise:.1e}" if floor > tolerance
               else "the tolerance")
        return f"not established: Newton stopped at residual {fixed_point_residual:.1e}, above {floor:.1e} ({why})"
    return "stable" if spectral_radius < 1 else "unstable"


def record_verdict(record: dict[str, Any]) -> str:
    """`orbit_verdict` of a Floquet record (floquet.json's), or of a summary holding its spectral_radius,
    converged_epsilon, fixed_point_residual, evaluation_noise (none: the tolerance alone) and newton_tolerance
    (NEWTON_TOLERANCE where it holds neither that nor the record's settings)."""
    default = record.get("newton_tolerance", NEWTON_TOLERANCE)
    tolerance = record.get("settings", {}).get("newton_tolerance", default)
    return orbit_verdict(record["spectral_radius"], record["converged_epsilon"], record["fixed_point_residual"],
                         tolerance, record.get("evaluation_noise"))


def predicted_deviations(jacobian: np.ndarray, delta: np.ndarray, steps: int) -> np.ndarray:
    """J^k δ for k = 1..steps, one row per step: the linearisation's prediction of a perturbation's
    deviation from the fixed point after k steps."""
    out, d = [], np.asarray(delta, dtype=float)
    for _ in range(steps):
        d = jacobian @ d
        out.append(d)
    return np.array(out)


# A map computed through a time-stepping contact simulation is smooth only in pieces: a contact that begins
# or ends one plant step earlier or later moves its image by a jump of its own size, and such pieces can be
# far narrower than any perturbation the Jacobian needs. Its slope at the scale of a walker's disturbances is
# then the least-squares fit of an affine map to many random perturbations of that size, the jumps averaging
# out as noise; the fit's residual is that noise, and resampling the fit (a bootstrap) says how well it fixes
# the multipliers.


@dataclass(frozen=True)
class Regression:
    """The least-squares affine fit of a map near x over random perturbations of one size
    (`regression_jacobian`): P(x + δ) ≈ image + jacobian δ. `noise`: the residuals' root-mean-square length
    relative to |x| (the jumps and curvature the affine map leaves); `radius`: the spectral radius of the
    jacobian (the section's trivial multiplier left out where the section's normal was given); `interval`:
    its bootstrap 5–95 % range; `samples` fitted, `falls` the perturbed steps that failed (left out)."""

    size: float
    jacobian: np.ndarray
    image: np.ndarray
    noise: float
    radius: float
    interval: tuple[float, float]
    samples: int
    falls: int

    def resolved(self, tolerance: float) -> bool:
        """Whether the bootstrap fixes the radius to within `tolerance` (relative) either side."""
        lo, hi = self.interval
        return self.falls == 0 and max(self.radius - lo, hi - self.radius) <= tolerance * max(self.radius, 1e-300)


def _affine_fit(deltas: np.ndarray, images: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    design = np.column_stack([np.ones(len(deltas)), deltas[:, active]])
    coef = np.linalg.lstsq(design, images, rcond=None)[0]
    jac = np.zeros((images.shape[1], len(active)))
    jac[:, active] = coef[1:].T
    return coef[0], jac


def _radius(jacobian: np.ndarray, section_normal: np.ndarray | None) -> float:
    return multipliers(jacobian, section_normal).nontrivial_radius()


def regression_jacobian(evaluate: Batch, x: np.ndarray, scales: Sequence[float], size: float, samples: int,
                        seed: int = 0, section_normal: np.ndarray | None = None,
                        resamples: int = 200) -> Regression:
    """The map's affine fit near `x` from `samples` perturbations δ = size · scales ⊙ g, g standard normal
    (coordinates with scale 0 are not perturbed, and their columns are 0), evaluated in one batch; a failed
    step is left out and counted. The radius's interval comes from `resamples` refits on the samples drawn
    again with replacement (seeded by `seed`, as the perturbations are). StepFailed when fewer samples
    than the fit's unknowns + 2 remain."""
    x = np.asarray(x, dtype=float).reshape(-1)
    dim = len(x)
    scales = np.broadcast_to(np.asarray(scales, dtype=float), (dim,))
    if np.any(~np.isfinite(scales)) or np.any(scales < 0) or not np.any(scales > 0):
        raise ValueError(f"scales must be >= 0, and not all 0: {scales.tolist()}")
    if not (math.isfinite(size) and size > 0):
        raise ValueError(f"size must be positive, got {size!r}")
    active = scales > 0
    if samples < int(active.sum()) + 3:
        raise ValueError(f"samples {samples}: need at least the perturbed coordinates + 3 ({int(active.sum()) + 3})")
    rng = np.random.default_rng(seed)
    deltas = size * scales * rng.standard_normal((samples, dim))
    points = [x + d for d in deltas]
    outputs = evaluate(points)
    kept = [i for i, y in enumerate(outputs)
            if y is not None and np.shape(y) == (dim,) and np.all(np.isfinite(y))]
    if len(kept) < int(active.sum()) + 2:
        raise StepFailed(f"{samples - len(kept)} of {samples} perturbed steps of size {size:g} failed: too few "
                         "left to fit")
    d = deltas[kept]
    y = np.array([np.asarray(outputs[i], dtype=float) for i in kept])
    image, jac = _affine_fit(d, y, active)
    residuals = y - image - d @ jac.T
    norm = max(float(np.linalg.norm(x)), 1e-300)
    noise = float(np.sqrt(np.mean(np.sum(residuals ** 2, axis=1)))) / norm
    radius = _radius(jac, section_normal)
    boot = np.random.default_rng([seed, 1])
    radii = []
    for _ in range(resamples):
        pick = boot.integers(0, len(kept), len(kept))
        radii.append(_radius(_affine_fit(d[pick], y[pick], active)[1], section_normal))
    lo, hi = np.percentile(radii, [5.0, 95.0]) if radii else (radius, radius)
    return Regression(size=float(size), jacobian=jac, image=image, noise=noise, radius=radius,
                      interval=(float(lo), float(hi)), samples=len(kept), falls=samples - len(kept))


def regression_plateau(rows: Sequence[Regression], tolerance: float = 0.05) -> dict[str, Any]:
    """Where the regression's multipliers hold: the longest run of consecutive sizes, each resolved by its
    bootstrap to within `tolerance` and with no fall, whose radii change by at most `tolerance` (relative)
    from one size to the next. Returns the chosen size (the run's middle, as `converged_epsilon` chooses) and
    its index, the plateau's bounds and width in decades; None values where no such run of two exists."""
    order = sorted(range(len(rows)), key=lambda i: rows[i].size)
    best: list[int] = []
    run: list[int] = []
    for i in order:
        r = rows[i]
        if not r.resolved(tolerance):
            run = []
            continue
        if run and abs(r.radius - rows[run[-1]].radius) > tolerance * max(r.radius, rows[run[-1]].radius):
            run = []
        run = run + [i]
        if len(run) > len(best):
            best = run
    if len(best) < 2:
        return {"size": None, "index": None, "plateau": None, "decades": 0.0}
    mid = best[len(best) // 2]
    lo, hi = rows[best[0]].size, rows[best[-1]].size
    return {"size": rows[mid].size, "index": mid, "plateau": [lo, hi], "decades": float(np.log10(hi / lo))}


def affine_fixed_point(fit: Regression, x: np.ndarray) -> np.ndarray:
    """The fixed point of the fitted affine map x + δ ↦ image + J δ: x + (I − J)⁻¹ (image − x)."""
    x = np.asarray(x, dtype=float).reshape(-1)
    return x + np.linalg.solve(np.eye(len(x)) - fit.jacobian, fit.image - x)


MAX_PERIOD = 8


class NoPeriodicOrbit(RuntimeError):
    """The iterates of a map repeat with no period up to the largest looked for: an irregular attractor (or a
    transient longer than the iterations given). `iterates` holds the last ones."""

    def __init__(self, message: str, iterates: np.ndarray):
        super().__init__(message)
        self.iterates = iterates


@dataclass(frozen=True)
class PeriodicOrbit:
    """An orbit of period `period` of a map P: `points` (period x n), points[i + 1] = P(points[i]) and
    P(points[-1]) = points[0]; `multipliers`, the eigenvalues of the k-fold map's Jacobian at points[0]
    (largest modulus first; the same at every point of the orbit); `jacobian` that Jacobian; `residual`
    |P^k(x) - x| / |x| at the orbit; `detected`, the period the iterates showed (None when `period` was given)."""

    period: int
    points: np.ndarray
    multipliers: np.ndarray
    jacobian: np.ndarray
    residual: float
    converged: bool
    detected: int | None

    @property
    def spectral_radius(self) -> float:
        return float(np.max(np.abs(self.multipliers)))

    @property
    def attracting(self) -> bool:
        return self.spectral_radius < 1.0


def repeat_period(iterates: np.ndarray, max_period: int = MAX_PERIOD, tolerance: float = 1e-6) -> int | None:
    """The smallest k <= max_period with |x_j - x_(j-k)| <= tolerance (|x_j| + 1) over the last 2 max_period
    iterates (rows of `iterates`), or None."""
    x = np.asarray(iterates, dtype=float)
    window = 2 * max_period
    if x.ndim != 2 or len(x) < window + max_period:
        raise ValueError(f"repeat_period: need at least {window + max_period} iterates (rows), got {x.shape}")
    tail = x[-(window + max_period):]
    for k in range(1, max_period + 1):
        a, b = tail[k:], tail[:-k]
        a, b = a[-window:], b[-window:]
        if np.all(np.linalg.norm(a - b, axis=1) <= tolerance * (np.linalg.norm(a, axis=1) + 1.0)):
            return k
    return None


def periodic_orbit(step: Callable[[np.ndarray], np.ndarray], x0: np.ndarray, period: int | None = None,
                   max_period: int = MAX_PERIOD, transient: int = 500, detect_tolerance: float = 1e-6,
                   epsilon: float | Sequence[float] = 1e-6, tolerance: float = 1e-10,
                   max_iterations: int = 8) -> PeriodicOrbit:
    """The attracting orbit of the smallest period k <= max_period of the map `step` (a 1-D array to a 1-D
    array) that the iterates from x0 settle on: iterate `transient` times, find the smallest k with which the
    last iterates repeat (`repeat_period`), then Newton on P^k(x) = x from the last iterate (central-difference
    Jacobians of the k-fold map, `epsilon` per coordinate) for the orbit, its points and the multipliers of
    the k-fold map. `period`: skip the detection and look for an orbit of that period (also a repelling one,
    from a start near it). NoPeriodicOrbit when the iterates show no period up to max_period; StepFailed
    when a step fails."""
    x = np.asarray(x0, dtype=float).reshape(-1)
    dim = len(x)

    def one(state: np.ndarray) -> np.ndarray:
        (y,) = check_outputs([step(np.asarray(state, dtype=float))], [state], dim)
        return y

    detected = None
    if period is None:
        iterates = [x]
        for _ in range(max(transient, 3 * max_period)):
            iterates.append(one(iterates[-1]))
        iterates = np.array(iterates)
        detected = repeat_period(iterates, max_period, detect_tolerance)
        if detected is None:
            raise NoPeriodicOrbit(f"the iterates show no period up to {max_period} after {len(iterates) - 1} steps "
                                  "(an irregular attractor, or a longer transient)", iterates[-4 * max_period:])
        period, x = detected, iterates[-1]
    elif not isinstance(period, (int, np.integer)) or period < 1:
        raise ValueError(f"periodic_orbit: period must be an integer >= 1, got {period!r}")

    def k_fold(state: np.ndarray) -> np.ndarray:
        for _ in range(period):
            state = one(state)
        return state

    fixed = newton_fixed_point(serial(k_fold), x, epsilon, tolerance=tolerance, max_iterations=max_iterations)
    start = fixed.state
    jac = difference_jacobian(serial(k_fold), start, epsilon)
    points = [start]
    for _ in range(period - 1):
        points.append(one(points[-1]))
    values = multipliers(jac).values
    return PeriodicOrbit(period=int(period), points=np.array(points), multipliers=values, jacobian=jac,
                         residual=fixed.residual, converged=fixed.converged, detected=detected)
