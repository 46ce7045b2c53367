"""Planar forward kinematics of the biped, in plain Python for the controller's hot path.

Sign conventions (see models/biped.urdf): x forward, z up, every angle counter-clockwise in the x-z view.
The torso pitch is positive when leaning back; a thigh's world angle is pitch + hip and is positive when
the foot is ahead of the hip; the shank's is thigh - knee; the foot's is shank + ankle.
Lengths, centres of mass and the foot's contact points are the model's: `model.check_geometry` compares
the constants below with the plant when a diagram is built and refuses a model that differs. Masses are
read from the plant (`model.link_masses`) and passed in; Table I's are only the default of the functions.
`tests/test_kinematics.py` checks these functions against MultibodyPlant.

The controller's compiled update calls the kernels (`*_k`) with the body as one vector (`BODY`,
`body_vector`); the functions below them are the same kinematics for Python callers.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from drake_biped.jit import njit
from drake_biped.layout import Field, VectorLayout
from drake_biped.paper import TABLE_I_LENGTHS_M, TABLE_I_MASSES_KG
from drake_biped.params import CONTACT_RADIUS_M, HEEL_X_M, SOLE_DEPTH_M, TOE_X_M

THIGH_M = TABLE_I_LENGTHS_M["thigh"]
SHANK_M = TABLE_I_LENGTHS_M["shank"]
TORSO_M = TABLE_I_LENGTHS_M["torso"]
# Contact spheres: centre one radius above the sole, at the heel and at the toe.
_SPHERE_Z = -SOLE_DEPTH_M + CONTACT_RADIUS_M
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
    """World (x, z) of a leg's knee, ankle, and heel/toe contact points (lowest point of each sphere)."""

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


# The body as the kernels take it: lengths and contact points (m), masses (kg).
BODY = VectorLayout("body", (
    Field("thigh_m", 1, "hip to knee"),
    Field("shank_m", 1, "knee to ankle"),
    Field("torso_m", 1, "hip to the torso's top (its centre of mass halfway)"),
    Field("heel_x_m", 1, "heel sphere centre, x in the ankle frame"),
    Field("toe_x_m", 1, "toe sphere centre, x in the ankle frame"),
    Field("sphere_z_m", 1, "contact spheres' centres, z in the ankle frame"),
    Field("contact_radius_m", 1, "contact spheres' radius"),
    Field("foot_com_x_m", 1, "foot centre of mass, x in the ankle frame"),
    Field("foot_com_z_m", 1, "foot centre of mass, z in the ankle frame"),
    Field("torso_kg", 1, "torso mass"),
    Field("thigh_kg", 1, "one thigh's mass"),
    Field("shank_kg", 1, "one shank's mass"),
    Field("foot_kg", 1, "one foot's mass"),
    Field("total_kg", 1, "the whole robot's mass"),
))
_b = BODY.offset
B_THIGH, B_SHANK, B_TORSO, B_HEEL_X, B_TOE_X = _b("thigh_m"), _b("shank_m"), _b("torso_m"), _b("heel_x_m"), _b("toe_x_m")
B_SPHERE_Z, B_RADIUS, B_FOOT_COM_X, B_FOOT_COM_Z = _b("sphere_z_m"), _b("contact_radius_m"), _b("foot_com_x_m"), \
    _b("foot_com_z_m")
B_M_TORSO, B_M_THIGH, B_M_SHANK, B_M_FOOT, B_M_TOTAL = _b("torso_kg"), _b("thigh_kg"), _b("shank_kg"), _b("foot_kg"), \
    _b("total_kg")
del _b


def body_vector(masses: LinkMasses = TABLE_I_MASSES) -> np.ndarray:
    """The body (BODY layout): this module's lengths and contact points with the given masses."""
    return np.array([THIGH_M, SHANK_M, TORSO_M, HEEL_X_M, TOE_X_M, _SPHERE_Z, CONTACT_RADIUS_M, FOOT_COM_M[0],
                     FOOT_COM_M[1], *masses], dtype=float)


