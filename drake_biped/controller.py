"""The CPG walking controller as a Drake LeafSystem: `CpgWalkingController`.

Its one periodic discrete update hands the plant state, its own state and the episode's numbers to the compiled
update (`control_kernel.control_step`, whose docstring says what the update does and when), then turns the
update's return code into a touchdown row, the plant motors' new gains (`PlantMotors`) and the
EventStatus that ends an episode. The episode's numbers are a numeric parameter of its Context (`control_law.LAW`),
so one built system serves every episode of its structure.

Input port:  "plant_state" (18): MultibodyPlant state q (9), v (9).
Output ports: "actuation" (6): joint torques (N*m), JOINT_NAMES order, applied by the plant (where the plant
              solves the hip motor, GaitParams.motor_solve "plant", the hips' feedforward: their PD-controlled
              actuators add the motor's torque).
              "controller_state" (control_kernel.CONTROLLER_STATE): phase, roles, step bookkeeping, work
              integrals, fall flag.
              "motor_command" (MOTOR_COMMAND_SIZE): the desired state of the plant's actuated joints, of which
              the hip motors read their rates (connected only where the plant solves the motor).
Discrete groups: actuation (6), controller state (CONTROLLER_STATE), touchdowns (capacity x TOUCHDOWN), motor
command (MOTOR_COMMAND_SIZE). The torques are held in a discrete-state group exported with
DeclareStateOutputPort, so the plant reads them at its own rate without calling back into Python.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector, EventStatus, LeafSystem

from drake_biped.control_kernel import (
    COM_X,
    CONTACT_RIGHT,
    CONTROLLER_STATE,
    DIVERGED_REVERSALS,
    DONE_BIT,
    FALL,
    FALL_REASONS,
    FELL,
    GAMMA,
    LIFTOFF_ANGLE,
    MOTOR_BOUND,
    MOTOR_COMMAND_SIZE,
    MOTOR_GAIN,
    MOTOR_MODEL_RATE,
    MOTORS,
    N_STATE,
    PREV_CLEARANCE,
    PREV_PITCH,
    PREV_RATES,
    Q_PREV,
    RECENT_REVERSALS,
    STANCE_RIGHT,
    STEP_COUNT,
    TARGET_X,
    TAU,
    TOUCHED,
    control_step,
    touchdown_capacity,
)
from drake_biped.control_kernel import (
    TOUCHDOWN_ROW as _TD,
)
from drake_biped.control_law import L_MOTOR, L_MOTOR_PLANT, LAW, LAW_COPIED
from drake_biped.hip_motor import DYN_SIZE, MOTOR_NO_TORQUE, MOTOR_OFF_GAIN, PlantDynamics
from drake_biped.kinematics import B_HIP_EFFORT, BODY, TABLE_I_BODY
from drake_biped.model import LEGS
from drake_biped.params import EpisodeConfig


def law_vector(config: EpisodeConfig) -> np.ndarray:
    """The LAW vector of an episode's configuration: the derived slots, then every LAW_COPIED field."""
    g, c, ground, sim = config.gait, config.cpg, config.ground, config.sim
    v = np.zeros(LAW.size)

    def put(name: str, value) -> None:
        v[LAW.offset(name)] = value

    for section, name, slot in LAW_COPIED:
        value = getattr(getattr(config, section), name)
        put(slot, math.nan if value is None else value)
    put("update_period_s", sim.update_period_s)
    put("state_lag_s", sim.time_step_s)
    put("swing_amplitude_rad", c.swing_amplitude_rad)
    put("integrated", 1.0 if g.swing_reading == "integrated" else 0.0)
    put("predicted_swap", 1.0 if g.swap_timing == "predicted" else 0.0)
    put("entrained", 1.0 if g.phase_reading == "entrained" else 0.0)
    if g.phase_reading == "entrained":  # the phase does not follow the steps: no phase condition
        put("touchdown_min_phase", -math.inf)
    put("ground_tan_slope", math.tan(ground.slope_rad))
    put("hip_motor", 1.0 if g.hip_drive == "motor" else 0.0)
    put("inter_leg", 1.0 if g.hip_joint == "inter_leg" else 0.0)
    put("motor_plant", 1.0 if config.gait.plant_motor else 0.0)
    return v


