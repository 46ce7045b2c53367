"""Planar forward kinematics of the biped, compiled for the controller's hot path.

Sign conventions (see models/biped.urdf): x forward, z up, every angle counter-clockwise in the x-z view.
The torso pitch is positive when leaning back; a thigh's world angle is pitch + hip and is positive when
the foot is ahead of the hip; the shank's is thigh - knee; the foot's is shank + ankle.
The body (joint positions, centres of mass, contact spheres, masses) is the model's: `model.body_of` reads
it from the plant when a diagram is built, for the shipped model and a user's alike. The constants below are
the shipped model's (Table I), the functions' default body. `tests/test_kinematics.py` checks these
functions against MultibodyPlant.

The controller's compiled update calls the kernels (`*_k`) with the body as one vector (`BODY`,
`body_vector`); the functions below them are the same kinematics for Python callers.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from drake_biped.jit import njit
from drake_biped.layout import Field, VectorLayout
from drake_biped.paper import HIP_LIMIT_RAD, TABLE_I_LENGTHS_M, TABLE_I_MASSES_KG
from drake_biped.params import CONTACT_RADIUS_M, EFFORT_LIMITS_NM, HEEL_X_M, SOLE_DEPTH_M, TOE_X_M

THIGH_M = TABLE_I_LENGTHS_M["thigh"]
SHANK_M = TABLE_I_LENGTHS_M["shank"]
TORSO_M = TABLE_I_LENGTHS_M["torso"]
FOOT_COM_M = (0.03, -0.015)  # foot centre of mass in the ankle frame (x, z; m)


class LinkMasses(NamedTuple):
    """Masses (kg) of the torso and of one leg's thigh, shank and foot (the legs are mirror images), and
    the whole robot's."""

    torso: float
    thigh: float
    shank: float
    foot: float
    total: float


def link_masses(torso: float, thigh: float, shank: float, foot: float) -> LinkMasses:
    return LinkMasses(torso, thigh, shank, foot, torso + 2 * (thigh + shank + foot))


TABLE_I_MASSES = link_masses(*(TABLE_I_MASSES_KG[k] for k in ("torso", "thigh", "shank", "foot")))


class LegPoints(NamedTuple):
    """World (x, z) of a leg's knee, ankle, and heel/toe contact points (lowest point of each sphere), the
    segments' world angles, and the hip joint's (x, z)."""

    knee_x: float
    knee_z: float
    ankle_x: float
    ankle_z: float
    heel_x: float
    heel_z: float
    toe_x: float
    toe_z: float
    thigh_angle: float
    shank_angle: float
    foot_angle: float
    hip_x: float
    hip_z: float


