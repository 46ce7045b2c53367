"""Specific mechanical cost of transport (eq. 1; Collins et al., Science 2005) and the paper's per-kg variant."""

from __future__ import annotations

import math

import numpy as np

GRAVITY_MPS2 = 9.81


def positive_work(torque, angular_velocity, dt: float) -> np.ndarray:
    """Per-joint positive mechanical work (J): sum over samples of max(tau * omega, 0) * dt.

    torque, angular_velocity: arrays (n_samples, n_joints) of torques held over each interval and the
    joint rates over it."""
    power = np.asarray(torque, dtype=float) * np.asarray(angular_velocity, dtype=float)
    return np.sum(np.maximum(power, 0.0), axis=0) * dt


def _check(positive_work_j: float, mass_kg: float, distance_m: float) -> None:
    if not (math.isfinite(positive_work_j) and positive_work_j >= 0):
        raise ValueError(f"positive_work_j must be a finite number >= 0, got {positive_work_j!r}")
    if not (math.isfinite(mass_kg) and mass_kg > 0):
        raise ValueError(f"mass_kg must be positive, got {mass_kg!r}")
    if math.isnan(distance_m):
        raise ValueError("distance_m is NaN")


def cost_of_transport(positive_work_j: float, mass_kg: float, distance_m: float, g: float = GRAVITY_MPS2) -> float:
    """Dimensionless C_mt = E+ / (m g d). Not finite (inf) unless the distance is positive. ValueError naming a
    value no walk gives: positive work that is negative or not finite, a mass or g that is not a positive
    number, a NaN distance."""
    _check(positive_work_j, mass_kg, distance_m)
    if not (math.isfinite(g) and g > 0):
        raise ValueError(f"mass_kg and g must be positive, got {mass_kg!r}, {g!r}")
    if not distance_m > 0:
        return math.inf
    return positive_work_j / (mass_kg * g * distance_m)


def cost_of_transport_per_kg(positive_work_j: float, mass_kg: float, distance_m: float) -> float:
    """The paper's printed eq. 1: E+ / (kg * m), in J/(kg*m) (= g times the dimensionless C_mt)."""
    _check(positive_work_j, mass_kg, distance_m)
    if not distance_m > 0:
        return math.inf
    return positive_work_j / (mass_kg * distance_m)


def cost_decimals(value: float, digits: int = 4) -> int:
    """The decimal places that show `value` to `digits` significant digits in fixed point."""
    if value == 0 or not math.isfinite(value):
        return digits - 1
    return max(0, digits - 1 - math.floor(math.log10(abs(value))))


def format_cost(value: float | None, missing: str = "n/a", digits: int = 4) -> str:
    """A cost of transport (C_mt, or per kg) as printed: `digits` significant digits in fixed point ("0.5566",
    "0.0001234", "12.30"), so a small C_mt that is not zero (a robot far heavier than its motors' work) never
    reads 0.000; None as `missing`."""
    if value is None:
        return missing
    return f"{value:.{cost_decimals(value, digits)}f}"


def format_cost_interval(value: float, half_width: float, digits: int = 4) -> str:
    """`value` ± `half_width`, both to the decimals that show `value` to `digits` significant digits."""
    d = cost_decimals(value, digits)
    return f"{value:.{d}f} ± {half_width:.{d}f}"
