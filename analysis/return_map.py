"""Linear Poincaré return maps (the paper's Table VI): the least-squares fit from section data, and the
step-to-step Jacobian by finite differences. Plain numpy; nothing here knows about Drake.

The return map linearised about the fixed point x* is x_{n+1} - x* = A (x_n - x*). With the deviations of
consecutive section states as columns of X (x_n) and Y (x_{n+1}), the least-squares A is Y Xᵀ (X Xᵀ)⁻¹
(the paper's formula); it is computed by `numpy.linalg.lstsq` on Xᵀ Aᵀ = Yᵀ, which gives the same A
without forming an inverse. The gait is locally stable when the spectral radius max |λ(A)| is below 1.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from drake_biped.analysis.floquet import check_outputs, difference_jacobian, serial


@dataclass(frozen=True)
class ReturnMapFit:
    """A fitted linear return map. `to_dict()` gives plain JSON types (complex numbers as [re, im])."""

    a_matrix: np.ndarray
    equilibrium: np.ndarray
    eigenvalues: np.ndarray
    spectral_radius: float
    residuals: np.ndarray
    residual_rms: float
    r_squared: float
    n_pairs: int
    n_sequences: int
    spectral_radius_ci: tuple[float, float] | None = None
    ci_level: float | None = None
    bootstrap_samples: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {
            "a_matrix": self.a_matrix.tolist(),
            "equilibrium": self.equilibrium.tolist(),
            "eigenvalues": complex_list(self.eigenvalues),
            "eigenvalue_moduli": np.abs(self.eigenvalues).tolist(),
            "spectral_radius": self.spectral_radius,
            "spectral_radius_ci": None if self.spectral_radius_ci is None else list(self.spectral_radius_ci),
            "ci_level": self.ci_level,
            "bootstrap_samples": self.bootstrap_samples,
            "residual_rms": self.residual_rms,
            "r_squared": self.r_squared,
            "n_pairs": self.n_pairs,
            "n_sequences": self.n_sequences,
            **self.extra,
        }


def complex_list(values: np.ndarray) -> list[list[float]]:
    """Eigenvalues as [[re, im], ...], sorted by decreasing modulus."""
    v = np.asarray(values, dtype=complex)
    order = np.argsort(-np.abs(v), kind="stable")
    return [[float(v[i].real), float(v[i].imag)] for i in order]


def spectral_radius(a_matrix: np.ndarray) -> float:
    return float(np.max(np.abs(np.linalg.eigvals(a_matrix))))


def section_pairs(sequences: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Stack (x_n, x_{n+1}) from each sequence, never across sequences: rows of X and Y, shape (N, d)."""
    if isinstance(sequences, np.ndarray):
        raise TypeError("sequences must be a list of (n_i x d) arrays, one per run")
    xs, ys, dim = [], [], None
    for k, seq in enumerate(sequences):
        s = np.asarray(seq, dtype=float)
        if s.ndim != 2:
            raise ValueError(f"sequence {k} must be a 2-D array (n_i x d), got shape {s.shape}")
        if dim is None:
            dim = s.shape[1]
        elif s.shape[1] != dim:
            raise ValueError(f"sequence {k} has states of dimension {s.shape[1]}, the first has {dim}")
        if not np.all(np.isfinite(s)):
            raise ValueError(f"sequence {k} holds non-finite section states")
        if len(s) >= 2:
            xs.append(s[:-1])
            ys.append(s[1:])
    if dim is None:
        raise ValueError("no sequences given")
    if not xs:
        return np.empty((0, dim)), np.empty((0, dim))
    return np.vstack(xs), np.vstack(ys)


