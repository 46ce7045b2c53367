"""The paper's hip motor (GaitParams.hip_drive "motor": zeta the swing hip joint's velocity, reached under an effort
limit, as ODE's joint motor), in its two solves.

- motor_solve "plant": each hip is one of Drake's PD-controlled actuators (proportional gain 0, velocity gain
  GaitParams.motor_gain_nms), which SAP solves in the plant's step together with the contacts and the joint stops.
  `controller.PlantMotors` sets the actuators' gains and effort limits between the plant's steps when the controller's state
  changes them (a role swap, a window's edge).
- motor_solve "controller": the controller computes the motor's torque at each update from a model of the plant
  (`PlantDynamics`: the mass matrix, the stance foot's contact rows, a knee at its stop, gravity and the bias
  term) through `motor_model_k`, solved by Cholesky loops of our own in a fixed order (`constrained_inverse_k`),
  so that a walk gives the same digits on every x86-64 CPU.
"""

from __future__ import annotations

import math

import numpy as np

from drake_biped.control_law import L_INTER_LEG
from drake_biped.jit import njit
from drake_biped.model import LEGS, joint_index

__all__ = ["DYN_SIZE", "MOTOR_NO_TORQUE", "MOTOR_OFF_GAIN", "PlantDynamics", "constrained_inverse_k",
           "motor_coordinate_k", "motor_model_k"]

# How much of what the hip motor's model missed at the last update it adds at the next (a low pass: an impact
# that the model misses for one update does not set the motor ringing).
MOTOR_DISTURBANCE_GAIN = 0.5
# The plant's hip motor (GaitParams.motor_solve "plant") is a PD-controlled actuator on each hip, proportional gain
# 0. Drake fixes which actuators are PD-controlled when the plant first steps, so the hip that is not driven keeps
# its actuator with this negligible velocity gain (its torque is the feedforward to within 1e-12 N*m per rad/s of
# its rate's change over a step; the update counts that part too).
MOTOR_OFF_GAIN = 1e-12
# Drake asks an actuator for a positive effort limit: the least double stands for none (its impulse over a step
# rounds to zero; the controller counts zero).
MOTOR_NO_TORQUE = math.ulp(0.0)

# What the hip motor (GaitParams.hip_drive "motor") reads of the plant's dynamics at each update, computed by
# `CpgWalkingController.motor_dynamics` from the state the update reads: the mass matrix M (9 x 9), the rows
# of the constraints that hold (the stance foot's contact: heel x, heel z, toe z; each knee at its stop), up to
# DYN_ROWS of 9, their number, and f = gravity - bias (9), row-major.
DYN_ROWS = 5
DYN_M, DYN_J, DYN_N, DYN_F = 0, 81, 81 + 9 * DYN_ROWS, 82 + 9 * DYN_ROWS
DYN_SIZE = DYN_F + 9


@njit
def cholesky_k(a, n: int):
    """The lower Cholesky factor L (a = L L^T) of the symmetric positive definite n x n matrix `a`, by the
    Cholesky-Banachiewicz loops in a fixed order: the same rounding on every x86-64 CPU, where a BLAS or LAPACK
    call picks its kernel (and so its order of operations) per CPU."""
    low = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1):
            total = a[i, j]
            for k in range(j):
                total -= low[i, k] * low[j, k]
            if i == j:
                low[i, i] = math.sqrt(total) if total > 0.0 else math.nan
            else:
                low[i, j] = total / low[j, j]
    return low


@njit
def cholesky_solve_k(low, b, n: int) -> None:
    """Solve (L L^T) x = b in place, for the columns of b (n x m), by forward and back substitution in a fixed
    order."""
    for c in range(b.shape[1]):
        for i in range(n):
            total = b[i, c]
            for k in range(i):
                total -= low[i, k] * b[k, c]
            b[i, c] = total / low[i, i]
        for i in range(n - 1, -1, -1):
            total = b[i, c]
            for k in range(i + 1, n):
                total -= low[k, i] * b[k, c]
            b[i, c] = total / low[i, i]


@njit
def constrained_inverse_k(dyn) -> tuple:
    """(P, b) from the plant's dynamics `dyn` (DYN_*): P = M^-1 - M^-1 Jc^T (Jc M^-1 Jc^T)^-1 Jc M^-1, the
    generalized accelerations per unit generalized force with the constraints that hold (the stance foot held
    by its contact, a knee at its stop), and b = P f, the accelerations of gravity and the velocity terms
    alone. Both Gram matrices (M, Jc M^-1 Jc^T) are symmetric positive definite and solved by Cholesky loops of
    our own in a fixed order, with no BLAS call, so that a walk gives the same digits on every x86-64 CPU."""
    n = 9
    m = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            m[i, j] = dyn[DYN_M + n * i + j]
    rows = int(dyn[DYN_N])
    low = cholesky_k(m, n)
    mi = np.zeros((n, n))  # M^-1, column by column
    for i in range(n):
        mi[i, i] = 1.0
    cholesky_solve_k(low, mi, n)
    mi_jt = np.empty((n, rows))  # M^-1 Jc^T
    for c in range(rows):
        for i in range(n):
            mi_jt[i, c] = dyn[DYN_J + n * c + i]
    cholesky_solve_k(low, mi_jt, n)
    gram = np.empty((rows, rows))  # Jc M^-1 Jc^T
    for r in range(rows):
        for c in range(rows):
            total = 0.0
            for k in range(n):
                total += dyn[DYN_J + n * r + k] * mi_jt[k, c]
            gram[r, c] = total
    for r in range(rows):  # symmetric to the last bit, as its factor assumes
        for c in range(r):
            gram[r, c] = gram[c, r] = 0.5 * (gram[r, c] + gram[c, r])
    gram_low = cholesky_k(gram, rows)
    k_t = np.empty((rows, n))  # (Jc M^-1 Jc^T)^-1 Jc M^-1, i.e. the transpose of M^-1 Jc^T (Jc M^-1 Jc^T)^-1
    for r in range(rows):
        for i in range(n):
            k_t[r, i] = mi_jt[i, r]
    cholesky_solve_k(gram_low, k_t, rows)
    p = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            total = mi[i, j]
            for r in range(rows):
                total -= mi_jt[i, r] * k_t[r, j]
            p[i, j] = total
    b = np.empty(n)
    for i in range(n):
        total = 0.0
        for j in range(n):
            total += p[i, j] * dyn[DYN_F + j]
        b[i] = total
    return p, b