# The body as the kernels take it: where each joint, centre of mass and contact sphere sits in its link's
# frame (m; x forward, z up, the sagittal plane), and the masses (kg). A link's centre of mass is kept as the
# fraction of the way from its proximal joint to its distal one plus an offset (in the link's frame) from that
# point, so that a centre of mass on the segment costs no rotation.
BODY = VectorLayout("body", (
    Field("hip_x_m", 1, "hip joint, x in the torso frame"),
    Field("hip_z_m", 1, "hip joint, z in the torso frame"),
    Field("torso_com_x_m", 1, "torso centre of mass, x in the torso frame"),
    Field("torso_com_z_m", 1, "torso centre of mass, z in the torso frame"),
    Field("knee_x_m", 1, "knee joint, x in the thigh frame"),
    Field("knee_z_m", 1, "knee joint, z in the thigh frame (minus the thigh's length)"),
    Field("thigh_com_fraction", 1, "thigh centre of mass: the fraction of the way from hip to knee"),
    Field("thigh_com_offset_x_m", 1, "thigh centre of mass: x offset from that point, in the thigh frame"),
    Field("thigh_com_offset_z_m", 1, "thigh centre of mass: z offset from that point, in the thigh frame"),
    Field("ankle_x_m", 1, "ankle joint, x in the shank frame"),
    Field("ankle_z_m", 1, "ankle joint, z in the shank frame (minus the shank's length)"),
    Field("shank_com_fraction", 1, "shank centre of mass: the fraction of the way from knee to ankle"),
    Field("shank_com_offset_x_m", 1, "shank centre of mass: x offset from that point, in the shank frame"),
    Field("shank_com_offset_z_m", 1, "shank centre of mass: z offset from that point, in the shank frame"),
    Field("foot_com_x_m", 1, "foot centre of mass, x in the ankle frame"),
    Field("foot_com_z_m", 1, "foot centre of mass, z in the ankle frame"),
    Field("heel_x_m", 1, "heel sphere centre, x in the ankle frame"),
    Field("heel_sole_z_m", 1, "heel sphere's lowest point with the foot flat, z in the ankle frame (the sole)"),
    Field("heel_radius_m", 1, "heel sphere radius (its centre is this far above the sole)"),
    Field("toe_x_m", 1, "toe sphere centre, x in the ankle frame"),
    Field("toe_sole_z_m", 1, "toe sphere's lowest point with the foot flat, z in the ankle frame (the sole)"),
    Field("toe_radius_m", 1, "toe sphere radius"),
    Field("torso_kg", 1, "torso mass"),
    Field("thigh_kg", 1, "one thigh's mass"),
    Field("shank_kg", 1, "one shank's mass"),
    Field("foot_kg", 1, "one foot's mass"),
    Field("total_kg", 1, "the whole robot's mass"),
    Field("hip_effort_nm", 1, "the hip motors' torque limit (the model's effort limit)"),
    Field("knee_effort_nm", 1, "the knee motors' torque limit"),
    Field("ankle_effort_nm", 1, "the ankle motors' torque limit"),
))
_b = BODY.offset
B_HIP_X, B_HIP_Z, B_TORSO_COM_X, B_TORSO_COM_Z = _b("hip_x_m"), _b("hip_z_m"), _b("torso_com_x_m"), _b("torso_com_z_m")
B_KNEE_X, B_KNEE_Z, B_THIGH_F, B_THIGH_OX, B_THIGH_OZ = (_b(n) for n in (
    "knee_x_m", "knee_z_m", "thigh_com_fraction", "thigh_com_offset_x_m", "thigh_com_offset_z_m"))
B_ANKLE_X, B_ANKLE_Z, B_SHANK_F, B_SHANK_OX, B_SHANK_OZ = (_b(n) for n in (
    "ankle_x_m", "ankle_z_m", "shank_com_fraction", "shank_com_offset_x_m", "shank_com_offset_z_m"))
B_FOOT_COM_X, B_FOOT_COM_Z = _b("foot_com_x_m"), _b("foot_com_z_m")
B_HEEL_X, B_HEEL_SOLE, B_HEEL_R, B_TOE_X, B_TOE_SOLE, B_TOE_R = (_b(n) for n in (
    "heel_x_m", "heel_sole_z_m", "heel_radius_m", "toe_x_m", "toe_sole_z_m", "toe_radius_m"))
B_M_TORSO, B_M_THIGH, B_M_SHANK, B_M_FOOT, B_M_TOTAL = _b("torso_kg"), _b("thigh_kg"), _b("shank_kg"), _b("foot_kg"), \
    _b("total_kg")
B_HIP_EFFORT, B_KNEE_EFFORT, B_ANKLE_EFFORT = _b("hip_effort_nm"), _b("knee_effort_nm"), _b("ankle_effort_nm")
del _b


def longest_step_m(body: np.ndarray, hip_limit_rad: float = HIP_LIMIT_RAD) -> float:
    """An upper bound on a step's length (m): the ankles of two straight legs whose thighs are each within the
    hips' range of the torso (Table I: +-51 deg), so at most 2 x 51 deg apart. The centre of mass advances by
    at most n times it, plus a leg's length, by its n-th touchdown: a shorter walk may end before it."""
    return float(2.0 * leg_length_m(body) * math.sin(min(hip_limit_rad, 0.5 * math.pi)))


