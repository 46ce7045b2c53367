"""Build the biped MultibodyPlant from a model file and add the ground; read the controller's body from it.

The shipped robot is loaded by `package://drake_biped/biped.urdf` through the `package.xml` shipped as package
data (`drake_biped.models`, the repository's models/ folder), never by a path relative to the caller's working
directory or the source tree. A user's model (`params.RobotModel`, `--model FILE`) is parsed from its text;
its package:// URIs resolve through the package.xml beside it, when there is one, and the shipped package.

`body_of` reads the controller's planar kinematics (joint positions, centres of mass, contact spheres, masses)
from the finalized plant. What cannot be read, it checks, with one line naming what is missing or different:
the links' and joints' names, a planar base, mirror-image legs, joints that turn in the sagittal plane with
the shipped model's signs, and a heel and a toe sphere on each foot.
"""

from __future__ import annotations

import logging
import math
import re
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote, urlparse

import numpy as np
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    AddRigidHydroelasticProperties,
    Box,
    HalfSpace,
    ProximityProperties,
    RoleAssign,
    SceneGraph,
    Sphere,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlant,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.framework import DiagramBuilder

from drake_biped.kinematics import (
    LinkMasses,
    body_vector,
    center_of_mass_k,
    leg_points_k,
    link_masses,
)
from drake_biped.params import GRAVITY_MPS2, ContactParams, Ground, ParameterError, RobotModel
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
# The joints by their leg's role: each joint of the swing leg, then the same joint of the stance leg.
ROLES = tuple(f"{role}_{joint}" for joint in JOINTS_OF_A_LEG for role in ("swing", "stance"))


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
    body: np.ndarray  # kinematics.BODY, read from the model (`body_of`): its masses are every per-kg figure's


def add_biped(
    builder: DiagramBuilder,
    ground: Ground,
    time_step_s: float,
    model: RobotModel | None = None,
    contact_approximation: str = "sap",
    contact: ContactParams | None = None,
) -> PlantHandles:
    """Add the biped (`model`, or the shipped one) and the ground to `builder`, finalize the plant and read
    the controller's body from it.

    Contact: the heel/toe spheres against the ground half-space(s), as point contacts or, under `contact.model`
    "hydroelastic", as compliant hydroelastic spheres against the rigid ground; solved by the discrete contact
    approximation given (SAP by default), with the material of `contact` (params.ContactParams; its defaults
    when None) on the foot spheres and the ground. Output ports are sampled (see controller "Timing").
    """
    contact = contact or ContactParams()
    config = MultibodyPlantConfig(
        time_step=time_step_s,
        use_sampled_output_ports=True,
        discrete_contact_approximation=contact_approximation,
        contact_model="point" if contact.model == "point" else "hydroelastic_with_fallback",
        penetration_allowance=1e-3,
        sap_near_rigid_threshold=contact.sap_near_rigid_threshold,
    )
    plant, scene_graph = AddMultibodyPlant(config, builder)
    parse_model(Parser(plant), model)
    _set_feet_material(plant, scene_graph, contact)
    _add_ground(plant, ground, contact)
    plant.Finalize()
    check_layout(plant)
    return PlantHandles(plant, scene_graph, body_of(plant, scene_graph))


_MATERIAL = (("point_contact_stiffness", "stiffness_npm"), ("relaxation_time", "relaxation_time_s"),
             ("hunt_crossley_dissipation", "hunt_crossley_dissipation_spm"))


def _with_material(props: ProximityProperties, contact: ContactParams) -> ProximityProperties:
    """`props` with the material values of `contact` that are set (None leaves Drake's default)."""
    for name, field in _MATERIAL:
        value = getattr(contact, field)
        if value is not None:
            props.UpdateProperty("material", name, float(value))
    return props


def _foot_properties(props: ProximityProperties, contact: ContactParams) -> ProximityProperties:
    """A foot sphere's properties: the material, and under the hydroelastic model a compliant hydroelastic
    sphere with the contact's modulus, mesh and margin."""
    props = _with_material(props, contact)
    if contact.model == "hydroelastic":
        AddCompliantHydroelasticProperties(contact.resolution_hint_m, contact.hydroelastic_modulus_pa, props)
        if contact.margin_m > 0.0:
            props.AddProperty("hydroelastic", "margin", float(contact.margin_m))
    return props


