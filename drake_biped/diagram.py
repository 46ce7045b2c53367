"""Wire the plant, the CPG controller, an optional push and the loggers into one Diagram."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce, MultibodyPlant
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import LogVectorOutput, TrajectorySource, VectorLogSink
from pydrake.trajectories import PiecewisePolynomial

from drake_biped.controller import CpgWalkingController
from drake_biped.hip_motor import MOTOR_OFF_GAIN
from drake_biped.kinematics import TABLE_I_BODY, LinkMasses, leg_points, masses_of
from drake_biped.model import add_biped
from drake_biped.params import EpisodeConfig, Push


class TorsoPush(LeafSystem):
    """A horizontal force on the torso's centre of mass during [start, start + duration)."""

    def __init__(self, plant: MultibodyPlant, push: Push):
        super().__init__()
        torso = plant.GetBodyByName("torso")
        self._push = push
        self._force = ExternallyAppliedSpatialForce()
        self._force.body_index = torso.index()
        self._force.p_BoBq_B = torso.default_com()
        self.DeclareAbstractOutputPort(
            "spatial_forces",
            lambda: AbstractValue.Make([ExternallyAppliedSpatialForce()]),
            self._calc,
        )

    def force_at(self, t: float) -> float:
        p = self._push
        return p.force_n if p.start_s <= t < p.start_s + p.duration_s else 0.0

    def _calc(self, context, output) -> None:
        self._force.F_Bq_W = SpatialForce(np.zeros(3), np.array([self.force_at(context.get_time()), 0.0, 0.0]))
        output.set_value([self._force])


@dataclass
class BipedDiagram:
    diagram: Diagram
    plant: MultibodyPlant
    controller: CpgWalkingController
    body: np.ndarray  # kinematics.BODY, the model's as the plant holds it (`model.body_of`)
    state_log: VectorLogSink | None = None
    controller_log: VectorLogSink | None = None
    actuation_log: VectorLogSink | None = None
    # the actuation log is the plant's net actuation (its hip motors solved in its step), each sample the torques
    # of the step that ended there; else the controller's output, each sample the torques of the step it begins
    actuation_applied: bool = False

    @property
    def masses(self) -> LinkMasses:
        """The model's link masses."""
        return masses_of(self.body)


def initial_state(config: EpisodeConfig, body: np.ndarray = TABLE_I_BODY) -> tuple[np.ndarray, np.ndarray, bool, float]:
    """The paper's initiation: q, v, whether the right leg is the first stance leg, the swing lift-off angle.

    The initial hip angle is the angle between the thighs (the inter-leg angle of the Poincare section):
    the torso at its reference lean (GaitParams.torso_pitch_rad, so the torso servo starts at rest), the
    right thigh at +hip_angle/2 from vertical (front, stance), the left at -hip_angle/2 (rear, swing), knees
    straight, feet parallel to the ground, lowest contact point 0.1 mm above it; every body moves forward
    at the initial speed (a horizontal velocity of the floating base with zero joint rates). `body`: the
    model's (kinematics.BODY), for the height that puts the lowest foot point on the ground."""
    a = 0.5 * config.initial.hip_angle_rad
    slope0 = config.ground.slope_at(0.0)
    pitch = config.gait.torso_pitch_rad
    q = np.zeros(9)
    q[2] = pitch
    q[3], q[6] = -a - pitch, a - pitch  # thigh world angles -a, +a
    q[5], q[8] = slope0 + a, slope0 - a  # foot angle = thigh - knee + ankle = local slope
    lowest = math.inf
    for i in (3, 6):
        p = leg_points(0.0, 0.0, pitch, q[i], q[i + 1], q[i + 2], body)
        for px, pz in ((p.heel_x, p.heel_z), (p.toe_x, p.toe_z)):
            lowest = min(lowest, pz - config.ground.height(px))
    q[1] = -lowest + 1e-4
    v = np.zeros(9)
    v[0] = config.initial.speed_mps
    return q, v, True, -a