class PlantMotors:
    """The plant's hip actuators as the plant's hip motor drives them (motor_solve "plant"): their velocity gains
    and effort limits, set between the plant's steps whenever the controller's state changes them. Drake reads
    an actuator's gains and limit at each step, from the plant's model, not from a Context: so one plant serves
    one episode at a time, as the episodes' diagrams are used (episode.DiagramCache)."""

    def __init__(self, plant):
        from pydrake.multibody.tree import PdControllerGains

        self._gains = PdControllerGains
        self._hips = [plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices()
                      if plant.get_joint_actuator(i).joint().name() in (f"{leg}_hip" for leg in LEGS)]
        names = [a.joint().name() for a in self._hips]
        if names != [f"{leg}_hip" for leg in LEGS]:
            raise ValueError(f"the plant's hip actuators: expected {[f'{leg}_hip' for leg in LEGS]}, got {names}")
        self._applied = [[math.nan, math.nan] for _ in self._hips]

    def apply(self, gains: np.ndarray, bounds: np.ndarray) -> None:
        """Give the left and the right hip's actuator `gains[leg]` (N*m*s/rad) and the torque bound `bounds[leg]`
        (N*m; 0: no torque), where they changed."""
        for leg, actuator in enumerate(self._hips):
            gain, bound = gains[leg], bounds[leg]
            applied = self._applied[leg]
            if gain != applied[0]:
                actuator.set_controller_gains(self._gains(p=0.0, d=gain))
                applied[0] = gain
            if bound != applied[1]:
                # Drake asks for a positive limit: the least double stands for none (its impulse over a step
                # rounds to zero; the update counts zero)
                actuator.set_effort_limit(max(bound, MOTOR_NO_TORQUE))
                applied[1] = bound