def _ground_properties(props: ProximityProperties, contact: ContactParams, boxed: bool) -> ProximityProperties:
    """The ground's properties: the material, and under the hydroelastic model rigid hydroelastic (a box's
    surface meshed at a tenth of its depth: its top face is flat, any mesh represents it exactly)."""
    props = _with_material(props, contact)
    if contact.model == "hydroelastic":
        if boxed:
            AddRigidHydroelasticProperties(0.1 * GROUND_DEPTH_M, props)
        else:
            AddRigidHydroelasticProperties(props)
    return props


def _set_feet_material(plant: MultibodyPlant, scene_graph: SceneGraph, contact: ContactParams) -> None:
    """Give every collision geometry of the feet the contact's material, keeping the model's friction."""
    inspector = scene_graph.model_inspector()
    for name in FOOT_BODIES:
        if not plant.HasBodyNamed(name):
            continue  # check_layout and body_of name what is missing
        for geometry in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(name)):
            props = ProximityProperties(inspector.GetProximityProperties(geometry))
            scene_graph.AssignRole(plant.get_source_id(), geometry, _foot_properties(props, contact),
                                   RoleAssign.kReplace)


def parse_model(parser: Parser, model: RobotModel | None = None) -> None:
    """Add `model` (or the shipped robot) to the parser's plant; ModelError naming the file when it cannot be
    parsed."""
    packages = parser.package_map()
    if model is not None and model.package_xml is not None and Path(model.package_xml).is_file():
        packages.AddPackageXml(model.package_xml)
    if not packages.Contains("drake_biped"):
        shipped = model_package_xml()
        if not shipped.is_file():
            raise ModelError(f"model package file not found: {shipped}")
        packages.AddPackageXml(str(shipped))
    name = MODEL_URL if model is None else model.name
    if model is not None:
        _check_masses(model)
        text = _with_resolved_files(model, packages)
    try:
        if model is None:
            parser.AddModels(url=MODEL_URL)
        else:
            parser.AddModelsFromString(text, model.format)
    except Exception as exc:  # Drake raises RuntimeError with the parser's message
        detail = " ".join(str(exc).split())
        if model is not None:  # Drake names a text it parsed "<literal-string>.urdf": name the file
            detail = detail.replace(f"<literal-string>.{model.format}", model.name)
        raise ModelError(f"could not parse the model {name}: {detail}") from exc


def _with_resolved_files(model: RobotModel, packages: PackageMap) -> str:
    """The model's text with each file it names (a URDF `filename="..."`, an SDFormat `<uri>`) checked and, when
    it is a path, made a file:// URI: a text parsed from a string has no folder of its own, so a relative name
    is read against the folder the model file was read from, and Drake takes no bare path in it at all.

    ModelError naming the file and where it was looked for when it is not there: a relative name in the model
    file's folder, a package:// (SDFormat model://) URI in its package, which must be known (the package.xml
    beside the model file, the shipped drake_biped, Drake's own). Other schemes are left to Drake."""
    folder = Path(model.directory) if model.directory else None

    def missing(value: str, looked: str) -> ModelError:
        return ModelError(f"the model {model.name} names the file {value!r}, which does not exist: looked for "
                          f"{looked}")

    def package_file(value: str, scheme: str) -> None:
        package, _, rest = value[len(scheme) + 3:].partition("/")
        if not packages.Contains(package):
            if model.package_xml and Path(model.package_xml).is_file():
                beside = f"the package.xml beside the model file ({model.package_xml}) declares another"
            elif folder is not None:
                beside = f"the model file's folder {folder} has no package.xml"
            else:
                beside = "the model was given as text, without the folder of a package.xml"
            raise ModelError(f"the model {model.name} names the file {value!r} in the package {package!r}, which "
                             f"is unknown: {beside}; the known packages are {sorted(packages.GetPackageNames())}")
        root = Path(packages.GetPath(package))
        if not (root / rest).exists():
            raise missing(value, f"{root / rest} (the package {package!r} is {root})")

    def checked(value: str) -> str:
        scheme = urlparse(value).scheme if "://" in value else ""
        if scheme in ("package", "model"):
            package_file(value, scheme)
            return value
        if scheme == "file":
            if not Path(unquote(urlparse(value).path)).exists():
                raise missing(value, unquote(urlparse(value).path))
            return value
        if scheme:
            return value  # another scheme: Drake's to resolve or name
        if Path(value).is_absolute():
            if not Path(value).exists():
                raise missing(value, value)
            return Path(value).resolve().as_uri()
        if folder is None:
            raise ModelError(f"the model {model.name} names the file {value!r} relative to the model file, but "
                             "the model was given as text without its folder: give it as a file "
                             "(RobotModel.from_file(path))")
        if not (folder / value).exists():
            raise missing(value, f"{folder / value} (in the model file's folder)")
        return (folder / value).resolve().as_uri()

    if model.format == "urdf":
        return re.sub(r"""filename=(["'])(.+?)\1""",
                      lambda m: f"filename={m.group(1)}{checked(m.group(2))}{m.group(1)}", model.text)
    return re.sub(r"<uri>\s*([^<]+?)\s*</uri>", lambda m: f"<uri>{checked(m.group(1))}</uri>", model.text)