def build_diagram(
    config: EpisodeConfig, meshcat=None, record: bool = False, log_period_s: float | None = None
) -> BipedDiagram:
    """Plant + SceneGraph + controller (+ push) (+ loggers), as a named Diagram.

    record: add loggers of the plant state, the controller state and the actuation, sampled every
    log_period_s (default: the control period). Without them the diagram keeps only what an episode's
    summary needs (the controller's own state: work integrals, touchdowns, fall flag).
    """
    builder = DiagramBuilder()
    handles = add_biped(builder, config.ground, config.sim.time_step_s, config.model,
                        contact_approximation=config.sim.contact_approximation, contact=config.contact)
    plant = handles.plant
    controller = builder.AddNamedSystem("cpg_controller", CpgWalkingController(config, handles.body, plant))
    builder.Connect(plant.get_state_output_port(), controller.get_input_port_plant_state())
    builder.Connect(controller.get_output_port_actuation(), plant.get_actuation_input_port())
    if config.gait.plant_motor:  # the hips' actuators are the motor's, inside the plant's step
        from pydrake.multibody.tree import PdControllerGains

        hips = [plant.get_joint_actuator(i) for i in plant.GetJointActuatorIndices()
                if plant.get_joint_actuator(i).joint().name().endswith("_hip")]
        for actuator in hips:
            actuator.set_controller_gains(PdControllerGains(p=0.0, d=MOTOR_OFF_GAIN))
        builder.Connect(controller.get_output_port_motor_command(),
                        plant.get_desired_state_input_port(hips[0].joint().model_instance()))
    if config.push is not None and config.push.force_n != 0.0 and config.push.duration_s > 0.0:
        push = builder.AddNamedSystem("torso_push", TorsoPush(plant, config.push))
        builder.Connect(push.get_output_port(), plant.get_applied_spatial_force_input_port())
    logs: dict[str, VectorLogSink] = {}
    if record:
        period = log_period_s or config.sim.update_period_s
        for name, port in (
            ("state_log", plant.get_state_output_port()),
            ("controller_log", controller.get_output_port_controller_state()),
            # the torques the plant applied: its motors' included, where it solves the hip motor
            ("actuation_log", plant.get_net_actuation_output_port() if config.gait.plant_motor
             else controller.get_output_port_actuation()),
        ):
            logs[name] = LogVectorOutput(port, builder, period)
            logs[name].set_name(name)
    if meshcat is not None:
        from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams, Role

        MeshcatVisualizer.AddToBuilder(
            builder, handles.scene_graph, meshcat, MeshcatVisualizerParams(role=Role.kIllustration)
        )
    diagram = builder.Build()
    diagram.set_name("drake_biped")
    return BipedDiagram(diagram, plant, controller, handles.body, **logs, actuation_applied=config.gait.plant_motor)


def build_replay_diagram(
    config: EpisodeConfig, times: np.ndarray, torques: np.ndarray, observer: LeafSystem | None = None
) -> tuple[Diagram, MultibodyPlant]:
    """The plant alone, driven by a zero-order hold of logged torques (no controller, no Python).

    times (n,) and torques (n, 6) are an actuation log sampled at the control period: torque k acts over
    [times[k], times[k] + period). Replayed from the same initial state at the same time step, it reproduces
    the closed-loop trajectory, so the plant sees exactly the closed loop's contacts: the reference against
    which the controller's cost is measured. An `observer` (a system with one 18-vector input) is fed the
    plant state and drives nothing: it times a controller's computation without letting it act.
    """
    times = np.asarray(times, dtype=float)
    torques = np.asarray(torques, dtype=float)
    if times.ndim != 1 or torques.shape != (times.size, 6) or times.size < 1:
        raise ValueError(f"expected times (n,) and torques (n, 6), got {times.shape} and {torques.shape}")
    builder = DiagramBuilder()
    plant = add_biped(builder, config.ground, config.sim.time_step_s, config.model,
                      contact_approximation=config.sim.contact_approximation, contact=config.contact).plant
    breaks = np.append(times, times[-1] + config.sim.update_period_s)
    hold = PiecewisePolynomial.ZeroOrderHold(breaks, np.vstack([torques, torques[-1:]]).T)
    source = builder.AddNamedSystem("logged_torques", TrajectorySource(hold))
    builder.Connect(source.get_output_port(), plant.get_actuation_input_port())
    if observer is not None:
        builder.AddSystem(observer)
        builder.Connect(plant.get_state_output_port(), observer.get_input_port(0))
    diagram = builder.Build()
    diagram.set_name("drake_biped_replay")
    return diagram, plant