def leg_length_m(body: np.ndarray) -> float:
    """Hip to ankle with the knee straight (m)."""
    return float(math.hypot(body[B_KNEE_X], body[B_KNEE_Z]) + math.hypot(body[B_ANKLE_X], body[B_ANKLE_Z]))


def com_on_segment(com_xz, joint_xz) -> tuple[float, float, float]:
    """A centre of mass at `com_xz` in a link's frame whose distal joint is at `joint_xz`, as (fraction of
    the way from the link's origin to the joint, x offset, z offset from that point)."""
    (cx, cz), (jx, jz) = (float(v) for v in com_xz), (float(v) for v in joint_xz)
    f = (cx * jx + cz * jz) / (jx * jx + jz * jz)
    return f, cx - f * jx, cz - f * jz


def body_vector(masses: LinkMasses = TABLE_I_MASSES, *, hip=(0.0, 0.0), torso_com=(0.0, 0.5 * TORSO_M),
                knee=(0.0, -THIGH_M), thigh_com=(0.0, -0.5 * THIGH_M), ankle=(0.0, -SHANK_M),
                shank_com=(0.0, -0.5 * SHANK_M), foot_com=FOOT_COM_M, heel=(HEEL_X_M, -SOLE_DEPTH_M, CONTACT_RADIUS_M),
                toe=(TOE_X_M, -SOLE_DEPTH_M, CONTACT_RADIUS_M),
                efforts=(EFFORT_LIMITS_NM["hip"], EFFORT_LIMITS_NM["knee"], EFFORT_LIMITS_NM["ankle"])) -> np.ndarray:
    """The body (BODY layout) from its joints, centres of mass and contact spheres (x, sole z, radius), each in
    its link's frame (defaults: the shipped model, Table I), the masses and the motors' torque limits (hip,
    knee, ankle; N*m). `model.body_of` reads them from a plant."""
    return np.array([*hip, *torso_com, *knee, *com_on_segment(thigh_com, knee), *ankle,
                     *com_on_segment(shank_com, ankle), *foot_com, *heel, *toe, *masses, *efforts], dtype=float)


TABLE_I_BODY = body_vector()
TABLE_I_BODY.flags.writeable = False


def masses_of(body) -> LinkMasses:
    """The link masses of a body vector."""
    return LinkMasses(*(float(body[i]) for i in (B_M_TORSO, B_M_THIGH, B_M_SHANK, B_M_FOOT, B_M_TOTAL)))


@njit
def leg_points_k(body, x: float, z: float, pitch: float, hip: float, knee: float, ankle: float) -> tuple:
    """leg_points() as a tuple, for the body vector `body` (BODY), with the hip joint's world (x, z) last."""
    thigh = pitch + hip
    shank = thigh - knee
    foot = shank + ankle
    cp, sp = math.cos(pitch), math.sin(pitch)
    hx = x + (body[B_HIP_X] * cp - body[B_HIP_Z] * sp)
    hz = z + (body[B_HIP_X] * sp + body[B_HIP_Z] * cp)
    c, s = math.cos(thigh), math.sin(thigh)
    kx = hx + (body[B_KNEE_X] * c - body[B_KNEE_Z] * s)
    kz = hz + (body[B_KNEE_X] * s + body[B_KNEE_Z] * c)
    c, s = math.cos(shank), math.sin(shank)
    ax = kx + (body[B_ANKLE_X] * c - body[B_ANKLE_Z] * s)
    az = kz + (body[B_ANKLE_X] * s + body[B_ANKLE_Z] * c)
    c, s = math.cos(foot), math.sin(foot)
    # Foot frame axes in the world: ex = (c, s), ez = (-s, c). Sphere bottoms are one radius below.
    heel, toe = body[B_HEEL_X], body[B_TOE_X]
    heel_z, toe_z = body[B_HEEL_SOLE] + body[B_HEEL_R], body[B_TOE_SOLE] + body[B_TOE_R]  # the centres
    ex = ax + heel * c - heel_z * s
    ez = az + heel * s + heel_z * c - body[B_HEEL_R]
    tx = ax + toe * c - toe_z * s
    tz = az + toe * s + toe_z * c - body[B_TOE_R]
    return (kx, kz, ax, az, ex, ez, tx, tz, thigh, shank, foot, hx, hz)