# A level-then-slope ground's boxes: the level part from GROUND_BEHIND_M (behind the start) to the slope's foot,
# the slope GROUND_AHEAD_M beyond it, both GROUND_DEPTH_M deep.
GROUND_BEHIND_M, GROUND_AHEAD_M, GROUND_DEPTH_M = -100.0, 2000.0, 10.0


def _add_ground(plant: MultibodyPlant, ground: Ground, contact: ContactParams) -> None:
    """Ground as half-space(s) for contact, with the contact's material, plus thin boxes so Meshcat can draw
    it."""
    friction = CoulombFriction(ground.friction, ground.friction)
    world = plant.world_body()

    def add_plane(name: str, angle: float, through_x: float) -> None:
        # Half-space whose surface passes through (through_x, 0, 0), tilted by `angle` (ascending +x).
        rotation = RotationMatrix.MakeYRotation(-angle)
        X = RigidTransform(rotation, [through_x, 0.0, 0.0])
        props = ProximityProperties()
        AddContactMaterial(friction=friction, properties=props)
        plant.RegisterCollisionGeometry(world, X, HalfSpace(), name, _ground_properties(props, contact, False))

    def add_ground_box(name: str, angle: float, x0: float, x1: float) -> None:
        # A box whose top face is the ground from x0 to x1 (measured along the ground), rising at `angle` from
        # (x0, 0, 0), GROUND_DEPTH_M deep.
        props = _ground_properties(ProximityProperties(), contact, True)
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


def actuator_of(plant: MultibodyPlant, joint: str):
    """The actuator driving `joint`: whatever the model names it (a URDF's <transmission> names its actuator,
    `left_hip_motor` in the shipped model; Drake names an SDFormat actuator after its joint). ModelError naming
    the joint when none drives it."""
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        if actuator.joint().name() == joint:
            return actuator
    raise ModelError(f"the model has no actuator for joint {joint} (a URDF <transmission> for it, or an SDFormat "
                     "<drake:controller>/effort limit on the joint)")


def check_layout(plant: MultibodyPlant) -> None:
    """Raise ModelError unless the joints and actuators are named as the shipped model's and positions,
    velocities and actuators follow JOINT_NAMES' order."""
    for name in ("floating_base", *JOINT_NAMES):
        if not plant.HasJointNamed(name):
            raise ModelError(f"the model has no joint named {name!r}; expected {['floating_base', *JOINT_NAMES]}")
    for name in JOINT_NAMES:
        actuator_of(plant, name)
    _check_every_body_rides_a_link(plant)
    if plant.num_positions() != 9 or plant.num_velocities() != 9 or plant.num_actuators() != 6:
        raise ModelError(
            f"expected 9 positions, 9 velocities and 6 actuators, got {plant.num_positions()}, "
            f"{plant.num_velocities()}, {plant.num_actuators()}"
        )
    base = plant.GetJointByName("floating_base")
    if base.type_name() != "planar" or base.position_start() != 0:
        raise ModelError("the floating base must be the planar joint at position 0")
    for i, name in enumerate(JOINT_NAMES):
        joint = plant.GetJointByName(name)
        if joint.position_start() != 3 + i or joint.velocity_start() != 3 + i:
            raise ModelError(f"joint {name} is at position {joint.position_start()}, expected {3 + i}")
        actuator = actuator_of(plant, name)
        if int(actuator.index()) != i:
            raise ModelError(f"actuator {actuator.name()} has index {int(actuator.index())}, expected {i}")


