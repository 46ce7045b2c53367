"""The learning reward (eq. 13) with the fall rule: a function of an episode's numbers, nothing else.

r = min(d / D, 1) / C_mt, where C_mt = E+ / (m g d) is the dimensionless cost of transport (as in Table V),
d the distance walked and D the episode's target distance (10 m). A walk that completes gets 1 / C_mt (eq.
13); a fall is scaled down by the fraction of the distance it covered: without that factor a fall after half
a metre, having spent little energy, would out-earn a complete walk. No distance or no work: r = 0.
"""

from __future__ import annotations

import math
import numbers

__all__ = ["reward"]


def _number(name: str, value: object) -> None:
    # a bool is not a number here: reward(True, ...) once read as C_mt 1
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"reward: {name} must be a number, got {type(value).__name__} {value!r:.60}")


def reward(cost_of_transport: float | None, distance_m: float, target_m: float) -> float:
    """The reward of one episode (module docstring). ValueError naming a value that no episode gives: a C_mt
    that is not a number >= 0, inf or None (NaN, negative: positive work over a distance is never below 0; an
    infinite one, of a walk that covered no distance, rewards 0), a distance that is not a finite number, or a
    target that is not a positive number."""
    if cost_of_transport is not None:
        _number("cost_of_transport", cost_of_transport)
        if math.isnan(cost_of_transport):
            raise ValueError("reward: cost_of_transport is NaN (an episode gives a number, inf or None)")
        if cost_of_transport < 0:
            raise ValueError(f"reward: cost_of_transport must be >= 0 (positive work over a distance), got "
                             f"{cost_of_transport!r}")
    _number("distance_m", distance_m)
    _number("target_m", target_m)
    if not math.isfinite(distance_m):
        raise ValueError(f"reward: distance_m must be finite, got {distance_m!r}")
    if not (math.isfinite(target_m) and target_m > 0):
        raise ValueError(f"reward: target_m must be a positive number, got {target_m!r}")
    if cost_of_transport is None or not math.isfinite(cost_of_transport) or cost_of_transport <= 0:
        return 0.0
    if distance_m <= 0:
        return 0.0
    return min(distance_m / target_m, 1.0) / cost_of_transport
