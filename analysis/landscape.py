"""What GARB climbs: the expected reward of a Gaussian policy over torque-free windows.

GARB is a stochastic gradient ascent on J(T̄) = E[r(t)], t ~ N(T̄, σ² I): the reward landscape r(t1, t2)
smoothed by the policy's own exploration. Where the windows that save energy form a region narrower than σ,
or lie next to windows that fall, J can be highest with no window at all even though single windows save
a lot; the learner then converges, correctly, to no window. This module estimates J from measured episodes
(a window map) so that a choice of σ² and start can be checked before thousands of episodes are spent.

The reward of a sampled t follows the learning run exactly (`drake_biped.analysis.reward`, times below 0
act as 0, t2 <= t1 means no window); a window between grid points takes the reward of the nearest measured
window (the map's spacing bounds the resolution). Plain numpy and scipy.

The `landscape` command (drake_biped/experiments/landscape.py) shares this module's name by design: it reads a
window map and writes what this module computes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.spatial import cKDTree

from drake_biped.analysis.reward import reward


class WindowRewards:
    """r(t1, t2) from measured windows: nearest measured window, the no-window reward where t2 <= t1."""

    def __init__(self, windows: np.ndarray, rewards: np.ndarray, no_window_reward: float):
        self.windows = np.asarray(windows, dtype=float).reshape(-1, 2)
        self.rewards = np.asarray(rewards, dtype=float).reshape(-1)
        if len(self.windows) == 0 or len(self.windows) != len(self.rewards):
            raise ValueError("need one reward per measured window, and at least one window")
        if not (np.all(np.isfinite(self.rewards)) and np.isfinite(no_window_reward)):
            raise ValueError("rewards must be finite")
        self.no_window_reward = float(no_window_reward)
        self._tree = cKDTree(self.windows)

    @classmethod
    def from_window_map(cls, record: dict[str, Any]) -> WindowRewards:
        """From a `window_map.json` record (drake-biped window-map)."""
        target = record["config"]["sim"]["distance_m"]
        base = record["baseline"]
        rows = record["windows"]
        windows = np.array([[r["t1"], r["t2"]] for r in rows])
        rewards = np.array([reward(r["cost_of_transport"], r["distance_m"], target) for r in rows])
        return cls(windows, rewards, reward(base["cost_of_transport"], base["distance_m"], target))

    def __call__(self, t: np.ndarray) -> np.ndarray:
        t = np.maximum(np.asarray(t, dtype=float).reshape(-1, 2), 0.0)
        out = np.full(len(t), self.no_window_reward)
        has = t[:, 1] > t[:, 0]
        if np.any(has):
            out[has] = self.rewards[self._tree.query(t[has])[1]]
        return out


def expected_reward(rewards: WindowRewards, means: np.ndarray, variance: float, samples: int = 4000,
                    seed: int = 0) -> np.ndarray:
    """J(T̄) for each row of `means`, by Monte Carlo with the same draws for every mean."""
    if not (np.isfinite(variance) and variance > 0):
        raise ValueError(f"variance must be > 0, got {variance!r}")
    if samples < 1:
        raise ValueError(f"samples must be >= 1, got {samples!r}")
    means = np.asarray(means, dtype=float).reshape(-1, 2)
    z = np.sqrt(variance) * np.random.default_rng(seed).standard_normal((samples, 2))
    return np.array([rewards(m + z).mean() for m in means])


def landscape(rewards: WindowRewards, variances: Sequence[float], t1_range=(0.0, 0.8), t2_range=(0.0, 1.0),
              step: float = 0.025, samples: int = 2000, seed: int = 0,
              starts: Sequence[Sequence[float]] = ((0.5, 0.5),)) -> dict[str, Any]:
    """J over a grid of policy means for each variance: its maximum, and J at the given start means,
    each also relative to the no-window reward."""
    t1s = np.arange(t1_range[0], t1_range[1] + 1e-9, step)
    t2s = np.arange(t2_range[0], t2_range[1] + 1e-9, step)
    grid = np.array([[a, b] for b in t2s for a in t1s])
    base = rewards.no_window_reward
    out: dict[str, Any] = {"t1": t1s.tolist(), "t2": t2s.tolist(), "no_window_reward": base, "variances": []}
    for var in variances:
        j = expected_reward(rewards, grid, var, samples, seed)
        k = int(np.argmax(j))
        at = expected_reward(rewards, np.asarray(starts, dtype=float), var, samples, seed)
        out["variances"].append({
            "variance": float(var),
            "expected_reward": j.reshape(len(t2s), len(t1s)).tolist(),
            "best_mean": grid[k].tolist(),
            "best_expected_reward": float(j[k]),
            "best_gain": float(j[k] / base - 1.0) if base > 0 else None,
            "reward_at_best_mean": float(rewards(grid[k])[0]),
            "starts": [{"mean": list(map(float, s)), "expected_reward": float(v),
                        "gain": float(v / base - 1.0) if base > 0 else None} for s, v in zip(starts, at)],
        })
    return out
