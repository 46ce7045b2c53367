"""Build the biped MultibodyPlant from the model file and add the ground.

The robot is loaded by `package://drake_biped/biped.urdf` through the `package.xml` shipped as package data
(`drake_biped.models`, the repository's models/ folder), never by a path relative to the caller's working
directory or the source tree.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.geometry import AddContactMaterial, Box, HalfSpace, ProximityProperties, SceneGraph, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlant,
    MultibodyPlantConfig,
)
from pydrake.systems.framework import DiagramBuilder

from drake_biped.kinematics import FOOT_COM_M, SHANK_M, THIGH_M, TORSO_M, LinkMasses, link_masses
from drake_biped.params import CONTACT_RADIUS_M, GRAVITY_MPS2, HEEL_X_M, SOLE_DEPTH_M, TOE_X_M, Ground
from drake_biped.resources import model_package_xml

MODEL_URL = "package://drake_biped/biped.urdf"

# Drake warns once per diagram (so once per worker and episode structure) that the ground's rigid half-spaces
# take no part in deformable contact, which this toolkit does not use. That one message, by its exact text,
# is dropped; every other message of Drake's logger passes.
HALF_SPACE_WARNING = ("Rigid (non-deformable) half spaces are not currently supported for deformable contact; "
                      "registration is allowed, but no contact data will be reported.")


class _DropHalfSpaceWarning(logging.Filter):
    def filter(self, record: logging.LogRecord) -> bool:
        return record.getMessage() != HALF_SPACE_WARNING


if not any(isinstance(f, _DropHalfSpaceWarning) for f in logging.getLogger("drake").filters):
    logging.getLogger("drake").addFilter(_DropHalfSpaceWarning())

# Legs and their joints, and the joint order used everywhere in the toolkit (positions 3..8, velocities
# 3..8, actuators 0..5): left hip, knee, ankle, then right.
LEGS = ("left", "right")
JOINTS_OF_A_LEG = ("hip", "knee", "ankle")
JOINT_NAMES = tuple(f"{leg}_{joint}" for leg in LEGS for joint in JOINTS_OF_A_LEG)


def joint_index(leg: str, joint: str) -> int:
    """Index of a leg's joint in JOINT_NAMES and in the actuation vector (add 3 for the plant's positions)."""
    return JOINT_NAMES.index(f"{leg}_{joint}")
BASE_NAMES = ("x", "z", "pitch")
FOOT_BODIES = ("left_foot", "right_foot")


class ModelError(RuntimeError):
    """The model file is missing, malformed, or not the biped this toolkit expects."""


@dataclass(frozen=True)
class PlantHandles:
    plant: MultibodyPlant
    scene_graph: SceneGraph
    masses: LinkMasses  # read from the model file: every per-kg figure and the centre of mass use these


def add_biped(
    builder: DiagramBuilder,
    ground: Ground,
    time_step_s: float,
    model_url: str = MODEL_URL,
    package_xml: Path | None = None,
    contact_approximation: str = "sap",
) -> PlantHandles:
    """Add the biped and the ground to `builder` and finalize the plant.

    Contact: point contact (the heel/toe spheres against the ground half-space(s)), solved by the discrete
    contact approximation given (SAP by default). Output ports are sampled (see controller "Timing").
    """
    config = MultibodyPlantConfig(
        time_step=time_step_s,
        use_sampled_output_ports=True,
        discrete_contact_approximation=contact_approximation,
        contact_model="point",
        penetration_allowance=1e-3,
    )
    plant, scene_graph = AddMultibodyPlant(config, builder)
    parser = Parser(plant)
    package_xml = model_package_xml() if package_xml is None else Path(package_xml)
    if not package_xml.is_file():
        raise ModelError(f"model package file not found: {package_xml}")
    parser.package_map().AddPackageXml(str(package_xml))
    try:
        parser.AddModels(url=model_url)
    except Exception as exc:  # Drake raises RuntimeError with the parser's message
        raise ModelError(f"could not parse the biped model {model_url}: {exc}") from exc
    _add_ground(plant, ground)
    plant.Finalize()
    check_layout(plant)
    check_geometry(plant, scene_graph)
    return PlantHandles(plant, scene_graph, link_masses_of(plant))


# A level-then-slope ground's boxes: the level part from GROUND_BEHIND_M (behind the start) to the slope's foot,
# the slope GROUND_AHEAD_M beyond it, both GROUND_DEPTH_M deep.
GROUND_BEHIND_M, GROUND_AHEAD_M, GROUND_DEPTH_M = -100.0, 2000.0, 10.0


def _add_ground(plant: MultibodyPlant, ground: Ground) -> None:
    """Ground as half-space(s) for contact plus thin boxes so Meshcat can draw it."""
    friction = CoulombFriction(ground.friction, ground.friction)
    world = plant.world_body()

    def add_plane(name: str, angle: float, through_x: float) -> None:
        # Half-space whose surface passes through (through_x, 0, 0), tilted by `angle` (ascending +x).
        rotation = RotationMatrix.MakeYRotation(-angle)
        X = RigidTransform(rotation, [through_x, 0.0, 0.0])
        props = ProximityProperties()
        AddContactMaterial(friction=friction, properties=props)
        plant.RegisterCollisionGeometry(world, X, HalfSpace(), name, props)

    def add_ground_box(name: str, angle: float, x0: float, x1: float) -> None:
        # A box whose top face is the ground from x0 to x1 (measured along the ground), rising at `angle` from
        # (x0, 0, 0), GROUND_DEPTH_M deep.
        props = ProximityProperties()
        AddContactMaterial(friction=friction, properties=props)
        rotation = RotationMatrix.MakeYRotation(-angle)
        centre = rotation.multiply(np.array([0.5 * (x1 - x0), 0.0, -0.5 * GROUND_DEPTH_M])) + np.array([x0, 0.0, 0.0])
        plant.RegisterCollisionGeometry(world, RigidTransform(rotation, centre), Box(x1 - x0, 10.0, GROUND_DEPTH_M),
                                        name, props)

    def add_visual(name: str, angle: float, x0: float, x1: float, z0: float) -> None:
        length = (x1 - x0) / math.cos(angle)
        centre_x = 0.5 * (x0 + x1)
        centre_z = z0 + 0.5 * (x1 - x0) * math.tan(angle)
        rotation = RotationMatrix.MakeYRotation(-angle)
        offset = rotation.multiply(np.array([0.0, 0.0, -0.01]))
        X = RigidTransform(rotation, [centre_x + offset[0], 0.0, centre_z + offset[2]])
        plant.RegisterVisualGeometry(world, X, Box(length, 1.0, 0.02), name, np.array([0.45, 0.6, 0.45, 1.0]))

    def add_marks(x0: float, x1: float) -> None:
        # A dark line across the ground every metre (visual only): the walk's progress shows in the
        # recording, whose camera moves with the robot.
        for k in range(math.ceil(x0), math.floor(x1) + 1):
            z = ground.height(float(k))
            angle = ground.slope_at(float(k))
            X = RigidTransform(RotationMatrix.MakeYRotation(-angle), [float(k), 0.0, z + 0.0005])
            plant.RegisterVisualGeometry(world, X, Box(0.015, 1.0, 0.001), f"ground_mark_{k}",
                                         np.array([0.25, 0.35, 0.25, 1.0]))

    # The drawn ground runs from 5 m behind the start to 60 m past the ground's last feature (the start, or
    # the foot of the slope), so every accepted level length (up to 1000 m) has a slope to draw after it.
    visual_end = 60.0 + (ground.level_length_m or 0.0)
    add_marks(-2.0, visual_end)
    if ground.level_length_m is None or ground.slope_rad == 0.0:
        # One surface is one half-space: a level length before no slope is the level ground itself (two
        # coincident half-spaces would give each foot sphere two contacts, twice the ground's stiffness).
        add_plane("ground", ground.slope_rad, 0.0)
        add_visual("ground_visual", ground.slope_rad, -5.0, visual_end, -5.0 * math.tan(ground.slope_rad))
    else:
        # Level-then-ascending, max(0, (x - x0) tan s): each surface a box that is the ground only where that
        # surface is, meeting at the kink x0. Two half-spaces (their union is the same ground) both reach under
        # the other part, so a foot sphere within p / tan s of the kink (5 cm at 1 mm and 0.02 rad) met the
        # ground twice; measured on the climbing gaits' 10 m (2 m level), C_mt moves by 0.14 % and 0.10 %.
        add_ground_box("ground_level", 0.0, GROUND_BEHIND_M, ground.level_length_m)
        add_ground_box("ground_slope", ground.slope_rad, ground.level_length_m, ground.level_length_m + GROUND_AHEAD_M)
        add_visual("ground_level_visual", 0.0, -5.0, ground.level_length_m, 0.0)
        add_visual("ground_slope_visual", ground.slope_rad, ground.level_length_m, visual_end, 0.0)


def check_layout(plant: MultibodyPlant) -> None:
    """Raise ModelError unless positions, velocities and actuators follow JOINT_NAMES' order."""
    if plant.num_positions() != 9 or plant.num_velocities() != 9 or plant.num_actuators() != 6:
        raise ModelError(
            f"expected 9 positions, 9 velocities and 6 actuators, got {plant.num_positions()}, "
            f"{plant.num_velocities()}, {plant.num_actuators()}"
        )
    for name in ("floating_base", *JOINT_NAMES):
        if not plant.HasJointNamed(name):
            raise ModelError(f"the model has no joint named {name!r}; expected {['floating_base', *JOINT_NAMES]}")
    for name in JOINT_NAMES:
        if not plant.HasJointActuatorNamed(f"{name}_motor"):
            raise ModelError(f"the model has no actuator named {name + '_motor'!r} (a <transmission> for joint {name})")
    base = plant.GetJointByName("floating_base")
    if base.type_name() != "planar" or base.position_start() != 0:
        raise ModelError("the floating base must be the planar joint at position 0")
    for i, name in enumerate(JOINT_NAMES):
        joint = plant.GetJointByName(name)
        if joint.position_start() != 3 + i or joint.velocity_start() != 3 + i:
            raise ModelError(f"joint {name} is at position {joint.position_start()}, expected {3 + i}")
        actuator = plant.GetJointActuatorByName(f"{name}_motor")
        if int(actuator.index()) != i:
            raise ModelError(f"actuator {name}_motor has index {int(actuator.index())}, expected {i}")