def _check_masses(model: RobotModel) -> None:
    """ModelError naming the link when the model file gives a link a mass that is not positive (Drake's parser
    only warns, and gives the link a default mass)."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.fromstring(model.text)
    except ET.ParseError as exc:
        raise ModelError(f"could not parse the model {model.name}: {exc}") from None
    for link in root.iter("link"):
        _check_inertia(model, link)
        mass = link.find("inertial/mass")
        if mass is None:
            continue
        text = mass.get("value") if model.format == "urdf" else mass.text
        try:
            value = float(text)
        except (TypeError, ValueError):
            raise ModelError(f"the model {model.name}: link {link.get('name')} has mass {text!r}, not a number") \
                from None
        if not (value > 0.0 or (value == 0.0 and link.get("name") not in LINKS)):
            raise ModelError(f"the model {model.name}: link {link.get('name')} has mass {value!r} kg; every "
                             "link's mass must be positive (a massless frame-holder, not one of the seven links, "
                             "may have 0)")


def _check_inertia(model: RobotModel, link) -> None:
    """ModelError naming the link when its rotational inertia is not physical: a negative moment, or one
    larger than the other two together (Drake's parser only warns, and walks it)."""
    inertia = link.find("inertial/inertia")
    if inertia is None:
        return
    names = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    try:
        if model.format == "urdf":
            values = {n: float(inertia.get(n, "0")) for n in names}
        else:
            values = {n: float(getattr(inertia.find(n), "text", None) or 0.0) for n in names}
    except ValueError:
        raise ModelError(f"the model {model.name}: link {link.get('name')}'s inertia is not a set of numbers") \
            from None
    matrix = np.array([[values["ixx"], values["ixy"], values["ixz"]], [values["ixy"], values["iyy"], values["iyz"]],
                       [values["ixz"], values["iyz"], values["izz"]]])
    moments = np.linalg.eigvalsh(matrix)
    tolerance = 1e-12 * max(1.0, float(np.max(np.abs(moments))))
    if not np.all(np.isfinite(matrix)) or moments[0] < -tolerance or \
            2.0 * float(np.max(moments)) > float(np.sum(moments)) + tolerance:
        shown = ", ".join(f"{n} {values[n]:g}" for n in names)
        raise ModelError(f"the model {model.name}: link {link.get('name')} has the inertia ({shown}) kg*m^2, which no "
                         "body has (principal moments must be >= 0 and each at most the sum of the other two)")


def _check_joint_limits(plant: MultibodyPlant) -> None:
    """ModelError naming the joint unless each leg joint has finite position limits: the gait relies on the
    knee's stop at full extension and on the hips' and ankles' ranges."""
    for name in JOINT_NAMES:
        joint = plant.GetJointByName(name)
        lower, upper = float(joint.position_lower_limits()[0]), float(joint.position_upper_limits()[0])
        if not (math.isfinite(lower) and math.isfinite(upper)):
            raise ModelError(f"joint {name} has the position limits [{lower:g}, {upper:g}] rad; the toolkit's "
                             "controller relies on finite limits for every leg joint (the knee's stop at full "
                             "extension, the hips' and ankles' ranges): give it <limit lower=... upper=...>")


LINKS = ("torso", *(f"{leg}_{link}" for leg in LEGS for link in ("thigh", "shank", "foot")))


def composite(plant: MultibodyPlant, name: str) -> tuple[float, tuple[float, float]]:
    """The mass (kg) and centre of mass (x, z in the link's frame, m) of the link `name` with every body welded
    to it (a sensor box bolted to the torso counts in the torso): the planar kinematics knows the seven links,
    and what hangs on them rigidly moves with them. ModelError naming a body that moves on a joint of its own."""
    link = plant.GetBodyByName(name)
    riders = [b for b in plant.GetBodiesWeldedTo(link)
              if b.name() not in LINKS and b.index() != plant.world_body().index()
              and math.isfinite(float(b.default_mass())) and float(b.default_mass()) >= 0.0]
    if not riders:  # the link alone: its own numbers, bit for bit
        return float(link.default_mass()), _xz(link.default_com())
    context = plant.CreateDefaultContext()
    total = float(link.default_mass())
    moment = total * np.asarray(link.default_com())
    for body in riders:
        m = float(body.default_mass())
        X = plant.CalcRelativeTransform(context, link.body_frame(), body.body_frame())
        total += m
        moment = moment + m * X.multiply(body.default_com())
    return total, _xz(moment / total)


def _check_every_body_rides_a_link(plant: MultibodyPlant) -> None:
    """ModelError naming a body that is neither one of the seven links nor welded to one (or to the world)."""
    if not all(plant.HasBodyNamed(name) for name in LINKS):
        return  # link_masses_of names the missing link
    riding = {int(b.index()) for name in (*LINKS, plant.world_body().name())
              for b in plant.GetBodiesWeldedTo(plant.GetBodyByName(name))}  # welded to the world: the ground's
    for index in range(plant.num_bodies()):
        body = plant.get_body(BodyIndex(index))
        if index == int(plant.world_body().index()) or index in riding:
            continue
        raise ModelError(f"link {body.name()} moves on a joint of its own; the toolkit's planar kinematics knows "
                         f"the seven links {list(LINKS)} and bodies welded (fixed) to them")


def link_masses_of(plant: MultibodyPlant) -> LinkMasses:
    """The links' masses as the model file gives them; ModelError unless each is positive and the legs are
    mirror images (the controller's centre of mass takes one mass per link kind)."""
    for name in LINKS:
        if not plant.HasBodyNamed(name):
            raise ModelError(f"the model has no link named {name!r}; expected {list(LINKS)}")
        m = float(plant.GetBodyByName(name).default_mass())
        if not m > 0.0:
            raise ModelError(f"link {name} has mass {m!r} kg; every link's mass must be positive")

    def mass(name: str) -> float:
        return composite(plant, name)[0]

    legs = {leg: tuple(mass(f"{leg}_{link}") for link in ("thigh", "shank", "foot")) for leg in LEGS}
    if legs["left"] != legs["right"]:
        raise ModelError(f"the legs' masses differ (left thigh, shank, foot {legs['left']} kg, right "
                         f"{legs['right']} kg); the toolkit assumes mirror-image legs")
    return link_masses(mass("torso"), *legs["left"])


# The joints' axes in the shipped model (the kinematics' sign conventions follow from them).
JOINT_AXES = {"hip": (0.0, -1.0, 0.0), "knee": (0.0, 1.0, 0.0), "ankle": (0.0, -1.0, 0.0)}


def _xz(v) -> tuple[float, float]:
    return float(v[0]), float(v[2])


def _leg_geometry(plant: MultibodyPlant, scene_graph: SceneGraph, leg: str) -> dict[str, tuple]:
    """One leg's joint positions, centres of mass and foot spheres (x, z in the parent link's frame, m)."""
    out: dict[str, tuple] = {}
    for joint in JOINTS_OF_A_LEG:
        j = plant.GetJointByName(f"{leg}_{joint}")
        if j.type_name() != "revolute":
            raise ModelError(f"joint {leg}_{joint} is a {j.type_name()} joint; expected a revolute joint")
        axis = tuple(float(a) for a in j.revolute_axis())
        if max(abs(a - b) for a, b in zip(axis, JOINT_AXES[joint])) > 1e-9:
            raise ModelError(f"joint {leg}_{joint} turns about {list(axis)}; the toolkit expects "
                             f"{list(JOINT_AXES[joint])} (models/biped.urdf's sign conventions)")
        for side, frame in (("parent", j.frame_on_parent()), ("child", j.frame_on_child())):
            pose = frame.GetFixedPoseInBodyFrame()
            if not pose.rotation().IsNearlyIdentity(1e-12):
                raise ModelError(f"joint {leg}_{joint}'s frame on its {side} link is rotated; the toolkit expects "
                                 "unrotated joint frames (a link's angle is its joint angles' sum)")
            if side == "child" and np.max(np.abs(pose.translation())) > 1e-12:
                raise ModelError(f"joint {leg}_{joint} is not at its child link's origin "
                                 f"({pose.translation().tolist()}); put the link's frame at the joint")
        out[joint] = _xz(j.frame_on_parent().GetFixedPoseInBodyFrame().translation())
    for link in ("thigh", "shank", "foot"):
        out[f"{link}_com"] = composite(plant, f"{leg}_{link}")[1]
    inspector = scene_graph.model_inspector()
    spheres = []
    for geometry in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(f"{leg}_foot")):
        shape = inspector.GetShape(geometry)
        if not isinstance(shape, Sphere):
            raise ModelError(f"{leg}_foot collides through a {type(shape).__name__}; the controller's "
                             "kinematics expects a sphere at the heel and one at the toe")
        x, z = _xz(inspector.GetPoseInFrame(geometry).translation())
        radius = float(shape.radius())
        spheres.append((x, z - radius, radius))  # the sphere's lowest point with the foot flat: the sole
    if len(spheres) != 2:
        raise ModelError(f"{leg}_foot has {len(spheres)} collision spheres; expected two (a heel and a toe)")
    out["heel"], out["toe"] = sorted(spheres)
    return out


