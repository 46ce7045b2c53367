"""The CPG walking controller's update, compiled: the state it advances and `control_step`, which advances it.

One periodic discrete update per control period (controller.CpgWalkingController, a Drake LeafSystem) does all the work: it advances the CPG phase (eq. 2),
detects touchdown and swaps the legs (resetting the phase), applies the torque-free gate, computes the six
joint torques (swing-hip PID on the CPG reference, torso balance through the stance hip, bang-bang swing
knee, constant stance-knee torque, ankles flat to the ground), integrates the motor work, records each
touchdown's Poincare section state, and ends the episode (an EventStatus the Simulator obeys) on a fall or
when the centre of mass has walked the distance. The torques are held in a discrete-state group exported
with DeclareStateOutputPort, so the plant reads them at its own rate without calling back into Python.

Input port:  "plant_state" (18): MultibodyPlant state q (9), v (9).
Output ports: "actuation" (6): joint torques (N*m), JOINT_NAMES order, applied by the plant (where the plant
              solves the hip motor, GaitParams.motor_solve "plant", the hips' feedforward: their PD-controlled
              actuators add the motor's torque).
              "controller_state" (CONTROLLER_STATE): phase, roles, step bookkeeping, work integrals, fall flag.
              "motor_command" (MOTOR_COMMAND_SIZE): the desired state of the plant's actuated joints, of which
              the hip motors read their rates (connected only where the plant solves the motor).
Discrete groups: actuation (6), controller state (CONTROLLER_STATE), touchdowns (capacity x TOUCHDOWN), motor
command (MOTOR_COMMAND_SIZE).
Both layouts are declared once below; outside the update, read them by name (`CONTROLLER_STATE.view`).

Timing: the plant's output ports are sampled (Drake's default for a discrete plant), so the state the
update at context time t reads is the plant state at t + h, h the plant time step, and the torques it
computes act from t + h on: state feedback without delay. The touchdown times and STATE_TIME are the
times of the states read, which are also the time stamps the state log gives those states.

Events at sub-step accuracy, so that the step map, C_mt and the reward are continuous in the state and in
the window's bounds (benchmarks/kick_sweep.py measures it): a touchdown is placed at the instant T_n the
swing foot's clearance crossed the touchdown height, interpolated between two updates; the step clock, the
CPG phase and the torque-free window all count from T_n; the section angle is interpolated to T_n and the
section rate extrapolated to T_n from the two updates before it (before the impact, which a 1 ms update
would otherwise sample at a random depth); and a control period that a window edge cuts applies the
servo's torque scaled by the part of the period outside the window; a switch of the swing knee's
bang-bang torque that falls inside a period (its condition crossed along the state extrapolated over the
period) blends the two torques by the part of the period each holds; and the roles' torques swap at the
crossing itself: where the clearance, extrapolated over the coming period, crosses the touchdown height
inside it, that period's torques blend the present roles' and the new roles' by the part of the period
each holds (GaitParams.swap_timing "predicted"; "update" swaps them at the update that sees the crossing).
tests/test_hot_path.py and tests/test_gait.py pin this down.

The update's arithmetic is one compiled kernel (`control_step`, numba): Python only hands it the plant state,
the update's own state vector (written in place) and the episode's numbers, a numeric parameter of the
context packed once per episode (`LAW`, `law_vector`, `set_episode`), and turns its return code into the touchdown row and the EventStatus. An episode that records
nothing calls the kernel itself between the plant's steps, on this system's state in the same context
(episode._step_directly), with the same numbers.
"""

from __future__ import annotations

import math

import numpy as np

from drake_biped.control_law import (  # the episode's numbers, as the kernel reads them
    L_ALPHA,
    L_AMPLITUDE,
    L_ANKLE_KD,
    L_ANKLE_KP,
    L_DT,
    L_ENTRAINED,
    L_FALL_HEIGHT,
    L_FALL_PITCH,
    L_FIRST_STEP,
    L_HIP_KD,
    L_HIP_KI,
    L_HIP_KP,
    L_INTEGRATED,
    L_KAPPA,
    L_KNEE,
    L_LAG,
    L_LEVEL,
    L_MOTOR,
    L_MOTOR_GAIN,
    L_MOTOR_LIMIT,
    L_MOTOR_PLANT,
    L_MOTOR_TAU,
    L_OFFSET,
    L_PLACE,
    L_PLACE_V,
    L_PREDICTED,
    L_SLOPE,
    L_STANCE_KNEE,
    L_T1,
    L_T2,
    L_TAN,
    L_TORSO_KD,
    L_TORSO_KP,
    L_TORSO_PITCH,
    L_TOUCHDOWN,
    L_UA,
    L_UETA,
    L_UR,
)
from drake_biped.cpg import advance_phase_k, output_k, phase_rate_k, swing_reference, torque_free_fraction
from drake_biped.gait import (
    ankle_torque_k,
    clip,
    hip_servo_torque_k,
    is_touchdown_k,
    placement_feedback_k,
    swing_knee_torque_over_k,
    torso_torque_k,
)
from drake_biped.hip_motor import (
    MOTOR_DISTURBANCE_GAIN,
    MOTOR_OFF_GAIN,
    motor_coordinate_k,
    motor_model_k,
)
from drake_biped.jit import njit
from drake_biped.kinematics import (
    B_ANKLE_EFFORT,
    B_HIP_EFFORT,
    B_KNEE_EFFORT,
    center_of_mass_k,
    leg_points_k,
)
from drake_biped.layout import Field, VectorLayout
from drake_biped.model import JOINTS_OF_A_LEG, LEGS, joint_index
from drake_biped.params import (
    EpisodeConfig,
)

