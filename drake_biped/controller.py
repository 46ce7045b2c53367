"""The CPG walking controller as a Drake LeafSystem.

One periodic discrete update per control period does all the work: it advances the CPG phase (eq. 2),
detects touchdown and swaps the legs (resetting the phase), applies the torque-free gate, computes the six
joint torques (swing-hip PID on the CPG reference, torso balance through the stance hip, bang-bang swing
knee, constant stance-knee torque, ankles flat to the ground), and integrates the motor work. The torques
are held in a discrete-state group exported with DeclareStateOutputPort, so the plant reads them without
calling back into Python.

Input port:  "plant_state" (18): MultibodyPlant state q (9), v (9).
Output ports: "actuation" (6): joint torques (N*m), JOINT_NAMES order, applied by the plant.
              "controller_state" (N_STATE): phase, roles, step bookkeeping, work integrals, fall flag.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from drake_biped import cpg, gait
from drake_biped.kinematics import center_of_mass_from_legs, leg_points
from drake_biped.params import EFFORT_LIMITS_NM, EpisodeConfig

# Layout of the "controller_state" discrete group.
GAMMA = 0  # CPG phase (rad)
STANCE_RIGHT = 1  # 1.0 when the right leg is the stance leg
STEP_START = 2  # T_n, time of the last touchdown (s)
LIFTOFF_ANGLE = 3  # swing thigh world angle at T_n (rad)
STEP_COUNT = 4  # touchdowns so far
INTEGRAL = 5  # hip PID integrator (rad*s)
GATE = 6  # 1.0 while the swing hip is torque-free
FALL = 7  # fall code, see FALL_REASONS
COM_X = 8  # whole-body centre of mass x (m)
Q_PREV = 9  # 6 joint angles at the previous update
POSITIVE_WORK = 15  # 6 per-joint integrals of max(tau * omega, 0) dt (J)
SIGNED_WORK = 21  # 6 per-joint integrals of tau * omega dt (J)
N_STATE = 27

FALL_REASONS = {
    0: "",
    1: "hip below the fall height",
    2: "torso tilted beyond the fall angle",
    3: "knee touched the ground",
    4: "non-finite state",
}

_HIP_LIMIT = EFFORT_LIMITS_NM["hip"]
_KNEE_LIMIT = EFFORT_LIMITS_NM["knee"]
_ANKLE_LIMIT = EFFORT_LIMITS_NM["ankle"]


class CpgWalkingController(LeafSystem):
    """CPG + torque-free gate + hip PID + knee/ankle/stance logic for the 7-link biped."""

    def __init__(self, config: EpisodeConfig, initial_stance_right: bool, initial_liftoff_angle: float):
        super().__init__()
        self._config = config
        self._cpg = config.cpg
        self._gait = config.gait
        self._ground = config.ground
        self._window = config.window
        self._dt = config.sim.control_period_s
        self._amplitude = config.cpg.swing_amplitude_rad
        self._fall_height = config.sim.fall_hip_height_m
        self._fall_pitch = config.sim.fall_pitch_rad

        self._plant_state = self.DeclareVectorInputPort("plant_state", 18)
        initial = np.zeros(N_STATE)
        initial[STANCE_RIGHT] = 1.0 if initial_stance_right else 0.0
        initial[LIFTOFF_ANGLE] = initial_liftoff_angle
        self._torque_group = self.DeclareDiscreteState(6)
        self._state_group = self.DeclareDiscreteState(BasicVector(initial))
        self.DeclareStateOutputPort("actuation", self._torque_group)
        self.DeclareStateOutputPort("controller_state", self._state_group)
        self.DeclarePeriodicDiscreteUpdateEvent(self._dt, 0.0, self._update)

    @property
    def state_group(self) -> int:
        return int(self._state_group)

    def set_initial_state(self, context, joint_angles, com_x: float) -> None:
        """Seed the work integrator's previous angles and the centre-of-mass x from the initial state."""
        s = context.get_mutable_discrete_state(self._state_group)
        s.SetAtIndex(COM_X, com_x)
        for i in range(6):
            s.SetAtIndex(Q_PREV + i, float(joint_angles[i]))

    def _update(self, context, discrete_state) -> None:
        t = context.get_time()
        x = self._plant_state.Eval(context).tolist()
        s = context.get_discrete_state(self._state_group).value().tolist()
        tau_prev = context.get_discrete_state(self._torque_group).value().tolist()
        g = self._gait
        q, v = x[:9], x[9:]

        # Work done by the held torques since the last update: tau is constant over the interval,
        # so its work on each joint is exactly tau * (q_now - q_prev).
        for i in range(6):
            w = tau_prev[i] * (q[3 + i] - s[Q_PREV + i])
            s[SIGNED_WORK + i] += w
            if w > 0.0:
                s[POSITIVE_WORK + i] += w
            s[Q_PREV + i] = q[3 + i]

        if not math.isfinite(sum(x)):  # a NaN or an infinity anywhere makes the sum non-finite
            s[FALL] = 4.0
            discrete_state.get_mutable_vector(self._torque_group).SetZero()
            discrete_state.get_mutable_vector(self._state_group).SetFromVector(s)
            return

        px, pz, pitch = q[0], q[1], q[2]
        pitch_rate = v[2]
        left = leg_points(px, pz, pitch, q[3], q[4], q[5])
        right = leg_points(px, pz, pitch, q[6], q[7], q[8])
        stance_right = s[STANCE_RIGHT] > 0.5
        st_i, sw_i = (6, 3) if stance_right else (3, 6)
        stance, swing = (right, left) if stance_right else (left, right)

        # Touchdown: swap the roles and reset the CPG phase (phase resetting).
        time_in_step = t - s[STEP_START]
        ground = self._ground
        clearance = min(swing.heel_z - ground.height(swing.heel_x), swing.toe_z - ground.height(swing.toe_x))
        advance = swing.ankle_x - stance.ankle_x
        if gait.is_touchdown(g, time_in_step, clearance, advance, s[GAMMA]):
            stance_right = not stance_right
            st_i, sw_i = sw_i, st_i
            stance, swing = swing, stance
            s[STANCE_RIGHT] = 1.0 if stance_right else 0.0
            s[STEP_START] = t
            s[LIFTOFF_ANGLE] = swing.thigh_angle
            s[STEP_COUNT] += 1.0
            s[GAMMA] = 0.0
            s[INTEGRAL] = 0.0
            time_in_step = 0.0

        # CPG (eq. 2-3) and the swing reference.
        gamma = cpg.advance_phase(self._cpg, s[GAMMA], v[st_i + 2], self._dt)
        s[GAMMA] = gamma
        zeta = cpg.output(self._cpg, gamma)
        target = gait.placement_target(g, self._amplitude, px - stance.ankle_x, v[0])
        reference = cpg.swing_reference(gamma, s[LIFTOFF_ANGLE], target)
        swing_rate = pitch_rate + v[sw_i]
        angle_error = reference - swing.thigh_angle

        # Torque-free gate: exactly zero swing-hip torque, integrator frozen.
        gated = s[STEP_COUNT] >= self._window.first_step and cpg.in_torque_free_window(
            time_in_step, self._window.start_s, self._window.end_s
        )
        if gated:
            tau_swing_hip = 0.0
        else:
            s[INTEGRAL] += angle_error * self._dt
            tau_swing_hip = gait.clip(
                gait.hip_servo_torque(g, angle_error, zeta - swing_rate, s[INTEGRAL]), _HIP_LIMIT
            )
        s[GATE] = 1.0 if gated else 0.0
        tau_stance_hip = gait.clip(gait.torso_torque(g, pitch, pitch_rate) - tau_swing_hip, _HIP_LIMIT)

        tau_swing_knee = gait.clip(gait.swing_knee_torque(g, gamma, q[sw_i + 1], swing.thigh_angle), _KNEE_LIMIT)
        tau_stance_knee = gait.clip(-g.stance_knee_torque, _KNEE_LIMIT)

        tau = [0.0] * 6
        a_sw, a_st = sw_i - 3, st_i - 3
        tau[a_sw] = tau_swing_hip
        tau[a_st] = tau_stance_hip
        tau[a_sw + 1] = tau_swing_knee
        tau[a_st + 1] = tau_stance_knee
        for leg, i in ((swing, sw_i), (stance, st_i)):
            foot_rate = pitch_rate + v[i] - v[i + 1] + v[i + 2]
            slope = ground.slope_at(leg.ankle_x)
            tau[i - 3 + 2] = gait.clip(gait.ankle_torque(g, leg.foot_angle, foot_rate, slope), _ANKLE_LIMIT)

        # Fall detection (read by the episode monitor).
        if pz - ground.height(px) < self._fall_height:
            s[FALL] = 1.0
        elif abs(pitch) > self._fall_pitch:
            s[FALL] = 2.0
        elif min(left.knee_z - ground.height(left.knee_x), right.knee_z - ground.height(right.knee_x)) < 0.0:
            s[FALL] = 3.0
        s[COM_X] = center_of_mass_from_legs(px, pz, pitch, left, right)[0]

        discrete_state.get_mutable_vector(self._torque_group).SetFromVector(tau)
        discrete_state.get_mutable_vector(self._state_group).SetFromVector(s)
