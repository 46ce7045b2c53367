"""Leg-role logic: hip servo, torso balance, knees, ankles and touchdown, as pure functions.

These are the laws the controller applies once per control period; each is small enough to test alone.
Each is a compiled kernel on floats (`*_k`), called by the controller's compiled update; the functions
taking a GaitParams are the same laws for Python callers.
"""

from __future__ import annotations

from drake_biped.jit import njit
from drake_biped.params import GaitParams


@njit
def clip(value: float, limit: float) -> float:
    return limit if value > limit else (-limit if value < -limit else value)


@njit
def hip_servo_torque_k(kp: float, kd: float, ki: float, angle_error: float, rate_error: float,
                       integral: float) -> float:
    return kp * angle_error + kd * rate_error + ki * integral


@njit
def torso_torque_k(kp: float, kd: float, reference_pitch: float, pitch: float, pitch_rate: float) -> float:
    return kp * (pitch - reference_pitch) + kd * pitch_rate


@njit
def placement_feedback_k(gain: float, velocity_gain: float, hip_ahead_of_stance_m: float, hip_speed: float) -> float:
    return gain * hip_ahead_of_stance_m + velocity_gain * hip_speed


@njit
def swing_knee_torque_k(knee: tuple, gamma: float, knee_angle: float, thigh_angle: float) -> float:
    """`knee`: (extend_phase, extend_thigh_rad, flex_max_rad, flex_until_phase, flex_torque, extend_torque,
    hold_torque), see knee_law()."""
    extend_phase, extend_thigh, flex_max, flex_until, flex_torque, extend_torque, hold_torque = knee
    if gamma >= extend_phase and thigh_angle >= extend_thigh:
        return -extend_torque
    if knee_angle >= flex_max:
        return -extend_torque
    if gamma < flex_until:
        return flex_torque
    return hold_torque


@njit
def swing_knee_torque_over_k(knee: tuple, start: tuple, end: tuple, iterations: int) -> float:
    first = swing_knee_torque_k(knee, start[0], start[1], start[2])
    last = swing_knee_torque_k(knee, end[0], end[1], end[2])
    if first == last:
        return first
    lo, hi = 0.0, 1.0  # the branch at lo is the first one, at hi it is not
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        if swing_knee_torque_k(knee, start[0] + mid * (end[0] - start[0]), start[1] + mid * (end[1] - start[1]),
                               start[2] + mid * (end[2] - start[2])) == first:
            lo = mid
        else:
            hi = mid
    f = 0.5 * (lo + hi)
    return f * first + (1.0 - f) * last


@njit
def ankle_torque_k(kp: float, kd: float, foot_angle: float, foot_rate: float, ground_angle: float) -> float:
    return -kp * (foot_angle - ground_angle) - kd * foot_rate


@njit
def is_touchdown_k(touchdown: tuple, time_in_step_s: float, swing_clearance_m: float, swing_ankle_advance_m: float,
                   gamma: float) -> bool:
    """`touchdown`: (min_step_s, height_m, min_advance_m, min_phase), see touchdown_rule()."""
    min_step, height, min_advance, min_phase = touchdown
    return (
        time_in_step_s > min_step
        and swing_clearance_m < height
        and swing_ankle_advance_m > min_advance
        and gamma > min_phase
    )


def knee_law(gait: GaitParams) -> tuple[float, ...]:
    """The swing knee's thresholds and torques, in swing_knee_torque_k's order."""
    return tuple(float(v) for v in (gait.knee_extend_phase, gait.knee_extend_thigh_rad, gait.knee_flex_max_rad,
                                    gait.knee_flex_until_phase, gait.knee_flex_torque, gait.knee_extend_torque,
                                    gait.knee_hold_torque))


def touchdown_rule(gait: GaitParams) -> tuple[float, ...]:
    """The touchdown conditions' thresholds, in is_touchdown_k's order."""
    return tuple(float(v) for v in (gait.touchdown_min_step_s, gait.touchdown_height_m, gait.touchdown_min_advance_m,
                                    gait.touchdown_min_phase))


def hip_servo_torque(gait: GaitParams, angle_error: float, rate_error: float, integral: float) -> float:
    """Swing-hip PID on the swing thigh's world angle (before the torque limit)."""
    return hip_servo_torque_k(gait.hip_kp, gait.hip_kd, gait.hip_ki, angle_error, rate_error, integral)


def torso_torque(gait: GaitParams, pitch: float, pitch_rate: float) -> float:
    """Stance-hip torque that holds the torso at gait.torso_pitch_rad.

    A positive hip torque turns the torso clockwise (forward), so a torso leaning back (pitch above the
    reference) asks for a positive torque."""
    return torso_torque_k(gait.torso_kp, gait.torso_kd, gait.torso_pitch_rad, pitch, pitch_rate)


def placement_feedback(gait: GaitParams, hip_ahead_of_stance_m: float, hip_speed: float) -> float:
    """Raibert-style foot-placement feedback (rad): reach further the further ahead and faster the hip is."""
    return placement_feedback_k(gait.placement_gain, gait.placement_velocity_gain, hip_ahead_of_stance_m, hip_speed)


def placement_target(gait: GaitParams, amplitude: float, hip_ahead_of_stance_m: float, hip_speed: float) -> float:
    """End-of-swing thigh angle of the anchored reading: the CPG amplitude plus foot-placement feedback."""
    return amplitude + placement_feedback(gait, hip_ahead_of_stance_m, hip_speed)


def swing_knee_torque(gait: GaitParams, gamma: float, knee_angle: float, thigh_angle: float) -> float:
    """Bang-bang swing knee with a passive middle.

    Extend once the CPG phase has passed knee_extend_phase and the thigh is ahead of
    knee_extend_thigh_rad (the clearance guard); before that, extend whenever the knee is past
    knee_flex_max_rad, flex while the phase is below knee_flex_until_phase, and otherwise apply
    knee_hold_torque (0 by default: the knee swings passively)."""
    return swing_knee_torque_k(knee_law(gait), gamma, knee_angle, thigh_angle)


def swing_knee_torque_over(gait: GaitParams, start: tuple[float, float, float], end: tuple[float, float, float],
                           iterations: int = 20) -> float:
    """The swing knee's torque over a control period along which (phase, knee angle, thigh angle) move
    linearly from `start` to `end`: the bang-bang torque at the start, or, where a switch falls inside the
    period, the two branches blended by the part of the period each holds (the switch's place found by
    bisection), so that a switch acts at its own time rather than at the next update and the torque's
    impulse is continuous in the state. One switch per period is resolved (a control period is far
    shorter than a branch)."""
    return swing_knee_torque_over_k(knee_law(gait), tuple(map(float, start)), tuple(map(float, end)), iterations)


def ankle_torque(gait: GaitParams, foot_angle: float, foot_rate: float, ground_angle: float) -> float:
    """PD that keeps the foot parallel to the local ground."""
    return ankle_torque_k(gait.ankle_kp, gait.ankle_kd, foot_angle, foot_rate, ground_angle)


def is_touchdown(
    gait: GaitParams,
    time_in_step_s: float,
    swing_clearance_m: float,
    swing_ankle_advance_m: float,
    gamma: float,
) -> bool:
    """A confirmed touchdown of the swing foot: all four conditions hold.

    Accepting a touchdown too early (a scuff in mid-swing) swaps the legs with the swing foot behind:
    the minimum step time, the forward advance and the phase threshold rule that out."""
    return bool(is_touchdown_k(touchdown_rule(gait), time_in_step_s, swing_clearance_m, swing_ankle_advance_m, gamma))