# The "controller_state" discrete group, declared once; the update below uses the offsets generated here.
CONTROLLER_STATE = VectorLayout("controller_state", (
    Field("cpg_phase", 1, "CPG phase gamma (rad)"),
    Field("stance_right", 1, "1.0 when the right leg is the stance leg (its hip balances the torso)"),
    Field("contact_right", 1, "1.0 when the right foot landed last (the stance leg under phase_reading 'reset')"),
    Field("step_start_s", 1, "T_n, the last touchdown: when the swing foot's clearance crossed the touchdown "
                             "height, interpolated within the control period (plant-state time, s)"),
    Field("liftoff_angle_rad", 1, "swing thigh world angle at T_n (rad)"),
    Field("step_count", 1, "touchdowns so far"),
    Field("hip_integral", 1, "swing-hip PID integrator (rad*s)"),
    Field("torque_free", 1, "the part of the control period the swing hip is torque-free (1.0: all of it)"),
    Field("fall_code", 1, "why the episode fell, a key of FALL_REASONS (0: it did not)"),
    Field("com_x_m", 1, "whole-body centre of mass x at the last update (m)"),
    Field("target_x_m", 1, "the episode ends when com_x_m reaches this (m)"),
    Field("done", 1, "1.0 once the distance is walked"),
    Field("state_time_s", 1, "time of the plant state read by the last update (s)"),
    Field("previous_joint_angles_rad", 6, "joint angles at the previous update, JOINT_NAMES order (rad)"),
    Field("torques_nm", 6, "torques held since the previous update, a copy of the actuation group (N*m)"),
    Field("positive_work_j", 6, "per-joint integrals of max(tau * omega, 0) dt (J)"),
    Field("signed_work_j", 6, "per-joint integrals of tau * omega dt (J)"),
    Field("previous_clearance_m", 1, "the swing foot's clearance at the previous update (m)"),
    Field("previous_pitch_rad", 1, "torso pitch at the previous update (rad)"),
    Field("previous_section_rates_radps", 2, "swing minus stance hip rate at the previous two updates, latest "
                                             "first; NaN until read in this step (rad/s)"),
    Field("swing_travel_rad", 1, "integral of zeta since T_n: the swing thigh's travel under the integrated "
                                 "reading (rad)"),
    Field("torque_reversals", 1, "updates at which a joint's torque jumped by more than REVERSAL_FACTOR times its "
                                 "motor's limit from the previous control period (a diverging control loop)"),
    Field("recent_reversals_s", 5, "the times of the last DIVERGED_REVERSALS reversals, latest first (-inf: none)"),
    Field("motor_model_rate_radps", 1, "the hip motor's coordinate rate its model expects at this update, from the "
                                       "last (NaN: none since the roles last swapped)"),
    Field("motor_disturbance_radps", 1, "what that model missed at the last update: the rate measured minus it"),
    Field("hip_motor_gain_nms", 2, "the plant's hip motors (motor_solve 'plant'), left and right: each hip "
                                   "actuator's velocity gain over the coming period (MOTOR_OFF_GAIN: a plain torque)"),
    Field("hip_motor_target_radps", 2, "the hip joint rate each motor drives to over the coming period (rad/s)"),
    Field("hip_motor_bound_nm", 2, "each hip actuator's torque bound over the coming period, its motor's "
                                   "feedforward included (0: no torque)"),
    Field("positive_work_by_role_j", 6, "integrals of max(tau * omega, 0) dt by the joint's role over each period, "
                                        "model.ROLES order (J)"),
    Field("negative_work_by_role_j", 6, "integrals of min(tau * omega, 0) dt by role, model.ROLES order (J)"),
))
N_STATE = CONTROLLER_STATE.size
_o = CONTROLLER_STATE.offset
GAMMA, STANCE_RIGHT, STEP_START, LIFTOFF_ANGLE = _o("cpg_phase"), _o("stance_right"), _o("step_start_s"), \
    _o("liftoff_angle_rad")
