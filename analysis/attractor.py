"""What a walk settles on (pure numpy): a periodic orbit of period k, an irregular attractor, or a fall; and the
largest Lyapunov exponent of a step map, the rate at which nearby walks part.

A walk is read at its touchdowns. Its step periods after the transient tell the attractor: period-k where the
last periods repeat with period k (k <= MAX_PERIOD): every k-th one within `tolerance_s` of the others,
else irregular. The Lyapunov exponent (per step) comes either from the Jacobians of the step
map along the walk (Benettin's method: a tangent vector carried by the product of the Jacobians, renormalised
every step) or from two walks that start a small distance apart (the mean logarithmic rate at which their
sections part, before they saturate).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

MAX_PERIOD = 8
# Step periods repeating to within this (s) over the last PERIOD_WINDOW steps: a periodic attractor.
PERIOD_TOLERANCE_S = 2e-3
PERIOD_WINDOW = 20
# The kick (rad/s on the swing hip's rate) that starts the neighbour walk a Lyapunov exponent is read from
# (`lyapunov_from_neighbours`; the bifurcation command walks it).
NEIGHBOUR_KICK_RADPS = 0.05


def step_period_label(periods_s: Sequence[float], fell: bool = False, window: int = PERIOD_WINDOW,
                      tolerance_s: float = PERIOD_TOLERANCE_S, max_period: int = MAX_PERIOD) -> dict:
    """The attractor a walk's step periods show: {"attractor": "fell" | "period-k" | "irregular" |
    "too short", "period": k or None, "spread_s": the last `window` periods' max - min}. Period-k: the smallest
    k for which, among the last max(window, 3 k) periods, every k-th one (T_j, T_(j+k), T_(j+2k), ...) varies
    by less than tolerance_s, and (k > 1) the k points of the orbit, those sequences' means, lie at least
    tolerance_s apart (period-1: the last `window` periods vary by less than tolerance_s). Without that second
    condition a period-1 walk jittering by a little more than tolerance_s passes for period-k by chance."""
    t = np.asarray(periods_s, dtype=float)
    if fell:
        return {"attractor": "fell", "period": None, "spread_s": None}
    if t.ndim != 1 or len(t) < max(window, 3 * max_period):
        return {"attractor": "too short", "period": None, "spread_s": None}
    last = t[-window:]
    spread = float(last.max() - last.min())
    for k in range(1, max_period + 1):
        tail = t[-max(window, 3 * k):]
        if all(np.ptp(tail[r::k]) < tolerance_s for r in range(k)) and (
                k == 1 or np.ptp([tail[r::k].mean() for r in range(k)]) >= tolerance_s):
            return {"attractor": f"period-{k}", "period": k, "spread_s": spread}
    return {"attractor": "irregular", "period": None, "spread_s": spread}


def lyapunov_from_jacobians(jacobians: Sequence[np.ndarray], discard: int = 0, seed: int = 0) -> float:
    """The largest Lyapunov exponent (per step) of a map from its Jacobians along an orbit, J_0, J_1, ...:
    the mean of log |J_k v_k| with v_(k+1) = J_k v_k / |J_k v_k| (Benettin), from a random unit v_0, the first
    `discard` steps (the vector settling onto the leading direction) left out of the mean."""
    jac = [np.atleast_2d(np.asarray(j, dtype=float)) for j in jacobians]
    if len(jac) <= discard:
        raise ValueError(f"lyapunov_from_jacobians: need more than {discard} Jacobians, got {len(jac)}")
    v = np.random.default_rng(seed).standard_normal(jac[0].shape[1])
    v /= np.linalg.norm(v)
    logs = []
    for j in jac:
        w = j @ v
        n = float(np.linalg.norm(w))
        if n == 0.0 or not math.isfinite(n):
            return -math.inf if n == 0.0 else math.nan
        logs.append(math.log(n))
        v = w / n
    return float(np.mean(logs[discard:]))


def lyapunov_from_neighbours(reference: np.ndarray, neighbour: np.ndarray, saturation: float = 0.1,
                             minimum_steps: int = 3) -> dict:
    """The largest Lyapunov exponent (per step) from two walks' section states (rows, one per touchdown) that
    start a small distance apart: the slope of log |x'_k - x_k| over the steps before their distance first
    reaches `saturation` x the reference's spread (a least-squares line). {"exponent", "steps", "initial",
    "final"}; exponent None when fewer than `minimum_steps` steps are usable (the walks part at once, or
    coincide)."""
    a = np.asarray(reference, dtype=float)
    b = np.asarray(neighbour, dtype=float)
    n = min(len(a), len(b))
    if a.ndim != 2 or b.ndim != 2 or n == 0:
        raise ValueError(f"lyapunov_from_neighbours: expected two (steps, n) arrays, got {a.shape}, {b.shape}")
    d = np.linalg.norm(a[:n] - b[:n], axis=1)
    scale = float(np.linalg.norm(a[:n].max(axis=0) - a[:n].min(axis=0))) or 1.0
    usable = []
    for k in range(n):
        if d[k] <= 0.0:
            continue
        if d[k] >= saturation * scale:
            break
        usable.append(k)
    if len(usable) < minimum_steps:
        return {"exponent": None, "steps": len(usable), "initial": float(d[0]), "final": float(d[n - 1])}
    k = np.array(usable, dtype=float)
    slope = float(np.polyfit(k, np.log(d[usable]), 1)[0])
    return {"exponent": slope, "steps": len(usable), "initial": float(d[0]), "final": float(d[usable[-1]])}