@njit
def _segment_com(f: float, ox: float, oz: float, angle: float, x0: float, z0: float, x1: float,
                 z1: float) -> tuple:
    c, s = math.cos(angle), math.sin(angle)
    g = 1.0 - f
    return g * x0 + f * x1 + (ox * c - oz * s), g * z0 + f * z1 + (ox * s + oz * c)


@njit
def center_of_mass_k(body, x: float, z: float, pitch: float, left: tuple, right: tuple) -> tuple:
    """center_of_mass_from_legs() for leg_points_k's tuples and the body vector `body` (BODY)."""
    mt, mth, msh, mft, total = body[B_M_TORSO], body[B_M_THIGH], body[B_M_SHANK], body[B_M_FOOT], body[B_M_TOTAL]
    cp, sp = math.cos(pitch), math.sin(pitch)
    sx = mt * (x + (body[B_TORSO_COM_X] * cp - body[B_TORSO_COM_Z] * sp))
    sz = mt * (z + (body[B_TORSO_COM_X] * sp + body[B_TORSO_COM_Z] * cp))
    fx, fz = body[B_FOOT_COM_X], body[B_FOOT_COM_Z]
    for p in (left, right):
        # p: knee x, z (0, 1), ankle x, z (2, 3), thigh, shank, foot angles (8, 9, 10), hip x, z (11, 12)
        thigh = _segment_com(body[B_THIGH_F], body[B_THIGH_OX], body[B_THIGH_OZ], p[8], p[11], p[12], p[0], p[1])
        shank = _segment_com(body[B_SHANK_F], body[B_SHANK_OX], body[B_SHANK_OZ], p[9], p[0], p[1], p[2], p[3])
        sx += mth * thigh[0] + msh * shank[0]
        sz += mth * thigh[1] + msh * shank[1]
        c, s = math.cos(p[10]), math.sin(p[10])
        sx += mft * (p[2] + fx * c - fz * s)
        sz += mft * (p[3] + fx * s + fz * c)
    return sx / total, sz / total


def leg_points(x: float, z: float, pitch: float, hip: float, knee: float, ankle: float,
               body=TABLE_I_BODY) -> LegPoints:
    """Points of one leg for the torso frame's position (x, z), torso pitch and the leg's joint angles (rad),
    of the body `body` (BODY; default the shipped model's)."""
    return LegPoints(*leg_points_k(body, float(x), float(z), float(pitch), float(hip), float(knee), float(ankle)))


def center_of_mass(q, body=TABLE_I_BODY) -> tuple[float, float]:
    """Whole-body centre of mass (x, z) for q = (x, z, pitch, hipL, kneeL, ankleL, hipR, kneeR, ankleR)."""
    x, z, pitch = q[0], q[1], q[2]
    return center_of_mass_from_legs(x, z, pitch, leg_points(x, z, pitch, q[3], q[4], q[5], body),
                                    leg_points(x, z, pitch, q[6], q[7], q[8], body), body)


def center_of_mass_from_legs(x: float, z: float, pitch: float, left: LegPoints, right: LegPoints,
                             body=TABLE_I_BODY) -> tuple[float, float]:
    """Centre of mass from the torso frame's position, torso pitch and both legs' points (already computed)."""
    return center_of_mass_k(body, float(x), float(z), float(pitch), tuple(map(float, left)),
                            tuple(map(float, right)))