CONTACT_RIGHT = _o("contact_right")
STEP_COUNT, INTEGRAL, GATE, FALL = _o("step_count"), _o("hip_integral"), _o("torque_free"), _o("fall_code")
COM_X, TARGET_X, DONE, STATE_TIME = _o("com_x_m"), _o("target_x_m"), _o("done"), _o("state_time_s")
Q_PREV, TAU = _o("previous_joint_angles_rad"), _o("torques_nm")
POSITIVE_WORK, SIGNED_WORK, PREV_CLEARANCE = _o("positive_work_j"), _o("signed_work_j"), _o("previous_clearance_m")
PREV_PITCH, PREV_RATES, TRAVEL = _o("previous_pitch_rad"), _o("previous_section_rates_radps"), _o("swing_travel_rad")
REVERSALS, RECENT_REVERSALS = _o("torque_reversals"), _o("recent_reversals_s")
MOTOR_MODEL_RATE, MOTOR_DISTURBANCE = _o("motor_model_rate_radps"), _o("motor_disturbance_radps")
MOTOR_GAIN, MOTOR_TARGET, MOTOR_BOUND = _o("hip_motor_gain_nms"), _o("hip_motor_target_radps"), _o("hip_motor_bound_nm")
ROLE_POSITIVE, ROLE_NEGATIVE = _o("positive_work_by_role_j"), _o("negative_work_by_role_j")
del _o

# One row of the "touchdowns" group per touchdown, written once, at the update that detects it.
TOUCHDOWN = VectorLayout("touchdown", (
    Field("time_s", 1, "when the swing foot's clearance crossed the touchdown height (s)"),
    Field("hip_angle_rad", 1, "section state: new stance thigh minus new swing thigh (rad)"),
    Field("hip_rate_radps", 1, "its rate (rad/s)"),
    Field("stance_right", 1, "1.0 when the new stance leg is the right one"),
    Field("com_x_m", 1, "centre of mass x (m)"),
    Field("positive_work_j", 1, "the motors' positive work since the start, all joints (J)"),
))
TOUCHDOWN_FIELDS = TOUCHDOWN.names
_TD = TOUCHDOWN_ROW = TOUCHDOWN.size  # the touchdown group's row length
MAX_TOUCHDOWNS = 4096

# Indices of the legs' joints: in the plant's positions and velocities (the planar base's 3 come first) and
# in the actuation and torque vectors; a leg's knee and ankle follow its hip.
Q_HIP = {leg: 3 + joint_index(leg, "hip") for leg in LEGS}
Q_HIP_LEFT, Q_HIP_RIGHT = Q_HIP["left"], Q_HIP["right"]
KNEE, ANKLE = JOINTS_OF_A_LEG.index("knee"), JOINTS_OF_A_LEG.index("ankle")

FALL_REASONS = {
    0: "",
    1: "hip below the fall height",
    2: "torso tilted beyond the fall angle",
    3: "knee touched the ground",
    4: "non-finite state",
    5: "the control loop diverged",
}
# A diverging control loop (a control period too long for the servos' gains: the torques chatter between their
# limits) is told from a walk by the rate of torque reversals: a joint's torque jumping by more than
# REVERSAL_FACTOR times its motor's limit from one period to the next. A chattering loop reverses at nearly every
# period; an impact or a push makes one reversal, rarely two, and a long walk may gather a few over hundreds of
# steps. So the episode ends as diverged when DIVERGED_REVERSALS reversals fall within DIVERGENCE_SPAN_PERIODS
# control periods (20 ms at 1 ms): a rate, not a total.
REVERSAL_FACTOR = 1.5
DIVERGED_REVERSALS = 5
DIVERGENCE_SPAN_PERIODS = 20
DIVERGED_CODE = 5
# The motor's command: the desired state of the plant's actuated joints (q_d, then v_d, in actuator order); only
# the hips' desired rates are read (the motors have no proportional gain, the other joints no PD).
MOTOR_COMMAND_SIZE = 12


def touchdown_capacity(config: EpisodeConfig) -> int:
    """Rows reserved for touchdowns: enough for the whole episode at the shortest accepted step."""
    shortest = max(config.gait.touchdown_min_step_s, config.sim.update_period_s)
    return min(MAX_TOUCHDOWNS, int(math.ceil(config.sim.max_time_s / shortest)) + 1)



