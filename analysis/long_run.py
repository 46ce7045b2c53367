"""Long-run measures of a walk (pure numpy): the cost of transport after the initiation's transient, with a
95 % interval from batch means over steps, and the statistics of the step periods.

A walk is read at its touchdowns: each has a time, the centre of mass x and the motors' positive work so far.
The steps whose touchdown lies less than `transient_m` beyond the first touchdown are the initiation's
transient and are dropped; the long-run C_mt is the positive work of the remaining whole steps over m g times
the distance they cover (the ratio of sums, so a long step weighs as much as it walks). Its interval: the steps
are cut into `batches` consecutive batches, each batch's own C_mt taken, and Student's t on their mean (batch
means: the steps of an irregular gait are correlated, batches of many steps much less).
"""

from __future__ import annotations

import math

import numpy as np

# The initiation's transient (m beyond the first touchdown) and the span a long-run figure needs beyond it.
TRANSIENT_M = 10.0
LONG_RUN_M = 100.0
BATCHES = 10
# Student's t, two-sided 95 %, for batches - 1 degrees of freedom (scipy.stats.t.ppf(0.975, df)).
_T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228,
         11: 2.201, 12: 2.179, 13: 2.160, 14: 2.145, 15: 2.131, 16: 2.120, 17: 2.110, 18: 2.101, 19: 2.093}


def has_long_run(distance_m: float, transient_m: float = TRANSIENT_M) -> bool:
    """Whether a walk of `distance_m` is long enough for a long-run mean: the transient and LONG_RUN_M beyond it."""
    return distance_m >= transient_m + LONG_RUN_M - 1e-9


def measure_text(distance_m: float, transient_m: float = TRANSIENT_M) -> str:
    """What the C_mt of walks of `distance_m` is, in words, as a report states it: the long-run mean after the
    transient where the walks are long enough (`has_long_run`), else the whole walk's."""
    if has_long_run(distance_m, transient_m):
        return f"{distance_m:g} m walks, C_mt the long-run mean after the first {transient_m:g} m"
    return (f"{distance_m:g} m walks, C_mt over the whole walk (a long-run mean needs "
            f"{transient_m + LONG_RUN_M:g} m)")


def t975(df: int) -> float:
    """The two-sided 95 % quantile of Student's t with `df` degrees of freedom (1.96 beyond 19)."""
    return _T975.get(int(df), 1.96)


def long_run_cost(times_s, com_x_m, positive_work_j, mass_kg: float, g: float,
                  transient_m: float = TRANSIENT_M, batches: int = BATCHES) -> dict:
    """The long-run C_mt of a walk from its touchdowns (arrays of equal length: time, centre-of-mass x,
    cumulative positive work), with its 95 % interval and the kept steps' period statistics.

    Returns a dict: cost_of_transport (None when fewer than 2 x batches whole steps follow the transient),
    interval_95 ([lo, hi]), half_width, steps (whole steps used), dropped_steps (touchdowns in the
    transient), distance_m (covered by the steps used), transient_m, batches, batch_costs, and
    step_period_mean_s / _std_s / _min_s / _max_s over the steps used."""
    t = np.asarray(times_s, dtype=float)
    x = np.asarray(com_x_m, dtype=float)
    w = np.asarray(positive_work_j, dtype=float)
    if not (t.shape == x.shape == w.shape and t.ndim == 1):
        raise ValueError(f"long_run_cost: times, com_x and work must be 1-D arrays of one length, got {t.shape}, "
                         f"{x.shape}, {w.shape}")
    if not (mass_kg > 0 and g > 0):
        raise ValueError(f"long_run_cost: mass_kg and g must be positive, got {mass_kg!r}, {g!r}")
    if not isinstance(batches, (int, np.integer)) or batches < 2:
        raise ValueError(f"long_run_cost: batches must be an integer >= 2, got {batches!r}")
    out = {"cost_of_transport": None, "interval_95": None, "half_width": None, "steps": 0,
           "dropped_steps": int(t.size), "distance_m": 0.0, "transient_m": float(transient_m),
           "batches": int(batches), "batch_costs": [], "step_period_mean_s": None, "step_period_std_s": None,
           "step_period_min_s": None, "step_period_max_s": None}
    if t.size == 0:
        return out
    first = int(np.searchsorted(x - x[0], transient_m, side="left"))  # x grows along a walk
    kept = slice(first, None)
    t, x, w = t[kept], x[kept], w[kept]
    out["dropped_steps"] = first
    n = t.size - 1
    if n < 1:
        return out
    periods = np.diff(t)
    out.update(steps=int(n), distance_m=float(x[-1] - x[0]), step_period_mean_s=float(periods.mean()),
               step_period_std_s=float(periods.std(ddof=1)) if n > 1 else 0.0,
               step_period_min_s=float(periods.min()), step_period_max_s=float(periods.max()))
    if n < 2 * batches or not x[-1] > x[0]:
        return out
    weight = mass_kg * g
    cost = float((w[-1] - w[0]) / (weight * (x[-1] - x[0])))
    edges = np.linspace(0, n, batches + 1).round().astype(int)
    batch_costs = np.array([(w[b] - w[a]) / (weight * (x[b] - x[a])) for a, b in zip(edges[:-1], edges[1:])])
    half = float(t975(batches - 1) * batch_costs.std(ddof=1) / math.sqrt(batches))
    out.update(cost_of_transport=cost, interval_95=[cost - half, cost + half], half_width=half,
               batch_costs=batch_costs.tolist())
    return out


def long_run_of_record(result: dict, g: float, transient_m: float = TRANSIENT_M, batches: int = BATCHES) -> dict:
    """long_run_cost of an episode's record (a result.json's dict: its "steps" and "mass_kg"); a step recorded
    without its work (a record from before touchdowns counted it) gives no long-run cost."""
    steps = result["steps"]
    work = [math.nan if s.get("positive_work_j") is None else s["positive_work_j"] for s in steps]
    out = long_run_cost([s["touchdown_time_s"] for s in steps], [s["com_x_m"] for s in steps], work,
                        result["mass_kg"], g, transient_m, batches)
    if out["cost_of_transport"] is not None and not math.isfinite(out["cost_of_transport"]):
        out.update(cost_of_transport=None, interval_95=None, half_width=None, batch_costs=[])
    return out
