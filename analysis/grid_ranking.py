"""How a grid orders its walks (pure Python): further first, to the centimetre, then cheaper (lower C_mt; a
walk without a C_mt after every one with one). `better` picks a grid's best point; `rank` places any walk among
the grid's, such as Table III's own beside Table IV's cell centres.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["better", "order_key", "rank"]


def order_key(row: dict[str, Any]) -> tuple[float, float]:
    """The key a grid sorts its walks by, ascending: a row with "distance_m" and "cost_of_transport"."""
    cost = row["cost_of_transport"]
    return -round(row["distance_m"], 2), math.inf if cost is None else cost


def better(a: dict[str, Any], b: dict[str, Any] | None) -> bool:
    """Whether row a beats row b: further (to the centimetre), then lower C_mt."""
    return b is None or order_key(a) < order_key(b)


def rank(row: dict[str, Any], rows: list[dict[str, Any]]) -> int:
    """Where `row` stands among `rows`: 1 + the number of rows that beat it (ties share a rank)."""
    key = order_key(row)
    return 1 + sum(order_key(r) < key for r in rows)