class CpgWalkingController(LeafSystem):
    """CPG + torque-free gate + hip PID + knee/ankle/stance logic for the 7-link biped."""

    def __init__(self, config: EpisodeConfig, body: np.ndarray = TABLE_I_BODY, plant=None):
        """`config`: the structure (`structure_key`) and the default context's numbers; an episode's numbers
        and initial conditions (first stance leg, lift-off angle, phase) are set in its context
        (`set_episode`, `set_initial_state`), so one system serves every episode of its structure. `body`:
        the model's body (kinematics.BODY, `model.body_of`), for the legs' points and the centre of mass.
        `plant`: the diagram's MultibodyPlant, whose dynamics the hip motor (GaitParams.hip_drive "motor")
        reads at each update through a context of its own (None: no motor)."""
        super().__init__()
        self._dyn = np.zeros(DYN_SIZE)
        self._dynamics = None if plant is None else PlantDynamics(plant, body)
        self._motors = None if plant is None else PlantMotors(plant)
        body = np.asarray(body, dtype=float)
        if body.shape != (BODY.size,):
            raise ValueError(f"body: expected a kinematics.BODY vector of {BODY.size}, got shape {body.shape}")
        self._body = body.copy()
        self._row = np.zeros(1 + _TD)  # the kernel's touchdown row: index, then TOUCHDOWN's fields
        # Structure: fixed for the life of the system.
        self._structure = self.structure_key(config)
        self._capacity = touchdown_capacity(config)
        # The episode's numbers (CPG, gait, window, fall thresholds: LAW) are a parameter of the Context, as
        # Drake's systems carry theirs: one built diagram serves any episode of its structure through its
        # context (`set_episode`), and nothing of the system changes between runs.
        self._law_index = self.DeclareNumericParameter(BasicVector(law_vector(config)))

        self._plant_state = self.DeclareVectorInputPort("plant_state", 18)
        initial = np.zeros(N_STATE)
        initial[STANCE_RIGHT] = initial[CONTACT_RIGHT] = 1.0  # until set_initial_state sets the episode's
        initial[TARGET_X] = math.inf
        initial[PREV_CLEARANCE] = math.inf
        initial[PREV_RATES : PREV_RATES + 2] = math.nan
        initial[RECENT_REVERSALS : RECENT_REVERSALS + DIVERGED_REVERSALS] = -math.inf
        initial[MOTOR_MODEL_RATE] = math.nan
        initial[MOTOR_GAIN : MOTOR_GAIN + 2] = MOTOR_OFF_GAIN  # the first plant step: no motor acts yet
        initial[MOTOR_BOUND : MOTOR_BOUND + 2] = body[B_HIP_EFFORT]
        self._torque_group = self.DeclareDiscreteState(6)
        self._state_group = self.DeclareDiscreteState(BasicVector(initial))
        self._touchdown_group = self.DeclareDiscreteState(self._capacity * _TD)
        self.DeclareStateOutputPort("actuation", self._torque_group)
        self.DeclareStateOutputPort("controller_state", self._state_group)
        self._command_group = self.DeclareDiscreteState(MOTOR_COMMAND_SIZE)
        self.DeclareStateOutputPort("motor_command", self._command_group)
        self.DeclarePeriodicDiscreteUpdateEvent(config.sim.update_period_s, 0.0, self._update)

    @staticmethod
    def structure_key(config: EpisodeConfig) -> tuple:
        """What the system's ports, state sizes and update period are built from."""
        sim = config.sim
        return (config.ground, sim.time_step_s, sim.update_period_s, sim.max_time_s, config.gait.touchdown_min_step_s,
                config.gait.plant_motor)

    def set_episode(self, context, config: EpisodeConfig) -> None:
        """Put the per-episode numbers (CPG, gait, window, fall thresholds) of `config` into this system's
        `context` (its LAW parameter). Its structure (ground, time step, control period, touchdown capacity)
        must be the one this system was built with."""
        if self.structure_key(config) != self._structure:
            raise ValueError("set_episode: this controller was built for another ground, time step, control "
                             "period, time limit, minimum step time or hip motor; build a new diagram")
        context.get_mutable_numeric_parameter(self._law_index).SetFromVector(law_vector(config))

    def law(self, context) -> np.ndarray:
        """The LAW vector in `context` (a view of the context's parameter)."""
        return context.get_numeric_parameter(self._law_index).get_value()

    def get_input_port_plant_state(self):
        """The plant state q (9), v (9) this controller reads."""
        return self._plant_state

    def get_output_port_actuation(self):
        """The six joint torques (N*m, JOINT_NAMES order)."""
        return self.GetOutputPort("actuation")

    def get_output_port_motor_command(self):
        """The plant's hip motors' command (GaitParams.motor_solve "plant"): the desired state of the plant's
        actuated joints, MOTOR_COMMAND_SIZE, for its desired-state input; only the hips' rates are read."""
        return self.GetOutputPort("motor_command")

    def get_output_port_controller_state(self):
        """The controller state (CONTROLLER_STATE)."""
        return self.GetOutputPort("controller_state")

    @property
    def state_group(self) -> int:
        return int(self._state_group)

    @property
    def touchdown_group(self) -> int:
        """The discrete group of the recorded touchdowns (capacity x TOUCHDOWN rows)."""
        return int(self._touchdown_group)

    def kernel_arguments(self, context) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What `control_step` takes besides the time, the plant state and the state vectors, for a caller
        that steps the plant itself (episode._step_directly): the episode's law vector, the body and the
        touchdown row it fills."""
        return self.law(context), self._body, self._row

    def store_touchdown(self, touchdowns: np.ndarray) -> None:
        """Write the touchdown row the kernel just filled (it returned TOUCHED) into the touchdown group's
        values `touchdowns`, while there is room."""
        n = int(self._row[0])
        if n < self._capacity:
            touchdowns[n * _TD : (n + 1) * _TD] = self._row[1:]

    @property
    def command_group(self) -> int:
        """The discrete group of the plant's motor command (the "motor_command" output)."""
        return int(self._command_group)

    def apply_motors(self, law: np.ndarray, s: np.ndarray) -> None:
        """Give the plant's hip actuators the gains and bounds the controller state `s` holds for the coming
        period (motor_solve "plant"; nothing otherwise): call after every update, and once an episode's initial
        state is set, before the plant's first step."""
        if law[L_MOTOR_PLANT] != 0.0:
            self._motors.apply(s[MOTOR_GAIN : MOTOR_GAIN + 2], s[MOTOR_BOUND : MOTOR_BOUND + 2])

    @property
    def torque_group(self) -> int:
        """The discrete group of the held torques (the "actuation" output)."""
        return int(self._torque_group)

    def set_initial_state(
        self,
        context,
        joint_angles,
        com_x: float,
        distance_m: float = math.inf,
        stance_right: bool | None = None,
        liftoff_angle: float | None = None,
        pitch: float = 0.0,
        phase: float = 0.0,
    ) -> None:
        """Seed the work integrator's previous angles (and the torso pitch), the centre-of-mass x, the
        distance to walk and the CPG phase of the first swing, and (when given) the first stance leg and the
        swing thigh's lift-off angle."""
        s = context.get_mutable_discrete_state(self._state_group)
        s.SetAtIndex(COM_X, com_x)
        s.SetAtIndex(TARGET_X, com_x + distance_m)
        s.SetAtIndex(PREV_PITCH, pitch)
        s.SetAtIndex(GAMMA, phase)
        for i in range(6):
            s.SetAtIndex(Q_PREV + i, float(joint_angles[i]))
        if stance_right is not None:
            s.SetAtIndex(STANCE_RIGHT, 1.0 if stance_right else 0.0)
            s.SetAtIndex(CONTACT_RIGHT, 1.0 if stance_right else 0.0)
        if liftoff_angle is not None:
            s.SetAtIndex(LIFTOFF_ANGLE, liftoff_angle)

    def state(self, context):
        """The controller state of `context`, by name (CONTROLLER_STATE.view)."""
        return CONTROLLER_STATE.view(context.get_discrete_state(self._state_group).value())

    def touchdowns(self, context) -> np.ndarray:
        """The recorded touchdowns, one row each (columns: TOUCHDOWN_FIELDS)."""
        n = min(int(context.get_discrete_state(self._state_group).GetAtIndex(STEP_COUNT)), self._capacity)
        rows = context.get_discrete_state(self._touchdown_group).value()[: n * _TD]
        return rows.reshape(n, _TD).copy()

    def motor_dynamics(self, law: np.ndarray, x: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The `dyn` argument of `control_step` for the plant state x and controller state s: the plant's
        dynamics where the law's hip is a motor (`hip_motor.PlantDynamics`), else the unread zeros."""
        if law[L_MOTOR] == 0.0 or law[L_MOTOR_PLANT] != 0.0:
            return self._dyn
        if self._dynamics is None:
            raise ValueError("hip_drive 'motor' needs the plant: build the controller with plant=")
        self._dynamics.fill(self._dyn, x, s[STANCE_RIGHT] > 0.5, s[TAU : TAU + 6])
        return self._dyn

    def _update(self, context, discrete_state):
        # The discrete state handed to the update holds the current values; the kernel advances the
        # controller state and the held torques in place.
        law, x = self.law(context), self._plant_state.Eval(context)
        s = discrete_state.get_mutable_value(self._state_group)
        code = control_step(law, self._body, context.get_time(), x, s,
                            discrete_state.get_mutable_value(self._torque_group), self._row,
                            self.motor_dynamics(law, x, s), discrete_state.get_mutable_value(self._command_group))
        if code & MOTORS:
            self.apply_motors(law, s)
        if code == 0:
            return None
        if code & TOUCHED:
            self.store_touchdown(discrete_state.get_mutable_value(self._touchdown_group))
        if code & FELL:
            fall = int(discrete_state.get_value(self._state_group)[FALL])
            return EventStatus.ReachedTermination(self, FALL_REASONS[fall])
        if code & DONE_BIT:
            return EventStatus.ReachedTermination(self, "distance reached")
        return None