_GEOMETRY_NAMES = {"hip": "hip position in the torso frame (x, z)", "knee": "knee position in the thigh frame",
                   "ankle": "ankle position in the shank frame", "thigh_com": "thigh centre of mass",
                   "shank_com": "shank centre of mass", "foot_com": "foot centre of mass",
                   "heel": "heel sphere (x, sole z, radius)", "toe": "toe sphere (x, sole z, radius)"}


def body_of(plant: MultibodyPlant, scene_graph: SceneGraph, tolerance_m: float = 1e-9) -> np.ndarray:
    """The controller's body (kinematics.BODY) read from a finalized plant: joint positions, centres of mass
    and foot contact spheres in their links' frames (x, z: the sagittal plane), and the masses. ModelError,
    naming what and both values, when the legs differ, the gravity is not params.GRAVITY_MPS2 (C_mt divides by
    m g d with it), or the planar kinematics does not reproduce the plant (checked at one configuration)."""
    gravity = plant.gravity_field().gravity_vector()
    if np.max(np.abs(gravity - [0.0, 0.0, -GRAVITY_MPS2])) > tolerance_m:
        raise ModelError(f"the model's gravity is {gravity.tolist()} m/s^2; the toolkit uses "
                         f"[0, 0, -{GRAVITY_MPS2}] (C_mt divides by m g d with it)")
    masses = link_masses_of(plant)
    _check_joint_limits(plant)
    legs = {leg: _leg_geometry(plant, scene_graph, leg) for leg in LEGS}
    for key, what in _GEOMETRY_NAMES.items():
        left, right = legs["left"][key], legs["right"][key]
        if max(abs(a - b) for a, b in zip(left, right)) > tolerance_m:
            raise ModelError(f"the legs differ: the left {what} is {np.round(left, 6).tolist()} m, the right "
                             f"{np.round(right, 6).tolist()} m; the toolkit assumes mirror-image legs")
    g = legs["left"]
    body = body_vector(masses, hip=g["hip"], torso_com=composite(plant, "torso")[1],
                       knee=g["knee"], thigh_com=g["thigh_com"], ankle=g["ankle"], shank_com=g["shank_com"],
                       foot_com=g["foot_com"], heel=g["heel"], toe=g["toe"], efforts=motor_limits(plant))
    _check_body(plant, body, tolerance_m)
    return body