# The kernel's return code: bits for what the Python side must do after it.
TOUCHED, FELL, DONE_BIT = 1, 2, 4
MOTORS = 8  # the plant's hip motors take other gains or bounds from this update on (CpgWalkingController.apply_motors)

# Leg points tuple (kinematics.leg_points_k): the slots the update reads.
_KNEE_X, _KNEE_Z, _ANKLE_X, _HEEL_X, _HEEL_Z, _TOE_X, _TOE_Z, _THIGH, _FOOT, _HIP_X, _HIP_Z = 0, 1, 2, 4, 5, 6, 7, 8, 10, \
    11, 12


@njit
def legs_k(right_stance: bool, left: tuple, right: tuple) -> tuple:
    """(stance hip's index, swing hip's index in q and v, stance leg's points, swing leg's points) when the
    right leg is the stance leg or not."""
    if right_stance:
        return Q_HIP_RIGHT, Q_HIP_LEFT, right, left
    return Q_HIP_LEFT, Q_HIP_RIGHT, left, right


@njit
def ground_height_k(law, x: float) -> float:
    """params.Ground.height() from the LAW vector."""
    level = law[L_LEVEL]
    if level != level:  # NaN: the slope everywhere
        return x * law[L_TAN]
    return max(0.0, (x - level) * law[L_TAN])


@njit
def ground_slope_k(law, x: float) -> float:
    """params.Ground.slope_at() from the LAW vector."""
    level = law[L_LEVEL]
    if level != level or x >= level:
        return law[L_SLOPE]
    return 0.0


@njit
def predicted_touchdown_k(law, s, now: float, clearance: float, c_prev: float, advance: float,
                          stance_ankle_rate: float) -> float:
    """The part of the coming control period before the swing foot's clearance, extrapolated linearly
    from this update and the previous one, crosses the touchdown height, when the touchdown would be
    confirmed at the period's end; -1 when no touchdown is predicted in it."""
    rule = (law[L_TOUCHDOWN], law[L_TOUCHDOWN + 1], law[L_TOUCHDOWN + 2], law[L_TOUCHDOWN + 3])
    thr = rule[1]
    if not (math.isfinite(c_prev) and clearance > thr):
        return -1.0
    c_end = 2.0 * clearance - c_prev
    if c_end >= thr:
        return -1.0
    dt = law[L_DT]
    gamma_end = advance_phase_k(law[L_UR], law[L_KAPPA], s[GAMMA], stance_ankle_rate, dt)
    if not is_touchdown_k(rule, now + dt - s[STEP_START], c_end, advance, gamma_end):
        return -1.0
    return (clearance - thr) / (clearance - c_end)


@njit
def realized_hip_torques_k(s, v, tau) -> None:
    """The plant's hip motors (motor_solve "plant"): the torque each hip's actuator applied over the period
    that just ended, into s[TAU + hip], as the plant's step computed it (Drake's PD-controlled actuator at the
    step's end rate: -gain (rate - target) + feedforward, clipped to the bound); `tau`: the feedforward held."""
    for leg in range(2):
        j = 3 * leg  # the hip's torque index (JOINT_NAMES: a leg's hip first)
        bound = s[MOTOR_BOUND + leg]
        u = -s[MOTOR_GAIN + leg] * (v[Q_HIP_LEFT + j] - s[MOTOR_TARGET + leg]) + tau[j]
        s[TAU + j] = 0.0 if bound <= 0.0 else clip(u, bound)


