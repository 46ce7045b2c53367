"""The shipped URDF written as SDFormat, for the tests that check an SDFormat model walks as the URDF does.

SDFormat has no planar joint: Drake's `<drake:joint type="planar">` moves in its frames' x-y plane, so both of
its frames are turned +90 deg about x (the plane becomes x-z, the rotation about -y, as the URDF's planar joint
about -y), the parent frame on a massless link welded to the world. Actuators come from the joints' effort
limits, named after the joints."""

from __future__ import annotations

import xml.etree.ElementTree as ET

TURN = "0 0 0 1.5707963267948966 0 0"


def urdf_to_sdf(text: str) -> str:
    root = ET.fromstring(text)
    joints = root.findall("joint")
    placed = {j.find("child").get("link"): (j.find("parent").get("link"), j.find("origin").get("xyz")
                                            if j.find("origin") is not None else "0 0 0") for j in joints}
    out = ['<?xml version="1.0"?>', '<sdf version="1.9" xmlns:drake="http://drake.mit.edu">', '<model name="biped">',
           f'<link name="base_plane"><pose>{TURN}</pose><inertial><mass>0</mass><inertia><ixx>0</ixx><iyy>0</iyy>'
           '<izz>0</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>',
           '<joint name="base_anchor" type="fixed"><parent>world</parent><child>base_plane</child></joint>']
    for link in root.findall("link"):
        name = link.get("name")
        if name == "world":
            continue
        parent, xyz = placed[name]
        relative = "" if parent == "world" else f' relative_to="{parent}"'
        out.append(f'<link name="{name}"><pose{relative}>{xyz} 0 0 0</pose>')
        inertial = link.find("inertial")
        i = inertial.find("inertia")
        out.append(f'<inertial><pose>{inertial.find("origin").get("xyz")} 0 0 0</pose>'
                   f'<mass>{inertial.find("mass").get("value")}</mass><inertia>'
                   + "".join(f"<{k}>{i.get(k)}</{k}>" for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"))
                   + "</inertia></inertial>")
        for c in link.findall("collision"):
            radius = c.find("geometry/sphere").get("radius")
            out.append(f'<collision name="{c.get("name")}"><pose>{c.find("origin").get("xyz")} 0 0 0</pose>'
                       f'<geometry><sphere><radius>{radius}</radius></sphere></geometry><drake:proximity_properties>'
                       '<drake:mu_dynamic>1.0</drake:mu_dynamic><drake:mu_static>1.0</drake:mu_static>'
                       '</drake:proximity_properties></collision>')
        out.append("</link>")
    out.append(f'<frame name="torso_plane" attached_to="torso"><pose>{TURN}</pose></frame>')
    for j in joints:
        if j.get("type") == "planar":
            out.append(f'<drake:joint name="{j.get("name")}" type="planar"><drake:parent>base_plane</drake:parent>'
                       '<drake:child>torso_plane</drake:child><drake:damping>0 0 0</drake:damping></drake:joint>')
            continue
        limit = j.find("limit")
        out.append(f'<joint name="{j.get("name")}" type="{j.get("type")}"><parent>{j.find("parent").get("link")}'
                   f'</parent><child>{j.find("child").get("link")}</child><axis><xyz>{j.find("axis").get("xyz")}</xyz>'
                   + "<limit>" + "".join(f"<{k}>{limit.get(k)}</{k}>" for k in ("lower", "upper", "effort", "velocity"))
                   + "</limit></axis></joint>")
    out.append("</model></sdf>")
    return "\n".join(out) + "\n"
