"""The central pattern generator (eq. 2-3) and the torque-free gate, as pure functions.

The CPG phase gamma obeys d(gamma)/dt = u_r + kappa * (stance ankle angular velocity) and its output
zeta = alpha * u_a * sin(gamma) + u_eta is the desired angular velocity of the swing thigh.

Phase resetting (our reading of "the stance and the swing leg are changed by zeta"): gamma is set to 0
at each confirmed touchdown, and held in [0, pi], so one CPG half-cycle drives one swing. This is the
standard CPG reading (Nakanishi et al. 2004, Aoi & Tsuchiya 2005) and it ties the phase to the step.

Each law is a compiled kernel on plain floats (`*_k`, or the function itself where it takes only floats),
which the controller's compiled update calls once per control period; the functions taking a CpgParams are
the same laws for Python callers.
"""

from __future__ import annotations

import math

from drake_biped.jit import njit
from drake_biped.params import CpgParams


@njit
def phase_rate_k(u_r: float, kappa: float, stance_ankle_rate: float) -> float:
    return u_r + kappa * stance_ankle_rate


@njit
def advance_phase_k(u_r: float, kappa: float, gamma: float, stance_ankle_rate: float, dt: float) -> float:
    return min(math.pi, max(0.0, gamma + dt * phase_rate_k(u_r, kappa, stance_ankle_rate)))


@njit
def output_k(alpha: float, u_a: float, u_eta: float, gamma: float) -> float:
    return alpha * u_a * math.sin(gamma) + u_eta


def phase_rate(cpg: CpgParams, stance_ankle_rate: float) -> float:
    """d(gamma)/dt in rad/s (eq. 2)."""
    return phase_rate_k(cpg.u_r, cpg.kappa, stance_ankle_rate)


def advance_phase(cpg: CpgParams, gamma: float, stance_ankle_rate: float, dt: float) -> float:
    """One explicit-Euler step of eq. 2, held in [0, pi] (one half-cycle per step)."""
    return advance_phase_k(cpg.u_r, cpg.kappa, gamma, stance_ankle_rate, dt)


def closed_form_phase(cpg: CpgParams, t: float) -> float:
    """gamma(t) for kappa = 0 from gamma(0) = 0, before clipping at pi: u_r * t."""
    return cpg.u_r * t


def output(cpg: CpgParams, gamma: float) -> float:
    """zeta, the desired swing-thigh angular velocity in rad/s (eq. 3, with alpha and u_eta)."""
    return output_k(cpg.alpha, cpg.u_a, cpg.u_eta, gamma)


@njit
def swing_reference(gamma: float, liftoff_angle: float, target_angle: float) -> float:
    """Desired swing-thigh world angle: the integral of zeta, anchored at lift-off and at the target.

    phi_d = phi_0 + (phi_T - phi_0) * (1 - cos gamma) / 2 runs from the lift-off angle phi_0 at gamma = 0
    to the target phi_T at gamma = pi; its time derivative is (phi_T - phi_0)/2 * sin(gamma) * d(gamma)/dt,
    which equals zeta without feedback when phi_T - phi_0 = 2 * alpha * u_a / u_r. Servoing the angle as
    well as the velocity keeps the swing from drifting (ODE's velocity motor has no such term).
    """
    return liftoff_angle + (target_angle - liftoff_angle) * 0.5 * (1.0 - math.cos(gamma))


# Times since T_n carry rounding noise (0.2 may arrive as 0.19999999999999996): window bounds are compared
# with this tolerance, so that a bound that falls on an update is met exactly there.
WINDOW_TOLERANCE_S = 1e-9


@njit
def torque_free_fraction(elapsed_s: float, period_s: float, start_s: float, end_s: float) -> float:
    """The part of the control period [elapsed_s, elapsed_s + period_s) (times since T_n) that lies in the
    window [start_s, end_s): 0 outside, 1 inside, and in between where an edge cuts the period, so that the
    gate's edges act at their exact times. Overlaps within WINDOW_TOLERANCE_S of 0 or 1 count as 0 or 1."""
    if not end_s > start_s:
        return 0.0
    overlap = min(elapsed_s + period_s, end_s) - max(elapsed_s, start_s)
    if overlap <= WINDOW_TOLERANCE_S:
        return 0.0
    if overlap >= period_s - WINDOW_TOLERANCE_S:
        return 1.0
    return overlap / period_s