@njit
def period_torques_k(law, body, s, q, v, now: float, stance_right: bool, stance: tuple, swing: tuple,
                     dyn) -> None:
    """The six torques over the period [now, now + dt) for the given roles, into s[TAU:], advancing
    the CPG phase, the swing travel, the hip integrator and the gate in s."""
    dt = law[L_DT]
    if stance_right:
        st_i, sw_i = Q_HIP_RIGHT, Q_HIP_LEFT
    else:
        st_i, sw_i = Q_HIP_LEFT, Q_HIP_RIGHT
    pitch, pitch_rate = q[2], v[2]
    hip_ahead = stance[_HIP_X] - stance[_ANKLE_X]  # the hip joint ahead of the stance ankle
    # This update's torques act over [now, now + dt): `elapsed` after T_n at its start.
    elapsed = now - s[STEP_START]

    # CPG (eq. 2-3) and the swing reference.
    gamma = advance_phase_k(law[L_UR], law[L_KAPPA], s[GAMMA], v[st_i + ANKLE], dt)
    zeta = output_k(law[L_ALPHA], law[L_UA], law[L_UETA], gamma)
    s[GAMMA] = gamma
    s[TRAVEL] += dt * zeta
    if law[L_INTEGRATED] != 0.0:
        # Table III's zeta drives the swing as printed: the reference angle is its integral from the
        # lift-off angle; placement feedback only adds an offset, blended in over the half-cycle.
        offset = law[L_OFFSET] + placement_feedback_k(law[L_PLACE], law[L_PLACE_V], hip_ahead, v[0])
        reference = s[LIFTOFF_ANGLE] + s[TRAVEL] + offset * 0.5 * (1.0 - math.cos(gamma))
    else:
        target = law[L_AMPLITUDE] + placement_feedback_k(law[L_PLACE], law[L_PLACE_V], hip_ahead, v[0])
        reference = swing_reference(gamma, s[LIFTOFF_ANGLE], target)
    swing_rate = pitch_rate + v[sw_i]
    angle_error = reference - swing[_THIGH]

    # Torque-free gate: the servo's torque scaled by the part of the period outside the window (exactly
    # zero for a period inside it), the integrator advanced by that part only.
    free = 0.0
    if s[STEP_COUNT] >= law[L_FIRST_STEP]:
        free = torque_free_fraction(elapsed, dt, law[L_T1], law[L_T2])
    s[GATE] = free
    a_sw, a_st = TAU + sw_i - 3, TAU + st_i - 3  # the legs' hip torques (the knee and ankle follow)
    # the swing knee's switches placed inside the period, along the state extrapolated over it
    knee = (law[L_KNEE], law[L_KNEE + 1], law[L_KNEE + 2], law[L_KNEE + 3], law[L_KNEE + 4], law[L_KNEE + 5],
            law[L_KNEE + 6])
    knee_start = (gamma, q[sw_i + KNEE], swing[_THIGH])
    knee_end = (advance_phase_k(law[L_UR], law[L_KAPPA], gamma, v[st_i + ANKLE], dt), q[sw_i + KNEE] + dt * v[sw_i + KNEE],
                swing[_THIGH] + dt * swing_rate)
    knee_limit = body[B_KNEE_EFFORT]
    s[a_sw + KNEE] = clip(swing_knee_torque_over_k(knee, knee_start, knee_end, 20), knee_limit)
    s[a_st + KNEE] = clip(-law[L_STANCE_KNEE], knee_limit)
    ankle_limit = body[B_ANKLE_EFFORT]
    for leg, i, a in ((swing, sw_i, a_sw), (stance, st_i, a_st)):
        foot_rate = pitch_rate + v[i] - v[i + KNEE] + v[i + ANKLE]
        slope = ground_slope_k(law, leg[_ANKLE_X])
        s[a + ANKLE] = clip(ankle_torque_k(law[L_ANKLE_KP], law[L_ANKLE_KD], leg[_FOOT], foot_rate, slope),
                            ankle_limit)

    # The hips: the swing hip drives the swing (servo or motor), gated; the stance hip holds the torso.
    hip_limit = body[B_HIP_EFFORT]
    torso = torso_torque_k(law[L_TORSO_KP], law[L_TORSO_KD], law[L_TORSO_PITCH], pitch, pitch_rate)
    if law[L_MOTOR_PLANT] != 0.0:
        # The plant's motor: the swing hip's actuator drives its joint's rate to zeta inside the plant's step,
        # bounded by the motor's limit times the part of the period outside the window (0 inside it); the
        # stance hip's actuator is a plain torque, the torso's law less the torque the swing hip's actuator
        # applied over the last period (s[a_sw] holds it: `realized_hip_torques_k`).
        sw_leg, st_leg = (sw_i - Q_HIP_LEFT) // 3, (st_i - Q_HIP_LEFT) // 3
        reaction = s[a_sw]
        s[a_sw] = 0.0
        s[MOTOR_GAIN + sw_leg] = law[L_MOTOR_GAIN]
        s[MOTOR_TARGET + sw_leg] = zeta
        s[MOTOR_BOUND + sw_leg] = (1.0 - free) * min(law[L_MOTOR_LIMIT], hip_limit)
        s[MOTOR_GAIN + st_leg] = MOTOR_OFF_GAIN
        s[MOTOR_TARGET + st_leg] = v[st_i]
        s[MOTOR_BOUND + st_leg] = hip_limit
        s[a_st] = clip(torso - reaction, hip_limit)
        return
    if law[L_MOTOR] != 0.0:
        # ODE's motor: the torque that brings the coordinate's rate to zeta by the update's end, from the
        # plant's dynamics and what the last update's model missed (the disturbance: the joint limits' and the
        # other contacts' forces, the contact's compliance), clipped to the motor's limit; the model's rate of
        # the torque applied is kept for the next update to measure the disturbance by.
        others = np.zeros(9)
        for i in range(6):
            if i % 3 != 0:  # knees and ankles, set above
                others[3 + i] = s[TAU + i]
        rate, gain, offset = motor_model_k(law, dyn, v, dt, sw_i, st_i, others, torso)
        drive = 0.0
        if gain > 0.0:
            # the part of the rate's miss this update closes: all of it (ODE's motor at its step), or dt / T of it
            # (a motor of time constant T, whose loop does not stiffen as the step shrinks)
            part = 1.0 if law[L_MOTOR_TAU] <= dt else dt / law[L_MOTOR_TAU]
            drive = clip(part * (zeta - rate - s[MOTOR_DISTURBANCE]) / gain, law[L_MOTOR_LIMIT])
        tau_swing_hip = 0.0 if free >= 1.0 else (1.0 - free) * clip(offset + drive, hip_limit)
        s[MOTOR_MODEL_RATE] = rate + gain * (tau_swing_hip - offset)
    elif free >= 1.0:
        tau_swing_hip = 0.0
    else:
        s[INTEGRAL] += angle_error * dt * (1.0 - free)
        tau_swing_hip = (1.0 - free) * clip(
            hip_servo_torque_k(law[L_HIP_KP], law[L_HIP_KD], law[L_HIP_KI], angle_error, zeta - swing_rate,
                               s[INTEGRAL]), hip_limit)
    s[a_sw] = tau_swing_hip
    s[a_st] = clip(torso - tau_swing_hip, hip_limit)