def least_squares_map(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """The matrix A minimising |dy - dx Aᵀ| (rows are pairs of deviations): A = Y Xᵀ (X Xᵀ)⁻¹ without
    forming the inverse."""
    a_t, *_ = np.linalg.lstsq(dx, dy, rcond=None)
    return a_t.T


def fit_return_map(
    sequences: Sequence[np.ndarray],
    equilibrium: np.ndarray | None = None,
    bootstrap: int = 1000,
    ci_level: float = 0.95,
    seed: int = 0,
) -> ReturnMapFit:
    """Fit A in x_{n+1} - x* = A (x_n - x*) to consecutive section states.

    sequences: one (n_i x d) array per run, rows in step order; pairs are formed inside each sequence only.
    equilibrium: x* (default: the mean of every section state given).
    bootstrap: resamples of the pairs (with replacement) for the percentile interval of the spectral radius
    at `ci_level`; 0 skips it. Deterministic for a given `seed`.
    """
    x, y = section_pairs(sequences)
    dim = x.shape[1]
    n = len(x)
    if n < dim + 1:
        raise ValueError(f"fit_return_map needs at least {dim + 1} pairs for a {dim}-D map, got {n}")
    if not 0 < ci_level < 1:
        raise ValueError(f"ci_level must be in (0, 1), got {ci_level}")
    if bootstrap < 0:
        raise ValueError(f"bootstrap must be >= 0, got {bootstrap}")
    if equilibrium is None:
        every = np.vstack([np.asarray(s, dtype=float) for s in sequences])
        x_star = every.mean(axis=0)
    else:
        x_star = np.asarray(equilibrium, dtype=float).reshape(-1)
        if x_star.shape != (dim,) or not np.all(np.isfinite(x_star)):
            raise ValueError(f"equilibrium must be {dim} finite numbers, got {equilibrium!r}")
    dx, dy = x - x_star, y - x_star
    if np.linalg.matrix_rank(dx) < dim:
        raise ValueError("the section states do not span the state space (all deviations on a line): "
                         "the return map is not identifiable; perturb the gait or add runs")
    a = least_squares_map(dx, dy)
    eig = np.linalg.eigvals(a)
    res = dy - dx @ a.T
    total = float(np.sum((dy - dy.mean(axis=0)) ** 2))
    r2 = 1.0 - float(np.sum(res**2)) / total if total > 0 else float("nan")
    ci = None
    if bootstrap:
        rng = np.random.default_rng(seed)
        radii = []
        for _ in range(bootstrap):
            idx = rng.integers(0, n, n)
            if np.linalg.matrix_rank(dx[idx]) < dim:
                continue
            radii.append(spectral_radius(least_squares_map(dx[idx], dy[idx])))
        if radii:
            tail = 100 * (1 - ci_level) / 2
            lo, hi = np.percentile(radii, [tail, 100 - tail])
            ci = (float(lo), float(hi))
    return ReturnMapFit(
        a_matrix=a,
        equilibrium=x_star,
        eigenvalues=eig,
        spectral_radius=float(np.max(np.abs(eig))),
        residuals=res,
        residual_rms=float(np.sqrt(np.mean(res**2))),
        r_squared=r2,
        n_pairs=n,
        n_sequences=sum(1 for s in sequences if len(s) >= 2),
        spectral_radius_ci=ci,
        ci_level=ci_level if ci else None,
        bootstrap_samples=bootstrap if ci else 0,
    )


def step_jacobian(
    step: Callable[[np.ndarray], np.ndarray | None],
    fixed_point: np.ndarray,
    deltas: Sequence[float] | float,
    central: bool = True,
) -> dict[str, Any]:
    """The Jacobian of a step-to-step map at `fixed_point` by finite differences.

    step(x) returns the next section state from section state x (None when the step fails: a fall).
    deltas: the perturbation per coordinate (a number for all). Central differences by default
    (error O(delta²)); forward differences use step(fixed_point) as the base. Returns the Jacobian, its
    eigenvalues and spectral radius, and the map's own residual |step(x*) - x*| (how close x* is to a fixed
    point: the Jacobian describes the return map only near one).
    """
    x0 = np.asarray(fixed_point, dtype=float).reshape(-1)
    dim = len(x0)
    h = np.broadcast_to(np.asarray(deltas, dtype=float), (dim,)).copy()
    if np.any(~np.isfinite(h)) or np.any(h <= 0):
        raise ValueError(f"deltas must be positive, got {deltas!r}")
    evaluate = serial(step)
    (base,) = check_outputs(evaluate([x0]), [x0], dim)  # a failed step raises StepFailed, a RuntimeError
    jac = difference_jacobian(evaluate, x0, h, central=central, base=base)
    eig = np.linalg.eigvals(jac)
    return {
        "jacobian": jac,
        "eigenvalues": eig,
        "spectral_radius": float(np.max(np.abs(eig))),
        "fixed_point": x0,
        "fixed_point_residual": float(np.linalg.norm(base - x0)),
        "deltas": h,
        "central": central,
    }