def _check_body(plant: MultibodyPlant, body: np.ndarray, tolerance_m: float) -> None:
    """ModelError unless the planar kinematics of `body` puts the knees, ankles and the centre of mass where the
    plant does, at one configuration away from every symmetry."""
    q = np.array([0.3, 0.9, 0.1, 0.4, 0.7, -0.2, -0.3, 0.2, 0.25])
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    points = {leg: leg_points_k(body, q[0], q[1], q[2], *q[3 + 3 * i: 6 + 3 * i]) for i, leg in enumerate(LEGS)}
    for leg in LEGS:
        for joint, slot in (("knee", 0), ("ankle", 2)):
            frame = plant.GetJointByName(f"{leg}_{joint}").frame_on_child()
            got = _xz(frame.CalcPoseInWorld(context).translation())
            want = points[leg][slot], points[leg][slot + 1]
            if max(abs(a - b) for a, b in zip(got, want)) > tolerance_m:
                raise ModelError(f"the model's {leg} {joint} is at {np.round(got, 6).tolist()} m where the planar "
                                 f"kinematics puts it at {np.round(want, 6).tolist()} m: the base must be planar "
                                 "in x-z with the torso's pitch about -y, as in models/biped.urdf")
    com = _xz(plant.CalcCenterOfMassPositionInWorld(context))
    want = center_of_mass_k(body, q[0], q[1], q[2], points["left"], points["right"])
    if max(abs(a - b) for a, b in zip(com, want)) > tolerance_m:
        raise ModelError(f"the model's centre of mass is at {np.round(com, 6).tolist()} m where the planar "
                         f"kinematics puts it at {np.round(want, 6).tolist()} m")


def effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Actuator torque limits (N*m) in JOINT_NAMES order, as read from the model file."""
    return np.array([actuator_of(plant, n).effort_limit() for n in JOINT_NAMES])


def motor_limits(plant: MultibodyPlant) -> tuple[float, float, float]:
    """The hip, knee and ankle motors' torque limits (N*m) of the model: the controller clips its torques to
    them, so the torque it counts the work of is the torque the plant applies (Drake clamps the actuation to
    these limits). ModelError naming the motor unless each is finite and positive and the legs agree."""
    limits = dict(zip(JOINT_NAMES, effort_limits(plant)))
    for name, value in limits.items():
        if not (math.isfinite(value) and value > 0.0):
            raise ModelError(f"the motor {name}_motor has the effort limit {float(value)!r} N*m; the controller needs a "
                             "finite positive torque limit for every motor (URDF <limit effort=...>)")
    out = []
    for joint in JOINTS_OF_A_LEG:
        left, right = limits[f"left_{joint}"], limits[f"right_{joint}"]
        if left != right:
            raise ModelError(f"the legs differ: the left {joint}'s effort limit is {left:g} N*m, the right "
                             f"{right:g} N*m; the toolkit assumes mirror-image legs")
        out.append(float(left))
    return tuple(out)


def build_plant(ground: Ground | None = None, time_step_s: float = 1e-3,
                model: RobotModel | None = None, contact: ContactParams | None = None) -> MultibodyPlant:
    """A finalized plant in its own diagram builder, for inspection and tests."""
    builder = DiagramBuilder()
    return add_biped(builder, ground or Ground(), time_step_s, model, contact=contact).plant


_BODIES: dict[str | None, np.ndarray] = {}


def body_of_model(model: RobotModel | None = None) -> np.ndarray:
    """The body (kinematics.BODY) of `model` (None: the shipped robot), read from its plant once per model
    and kept; ModelError as `add_biped`. A read-only array."""
    if model is not None and not isinstance(model, RobotModel):
        raise ParameterError(f"body_of_model: model must be a RobotModel (RobotModel.from_file(path)) or None for "
                             f"the shipped robot, got {type(model).__name__} {model!r}")
    key = None if model is None else model.sha256
    if key not in _BODIES:
        handles = add_biped(DiagramBuilder(), Ground(), 1e-3, model)
        body = handles.body
        body.flags.writeable = False
        _BODIES[key] = body
    return _BODIES[key]
