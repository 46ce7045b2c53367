"""The learning reward (eq. 13) with the fall rule: a function of an episode's numbers, nothing else.

r = min(d / D, 1) / C_mt, where C_mt = E+ / (m g d) is the dimensionless cost of transport (as in Table V),
d the distance walked and D the episode's target distance (10 m). A walk that completes gets 1 / C_mt (eq.
13); a fall is scaled down by the fraction of the distance it covered: without that factor a fall after half
a metre, having spent little energy, would out-earn a complete walk. No distance or no work: r = 0.
"""

from __future__ import annotations

import math

__all__ = ["reward"]


def reward(cost_of_transport: float | None, distance_m: float, target_m: float) -> float:
    """The reward of one episode (module docstring)."""
    if cost_of_transport is None or not math.isfinite(cost_of_transport) or cost_of_transport <= 0:
        return 0.0
    if distance_m <= 0 or target_m <= 0:
        return 0.0
    return min(distance_m / target_m, 1.0) / cost_of_transport