@njit
def motor_coordinate_k(law, v, sw_i: int, st_i: int) -> float:
    """The rate the hip motor drives: the swing hip joint's, or the inter-leg angle's (swing minus stance)."""
    return v[sw_i] - v[st_i] if law[L_INTER_LEG] != 0.0 else v[sw_i]


@njit
def motor_model_k(law, dyn, v, dt: float, sw_i: int, st_i: int, others, torso: float) -> tuple:
    """(rate, gain, offset): the model's rate of the motor's coordinate (`motor_coordinate_k`) at the end of
    the update is rate + gain * (swing hip torque - offset), given the other joints' torques `others` (9
    generalized forces, the hips' zero) and the torso's torque law `torso` (the hips' summed torque): the
    stance hip gives torso - swing hip torque (hip_joint "swing"); under "inter_leg" the hips' common mode holds
    the torso and their difference mode (swing - offset, offset = torso / 2) drives the legs apart."""
    p, b = constrained_inverse_k(dyn)
    u = others.copy()
    if law[L_INTER_LEG] != 0.0:
        u[sw_i] += 0.5 * torso
        u[st_i] += 0.5 * torso
        rate = v[sw_i] - v[st_i] + dt * (b[sw_i] - b[st_i])
        for j in range(9):
            rate += dt * (p[sw_i, j] - p[st_i, j]) * u[j]
        return rate, dt * (p[sw_i, sw_i] - p[sw_i, st_i] - p[st_i, sw_i] + p[st_i, st_i]), 0.5 * torso
    u[st_i] += torso
    rate = v[sw_i] + dt * b[sw_i]
    for j in range(9):
        rate += dt * p[sw_i, j] * u[j]
    return rate, dt * (p[sw_i, sw_i] - p[sw_i, st_i]), 0.0


KNEE_STOP_RAD = 1e-3  # a knee within this of full extension (its stop, params.KNEE_LIMIT_RAD[0] = 0) is at it


class PlantDynamics:
    """The plant's dynamics at a state, as the hip motor reads them (DYN_*), through a context of the plant's
    own: the mass matrix, the stance foot's contact rows (its heel's x and z, its toe's z, at the soles'
    lowest points) and gravity minus the bias term."""

    def __init__(self, plant, body: np.ndarray):
        from pydrake.multibody.tree import JacobianWrtVariable

        from drake_biped.kinematics import B_HEEL_SOLE, B_HEEL_X, B_TOE_SOLE, B_TOE_X

        self._plant = plant
        self._context = plant.CreateDefaultContext()
        self._feet = {right: plant.GetBodyByName(f"{'right' if right else 'left'}_foot").body_frame()
                      for right in (False, True)}
        self._points = np.array([[body[B_HEEL_X], 0.0, body[B_HEEL_SOLE]], [body[B_TOE_X], 0.0, body[B_TOE_SOLE]]]).T
        self._kv = JacobianWrtVariable.kV
        self._knees = [3 + joint_index(leg, "knee") for leg in LEGS]

    def fill(self, dyn: np.ndarray, x: np.ndarray, stance_right: bool, torques: np.ndarray) -> None:
        plant, context = self._plant, self._context
        plant.SetPositionsAndVelocities(context, x)
        dyn[DYN_M : DYN_M + 81] = plant.CalcMassMatrix(context).ravel()
        world = plant.world_frame()
        jac = plant.CalcJacobianTranslationalVelocity(context, self._kv, self._feet[stance_right], self._points,
                                                      world, world)
        dyn[DYN_J : DYN_J + 27] = jac[[0, 2, 5]].ravel()  # heel x, heel z, toe z
        rows = 3
        for k in self._knees:  # a knee at its stop with an extending torque held holds there
            if x[k] <= KNEE_STOP_RAD and torques[k - 3] < 0.0:
                dyn[DYN_J + 9 * rows : DYN_J + 9 * rows + 9] = 0.0
                dyn[DYN_J + 9 * rows + k] = 1.0
                rows += 1
        dyn[DYN_N] = rows
        dyn[DYN_F : DYN_F + 9] = plant.CalcGravityGeneralizedForces(context) - plant.CalcBiasTerm(context)