def link_masses_of(plant: MultibodyPlant) -> LinkMasses:
    """The links' masses as the model file gives them; ModelError unless the legs are mirror images (the
    controller's centre of mass takes one mass per link kind)."""
    def mass(name: str) -> float:
        return float(plant.GetBodyByName(name).default_mass())

    legs = {leg: tuple(mass(f"{leg}_{link}") for link in ("thigh", "shank", "foot")) for leg in LEGS}
    if legs["left"] != legs["right"]:
        raise ModelError(f"the legs' masses differ (left thigh, shank, foot {legs['left']} kg, right "
                         f"{legs['right']} kg); the toolkit assumes mirror-image legs")
    return link_masses(mass("torso"), *legs["left"])


def check_geometry(plant: MultibodyPlant, scene_graph: SceneGraph, tolerance_m: float = 1e-9) -> None:
    """Raise ModelError, naming the quantity and both values, unless the model's lengths, centres of mass and
    foot contact spheres are those the controller's planar kinematics uses (`kinematics`): the controller
    computes touchdowns, falls and the centre of mass from them."""
    def check(what: str, model_value, expected) -> None:
        model_value, expected = np.asarray(model_value, float), np.asarray(expected, float)
        if model_value.shape != expected.shape or np.max(np.abs(model_value - expected)) > tolerance_m:
            raise ModelError(f"the model's {what} is {np.round(model_value, 6).tolist()}, but the controller's "
                             f"kinematics uses {np.round(expected, 6).tolist()} (drake_biped/kinematics.py)")

    def xz(v) -> list[float]:
        return [float(v[0]), float(v[2])]

    check("gravity (x, y, z, m/s^2; C_mt divides by m g d with g = params.GRAVITY_MPS2)",
          plant.gravity_field().gravity_vector(), [0.0, 0.0, -GRAVITY_MPS2])
    check("torso centre of mass (x, z in the torso frame, m)", xz(plant.GetBodyByName("torso").default_com()),
          [0.0, 0.5 * TORSO_M])
    for leg in LEGS:
        offset = plant.GetJointByName(f"{leg}_hip").frame_on_parent().GetFixedPoseInBodyFrame().translation()
        check(f"{leg} hip position in the torso frame (x, z, m)", xz(offset), [0.0, 0.0])
        for joint, parent, length in (("knee", "thigh", THIGH_M), ("ankle", "shank", SHANK_M)):
            frame = plant.GetJointByName(f"{leg}_{joint}").frame_on_parent()
            check(f"{leg} {joint} position in the {parent} frame (x, z, m; the {parent} length)",
                  xz(frame.GetFixedPoseInBodyFrame().translation()), [0.0, -length])
            check(f"{leg} {parent} centre of mass (x, z, m)", xz(plant.GetBodyByName(f"{leg}_{parent}").default_com()),
                  [0.0, -0.5 * length])
        foot = plant.GetBodyByName(f"{leg}_foot")
        check(f"{leg} foot centre of mass (x, z in the ankle frame, m)", xz(foot.default_com()), list(FOOT_COM_M))
        inspector = scene_graph.model_inspector()
        spheres = []
        for geometry in plant.GetCollisionGeometriesForBody(foot):
            shape = inspector.GetShape(geometry)
            if not isinstance(shape, Sphere):
                raise ModelError(f"{leg}_foot collides through a {type(shape).__name__}; the controller's "
                                 "kinematics expects a sphere at the heel and one at the toe")
            spheres.append([*xz(inspector.GetPoseInFrame(geometry).translation()), shape.radius()])
        check(f"{leg} foot contact spheres (x, z, radius in the ankle frame, m)", sorted(spheres),
              [[HEEL_X_M, CONTACT_RADIUS_M - SOLE_DEPTH_M, CONTACT_RADIUS_M],
               [TOE_X_M, CONTACT_RADIUS_M - SOLE_DEPTH_M, CONTACT_RADIUS_M]])


def effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Actuator torque limits (N*m) in JOINT_NAMES order, as read from the model file."""
    return np.array([plant.GetJointActuatorByName(f"{n}_motor").effort_limit() for n in JOINT_NAMES])


def build_plant(ground: Ground | None = None, time_step_s: float = 1e-3) -> MultibodyPlant:
    """A finalized plant in its own diagram builder, for inspection and tests."""
    builder = DiagramBuilder()
    return add_biped(builder, ground or Ground(), time_step_s).plant