TABLE_I_BODY = body_vector()
TABLE_I_BODY.flags.writeable = False


@njit
def leg_points_k(body, x: float, z: float, pitch: float, hip: float, knee: float, ankle: float) -> tuple:
    """leg_points() as a tuple, for the body vector `body` (BODY)."""
    thigh = pitch + hip
    shank = thigh - knee
    foot = shank + ankle
    kx = x + body[B_THIGH] * math.sin(thigh)
    kz = z - body[B_THIGH] * math.cos(thigh)
    ax = kx + body[B_SHANK] * math.sin(shank)
    az = kz - body[B_SHANK] * math.cos(shank)
    c, s = math.cos(foot), math.sin(foot)
    # Foot frame axes in the world: ex = (c, s), ez = (-s, c). Sphere bottoms are one radius below.
    heel, toe, sphere_z, radius = body[B_HEEL_X], body[B_TOE_X], body[B_SPHERE_Z], body[B_RADIUS]
    hx = ax + heel * c - sphere_z * s
    hz = az + heel * s + sphere_z * c - radius
    tx = ax + toe * c - sphere_z * s
    tz = az + toe * s + sphere_z * c - radius
    return (kx, kz, ax, az, hx, hz, tx, tz, thigh, shank, foot)


@njit
def center_of_mass_k(body, x: float, z: float, pitch: float, left: tuple, right: tuple) -> tuple:
    """center_of_mass_from_legs() for leg_points_k's tuples and the body vector `body` (BODY)."""
    mt, mth, msh, mft, total = body[B_M_TORSO], body[B_M_THIGH], body[B_M_SHANK], body[B_M_FOOT], body[B_M_TOTAL]
    sx = mt * (x - 0.5 * body[B_TORSO] * math.sin(pitch))
    sz = mt * (z + 0.5 * body[B_TORSO] * math.cos(pitch))
    fx, fz = body[B_FOOT_COM_X], body[B_FOOT_COM_Z]
    for p in (left, right):
        # p: knee x, z (0, 1), ankle x, z (2, 3), foot angle (10)
        sx += mth * 0.5 * (x + p[0]) + msh * 0.5 * (p[0] + p[2])
        sz += mth * 0.5 * (z + p[1]) + msh * 0.5 * (p[1] + p[3])
        c, s = math.cos(p[10]), math.sin(p[10])
        sx += mft * (p[2] + fx * c - fz * s)
        sz += mft * (p[3] + fx * s + fz * c)
    return sx / total, sz / total


def _body(masses: LinkMasses) -> np.ndarray:
    return TABLE_I_BODY if masses == TABLE_I_MASSES else body_vector(masses)


def leg_points(x: float, z: float, pitch: float, hip: float, knee: float, ankle: float) -> LegPoints:
    """Points of one leg for hip position (x, z), torso pitch and the leg's joint angles (rad)."""
    return LegPoints(*leg_points_k(TABLE_I_BODY, float(x), float(z), float(pitch), float(hip), float(knee),
                                   float(ankle)))


def center_of_mass(q, masses: LinkMasses = TABLE_I_MASSES) -> tuple[float, float]:
    """Whole-body centre of mass (x, z) for q = (x, z, pitch, hipL, kneeL, ankleL, hipR, kneeR, ankleR)."""
    x, z, pitch = q[0], q[1], q[2]
    return center_of_mass_from_legs(
        x, z, pitch, leg_points(x, z, pitch, q[3], q[4], q[5]), leg_points(x, z, pitch, q[6], q[7], q[8]), masses
    )


def center_of_mass_from_legs(x: float, z: float, pitch: float, left: LegPoints, right: LegPoints,
                             masses: LinkMasses = TABLE_I_MASSES) -> tuple[float, float]:
    """Centre of mass from the hip position, torso pitch and both legs' points (already computed)."""
    return center_of_mass_k(_body(masses), float(x), float(z), float(pitch), tuple(map(float, left)),
                            tuple(map(float, right)))
