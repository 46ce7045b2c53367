"""Leg-role logic: hip servo, torso balance, knees, ankles and touchdown, as pure functions.

These are the laws the controller applies once per control period; each is small enough to test alone.
"""

from __future__ import annotations

from drake_biped.params import GaitParams


def clip(value: float, limit: float) -> float:
    return limit if value > limit else (-limit if value < -limit else value)


def hip_servo_torque(
    gait: GaitParams, angle_error: float, rate_error: float, integral: float
) -> float:
    """Swing-hip PID on the swing thigh's world angle (before the torque limit)."""
    return gait.hip_kp * angle_error + gait.hip_kd * rate_error + gait.hip_ki * integral


def torso_torque(gait: GaitParams, pitch: float, pitch_rate: float) -> float:
    """Stance-hip torque that holds the torso at gait.torso_pitch_rad.

    A positive hip torque turns the torso clockwise (forward), so a torso leaning back (pitch above the
    reference) asks for a positive torque."""
    return gait.torso_kp * (pitch - gait.torso_pitch_rad) + gait.torso_kd * pitch_rate


def placement_feedback(gait: GaitParams, hip_ahead_of_stance_m: float, hip_speed: float) -> float:
    """Raibert-style foot-placement feedback (rad): reach further the further ahead and faster the hip is."""
    return gait.placement_gain * hip_ahead_of_stance_m + gait.placement_velocity_gain * hip_speed


def placement_target(gait: GaitParams, amplitude: float, hip_ahead_of_stance_m: float, hip_speed: float) -> float:
    """End-of-swing thigh angle of the anchored reading: the CPG amplitude plus foot-placement feedback."""
    return amplitude + placement_feedback(gait, hip_ahead_of_stance_m, hip_speed)


def swing_knee_torque(gait: GaitParams, gamma: float, knee_angle: float, thigh_angle: float) -> float:
    """Bang-bang swing knee with a passive middle.

    Extend once the CPG phase has passed knee_extend_phase and the thigh is ahead of
    knee_extend_thigh_rad (the clearance guard); before that, extend whenever the knee is past
    knee_flex_max_rad, flex while the phase is below knee_flex_until_phase, and otherwise apply
    knee_hold_torque (0 by default: the knee swings passively)."""
    if gamma >= gait.knee_extend_phase and thigh_angle >= gait.knee_extend_thigh_rad:
        return -gait.knee_extend_torque
    if knee_angle >= gait.knee_flex_max_rad:
        return -gait.knee_extend_torque
    if gamma < gait.knee_flex_until_phase:
        return gait.knee_flex_torque
    return gait.knee_hold_torque


def swing_knee_torque_over(gait: GaitParams, start: tuple[float, float, float], end: tuple[float, float, float],
                           iterations: int = 20) -> float:
    """The swing knee's torque over a control period along which (phase, knee angle, thigh angle) move
    linearly from `start` to `end`: the bang-bang torque at the start, or, where a switch falls inside the
    period, the two branches blended by the part of the period each holds (the switch's place found by
    bisection), so that a switch acts at its own time rather than at the next update and the torque's
    impulse is continuous in the state. One switch per period is resolved (a control period is far
    shorter than a branch)."""
    first = swing_knee_torque(gait, *start)
    last = swing_knee_torque(gait, *end)
    if first == last:
        return first
    lo, hi = 0.0, 1.0  # the branch at lo is the first one, at hi it is not
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        point = [a + mid * (b - a) for a, b in zip(start, end)]
        if swing_knee_torque(gait, *point) == first:
            lo = mid
        else:
            hi = mid
    f = 0.5 * (lo + hi)
    return f * first + (1.0 - f) * last


def ankle_torque(gait: GaitParams, foot_angle: float, foot_rate: float, ground_angle: float) -> float:
    """PD that keeps the foot parallel to the local ground."""
    return -gait.ankle_kp * (foot_angle - ground_angle) - gait.ankle_kd * foot_rate


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
    return (
        time_in_step_s > gait.touchdown_min_step_s
        and swing_clearance_m < gait.touchdown_height_m
        and swing_ankle_advance_m > gait.touchdown_min_advance_m
        and gamma > gait.touchdown_min_phase
    )
