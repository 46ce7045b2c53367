"""Planar forward kinematics of the biped, in plain Python for the controller's hot path.

Sign conventions (see models/biped.urdf): x forward, z up, every angle counter-clockwise in the x-z view.
The torso pitch is positive when leaning back; a thigh's world angle is pitch + hip and is positive when
the foot is ahead of the hip; the shank's is thigh - knee; the foot's is shank + ankle.
Lengths, centres of mass and the foot's contact points are the model's: `model.check_geometry` compares
the constants below with the plant when a diagram is built and refuses a model that differs. Masses are
read from the plant (`model.link_masses`) and passed in; Table I's are only the default of the functions.
`tests/test_kinematics.py` checks these functions against MultibodyPlant.
"""

from __future__ import annotations

import math
from typing import NamedTuple

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


def leg_points(x: float, z: float, pitch: float, hip: float, knee: float, ankle: float) -> LegPoints:
    """Points of one leg for hip position (x, z), torso pitch and the leg's joint angles (rad)."""
    thigh = pitch + hip
    shank = thigh - knee
    foot = shank + ankle
    kx = x + THIGH_M * math.sin(thigh)
    kz = z - THIGH_M * math.cos(thigh)
    ax = kx + SHANK_M * math.sin(shank)
    az = kz - SHANK_M * math.cos(shank)
    c, s = math.cos(foot), math.sin(foot)
    # Foot frame axes in the world: ex = (c, s), ez = (-s, c). Sphere bottoms are one radius below.
    hx = ax + HEEL_X_M * c - _SPHERE_Z * s
    hz = az + HEEL_X_M * s + _SPHERE_Z * c - CONTACT_RADIUS_M
    tx = ax + TOE_X_M * c - _SPHERE_Z * s
    tz = az + TOE_X_M * s + _SPHERE_Z * c - CONTACT_RADIUS_M
    return LegPoints(kx, kz, ax, az, hx, hz, tx, tz, thigh, shank, foot)


def center_of_mass(q, masses: LinkMasses = TABLE_I_MASSES) -> tuple[float, float]:
    """Whole-body centre of mass (x, z) for q = (x, z, pitch, hipL, kneeL, ankleL, hipR, kneeR, ankleR)."""
    x, z, pitch = q[0], q[1], q[2]
    return center_of_mass_from_legs(
        x, z, pitch, leg_points(x, z, pitch, q[3], q[4], q[5]), leg_points(x, z, pitch, q[6], q[7], q[8]), masses
    )


def center_of_mass_from_legs(x: float, z: float, pitch: float, left: LegPoints, right: LegPoints,
                             masses: LinkMasses = TABLE_I_MASSES) -> tuple[float, float]:
    """Centre of mass from the hip position, torso pitch and both legs' points (already computed)."""
    mt, mth, msh, mft, total = masses
    sx = mt * (x - 0.5 * TORSO_M * math.sin(pitch))
    sz = mt * (z + 0.5 * TORSO_M * math.cos(pitch))
    for p in (left, right):
        sx += mth * 0.5 * (x + p.knee_x) + msh * 0.5 * (p.knee_x + p.ankle_x)
        sz += mth * 0.5 * (z + p.knee_z) + msh * 0.5 * (p.knee_z + p.ankle_z)
        c, s = math.cos(p.foot_angle), math.sin(p.foot_angle)
        sx += mft * (p.ankle_x + FOOT_COM_M[0] * c - FOOT_COM_M[1] * s)
        sz += mft * (p.ankle_z + FOOT_COM_M[0] * s + FOOT_COM_M[1] * c)
    return sx / total, sz / total