@njit
def control_step(law, body, t: float, x, s, tau, row, dyn, command) -> int:
    """One control update at context time t: reads the plant state x (q, v), advances the controller state
    s (CONTROLLER_STATE) in place and writes the torques for the coming period into tau (6). Returns a
    code of TOUCHED (a touchdown was confirmed: `row` holds its index and its TOUCHDOWN fields), FELL,
    DONE_BIT and MOTORS. `dyn`: the plant's dynamics at x (DYN_*) where the controller solves the hip motor, else unread;
    `command`: the plant's motor command (MOTOR_COMMAND_SIZE), written where the plant solves it."""
    dt = law[L_DT]
    now = t + law[L_LAG]  # the time of the plant state read (see "Timing")
    s[STATE_TIME] = now
    q, v = x[:9], x[9:]
    q_prev = s[Q_PREV : Q_PREV + 6].copy()
    pitch_prev = s[PREV_PITCH]
    code = 0

    # Work done by the held torques since the last update: tau is constant over the interval,
    # so its work on each joint is exactly tau * (q_now - q_prev). The plant's motors: the torque they applied.
    held_gains = (s[MOTOR_GAIN], s[MOTOR_GAIN + 1])
    held_bounds = (s[MOTOR_BOUND], s[MOTOR_BOUND + 1])
    if law[L_MOTOR_PLANT] != 0.0:
        realized_hip_torques_k(s, v, tau)
    total = 0.0
    for i in range(18):
        total += x[i]
    # The work by role (model.ROLES): each period for the roles the legs held when it began (a period the roles swap
    # inside counts for the roles before the swap).
    held_right = s[STANCE_RIGHT] > 0.5
    for i in range(6):
        w = s[TAU + i] * (q[3 + i] - q_prev[i])
        s[SIGNED_WORK + i] += w
        role = 2 * (i % 3) + (1 if (i >= 3) == held_right else 0)  # ROLES: swing, then stance, of each joint
        if w > 0.0:
            s[POSITIVE_WORK + i] += w
            s[ROLE_POSITIVE + role] += w
        else:
            s[ROLE_NEGATIVE + role] += w
        s[Q_PREV + i] = q[3 + i]

    if not math.isfinite(total):  # a NaN or an infinity anywhere makes the sum non-finite
        s[FALL] = 4.0
        for i in range(6):
            s[TAU + i] = 0.0
            tau[i] = 0.0
        return FELL

    px, pz, pitch = q[0], q[1], q[2]
    pitch_rate = v[2]
    s[PREV_PITCH] = pitch
    left = leg_points_k(body, px, pz, pitch, q[3], q[4], q[5])
    right = leg_points_k(body, px, pz, pitch, q[6], q[7], q[8])
    entrained = law[L_ENTRAINED] != 0.0
    stance_right = s[STANCE_RIGHT] > 0.5
    st_i, sw_i, stance, swing = legs_k(stance_right, left, right)
    # The legs by contact (the foot that landed last, and the other): the same as the roles but under the
    # entrained phase reading, where the phase swaps the roles and a touchdown only marks T_n.
    contact_right = s[CONTACT_RIGHT] > 0.5
    cst_i, csw_i, c_stance, c_swing = legs_k(contact_right, left, right)
    if law[L_MOTOR] != 0.0 and s[MOTOR_MODEL_RATE] == s[MOTOR_MODEL_RATE]:  # the motor's model, measured
        missed = motor_coordinate_k(law, v, sw_i, st_i) - s[MOTOR_MODEL_RATE]
        s[MOTOR_DISTURBANCE] += MOTOR_DISTURBANCE_GAIN * (missed - s[MOTOR_DISTURBANCE])
    com_x = center_of_mass_k(body, px, pz, pitch, left, right)[0]
    s[COM_X] = com_x

    # Touchdown: record the section state and start the step's clock; under the reset reading, swap the
    # roles and reset the CPG phase too (phase resetting).
    clearance = min(c_swing[_HEEL_Z] - ground_height_k(law, c_swing[_HEEL_X]),
                    c_swing[_TOE_Z] - ground_height_k(law, c_swing[_TOE_X]))
    advance = c_swing[_ANKLE_X] - c_stance[_ANKLE_X]
    c_prev = s[PREV_CLEARANCE]
    s[PREV_CLEARANCE] = clearance
    rate_1, rate_2 = s[PREV_RATES], s[PREV_RATES + 1]
    s[PREV_RATES + 1] = rate_1
    s[PREV_RATES] = v[csw_i] - v[cst_i]  # the section rate, were the swing foot to land now
    rule = (law[L_TOUCHDOWN], law[L_TOUCHDOWN + 1], law[L_TOUCHDOWN + 2], law[L_TOUCHDOWN + 3])
    touched = is_touchdown_k(rule, now - s[STEP_START], clearance, advance, s[GAMMA])
    if touched:
        contact_right = not contact_right
        cst_i, csw_i = csw_i, cst_i
        c_stance, c_swing = c_swing, c_stance
        # T_n: the moment the clearance crossed the touchdown height, linearly between this update and
        # the previous one, when the crossing is what confirmed the touchdown (otherwise this update).
        back = 0.0
        thr = rule[1]
        crossed = math.isfinite(c_prev) and c_prev > thr >= clearance
        if crossed:
            back = (1.0 - (c_prev - thr) / (c_prev - clearance)) * dt
        f = back / dt  # how far back towards the previous update T_n lies
        angle = (1.0 - f) * (q[cst_i] - q[csw_i]) + f * (q_prev[cst_i - 3] - q_prev[csw_i - 3])
        if crossed and math.isfinite(rate_2):
            # both rates were read before the foot reached the ground: extrapolate them to T_n
            rate = rate_1 + (rate_1 - rate_2) * (1.0 - f)
        else:
            rate = v[cst_i] - v[csw_i]
        step_start = now - back
        n = s[STEP_COUNT]
        row[0] = n
        row[1] = step_start
        row[2] = angle
        row[3] = rate
        row[4] = 1.0 if contact_right else 0.0
        row[5] = com_x
        row[6] = 0.0
        for i in range(6):
            row[6] += s[POSITIVE_WORK + i]
        code |= TOUCHED
        s[CONTACT_RIGHT] = 1.0 if contact_right else 0.0
        s[STEP_START] = step_start
        s[STEP_COUNT] = n + 1.0
        s[PREV_CLEARANCE] = math.inf  # the next swing foot's clearance is not yet known
        s[PREV_RATES] = math.nan
        s[PREV_RATES + 1] = math.nan
        if not entrained:
            stance_right = contact_right
            st_i, sw_i = cst_i, csw_i
            stance, swing = c_stance, c_swing
            s[STANCE_RIGHT] = 1.0 if stance_right else 0.0
            # the new swing thigh's world angle at T_n
            s[LIFTOFF_ANGLE] = (1.0 - f) * swing[_THIGH] + f * (pitch_prev + q_prev[sw_i - 3])
            s[GAMMA] = advance_phase_k(law[L_UR], law[L_KAPPA], 0.0, v[st_i + ANKLE], back)  # the phase since T_n
            s[INTEGRAL] = 0.0
            s[TRAVEL] = back * output_k(law[L_ALPHA], law[L_UA], law[L_UETA], 0.5 * s[GAMMA])
            s[MOTOR_MODEL_RATE] = math.nan  # the motor drives the other legs' coordinate from here
            s[MOTOR_DISTURBANCE] = 0.0

    # A touchdown predicted inside the coming period (the clearance extrapolated over it crosses the
    # touchdown height) swaps the roles at its own time: the period's torques blend the present roles'
    # and the new roles' by the part of the period each holds, so the swap's impulse is continuous in
    # the state. The swap itself is recorded at the next update, from the crossing it then sees.
    # Under the entrained reading the roles swap where the phase crosses pi inside the coming period, with
    # the same blend; the new half-cycle's phase runs on from there, and the state is the new roles' at once.
    swap = -1.0
    crossing = False
    if entrained:
        rate = phase_rate_k(law[L_UR], law[L_KAPPA], v[st_i + ANKLE])
        if rate > 0.0 and s[GAMMA] + dt * rate >= math.pi:
            swap = (math.pi - s[GAMMA]) / (dt * rate)
            crossing = True
    elif not touched and law[L_PREDICTED] != 0.0:
        swap = predicted_touchdown_k(law, s, now, clearance, c_prev, advance, v[st_i + ANKLE])
    if swap >= 0.0:
        new = s.copy()
        new[STANCE_RIGHT] = 0.0 if stance_right else 1.0
        new[LIFTOFF_ANGLE] = stance[_THIGH] + swap * dt * (pitch_rate + v[st_i])
        if not crossing:
            new[STEP_START] = now + swap * dt
            new[STEP_COUNT] = s[STEP_COUNT] + 1.0
        # the phase and the travel from T_n: negative now, so that after the period they are the part of
        # it after T_n
        new[GAMMA] = -swap * dt * phase_rate_k(law[L_UR], law[L_KAPPA], v[sw_i + ANKLE])
        new[TRAVEL] = -swap * dt * output_k(law[L_ALPHA], law[L_UA], law[L_UETA], 0.0)
        new[INTEGRAL] = 0.0
        new[MOTOR_DISTURBANCE] = 0.0
        period_torques_k(law, body, new, q, v, now, not stance_right, swing, stance, dyn)
    period_torques_k(law, body, s, q, v, now, stance_right, stance, swing, dyn)
    if swap >= 0.0:
        for i in range(TAU, TAU + 6):
            s[i] = swap * s[i] + (1.0 - swap) * new[i]
        for i in range(MOTOR_GAIN, MOTOR_BOUND + 2):  # the plant's motors too: each hip's by its part
            s[i] = swap * s[i] + (1.0 - swap) * new[i]
        if crossing:
            for i in range(N_STATE):
                if (i < TAU or i >= TAU + 6) and (i < MOTOR_GAIN or i >= MOTOR_BOUND + 2):
                    s[i] = new[i]

    # Fall detection and the end of the episode.
    if left[_HIP_Z] - ground_height_k(law, left[_HIP_X]) < law[L_FALL_HEIGHT]:  # the hip joint's height
        s[FALL] = 1.0
    elif abs(pitch) > law[L_FALL_PITCH]:
        s[FALL] = 2.0
    elif min(left[_KNEE_Z] - ground_height_k(law, left[_KNEE_X]),
             right[_KNEE_Z] - ground_height_k(law, right[_KNEE_X])) < 0.0:
        s[FALL] = 3.0
    if com_x >= s[TARGET_X]:
        s[DONE] = 1.0
    reversed_ = False
    for i in range(6):
        limit = body[B_HIP_EFFORT] if i % 3 == 0 else (body[B_KNEE_EFFORT] if i % 3 == 1 else body[B_ANKLE_EFFORT])
        if abs(s[TAU + i] - tau[i]) > REVERSAL_FACTOR * limit:
            reversed_ = True
        tau[i] = s[TAU + i]
    if law[L_MOTOR_PLANT] != 0.0:
        for leg in range(2):
            command[MOTOR_COMMAND_SIZE // 2 + 3 * leg] = s[MOTOR_TARGET + leg]
            if s[MOTOR_GAIN + leg] != held_gains[leg] or s[MOTOR_BOUND + leg] != held_bounds[leg]:
                code |= MOTORS
    if reversed_:  # one reversal per update, however many joints jumped
        s[REVERSALS] += 1.0
        for j in range(DIVERGED_REVERSALS - 1, 0, -1):
            s[RECENT_REVERSALS + j] = s[RECENT_REVERSALS + j - 1]
        s[RECENT_REVERSALS] = now
    oldest = s[RECENT_REVERSALS + DIVERGED_REVERSALS - 1]
    if s[FALL] == 0.0 and now - oldest < (DIVERGENCE_SPAN_PERIODS - 0.5) * dt:
        s[FALL] = 5.0
    if s[FALL] != 0.0:
        code |= FELL
    if s[DONE] != 0.0:
        code |= DONE_BIT
    return code
