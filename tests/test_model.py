"""The plant read back from models/biped.urdf against Table I and the documented limits."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.model import JOINT_NAMES, ModelError, add_biped, build_plant, effort_limits
from drake_biped.paper import TABLE_I_LENGTHS_M, TABLE_I_MASSES_KG
from drake_biped.params import EFFORT_LIMITS_NM, TOTAL_MASS_KG, Ground


@pytest.fixture(scope="module")
def plant():
    return build_plant()


def test_total_mass_is_table_one(plant):
    ctx = plant.CreateDefaultContext()
    assert plant.CalcTotalMass(ctx) == pytest.approx(10.202, abs=1e-9)
    assert TOTAL_MASS_KG == pytest.approx(10.202, abs=1e-9)


@pytest.mark.parametrize("link", ["torso", "thigh", "shank", "foot"])
def test_link_masses(plant, link):
    names = [link] if link == "torso" else [f"left_{link}", f"right_{link}"]
    for name in names:
        assert plant.GetBodyByName(name).default_mass() == pytest.approx(TABLE_I_MASSES_KG[link])


def test_link_lengths_from_joint_offsets(plant):
    ctx = plant.CreateDefaultContext()
    knee = plant.GetJointByName("left_knee").frame_on_parent().CalcPoseInBodyFrame(ctx).translation()
    ankle = plant.GetJointByName("left_ankle").frame_on_parent().CalcPoseInBodyFrame(ctx).translation()
    assert np.linalg.norm(knee) == pytest.approx(TABLE_I_LENGTHS_M["thigh"])
    assert np.linalg.norm(ankle) == pytest.approx(TABLE_I_LENGTHS_M["shank"])
    # Torso: its centre of mass sits at half its length above the hip.
    assert plant.GetBodyByName("torso").default_com()[2] == pytest.approx(TABLE_I_LENGTHS_M["torso"] / 2)


def test_foot_contact_span(plant):
    from drake_biped.params import HEEL_X_M, TOE_X_M

    assert TOE_X_M - HEEL_X_M == pytest.approx(TABLE_I_LENGTHS_M["foot"])


def test_joint_limits(plant):
    for side in ("left", "right"):
        hip = plant.GetJointByName(f"{side}_hip")
        ankle = plant.GetJointByName(f"{side}_ankle")
        knee = plant.GetJointByName(f"{side}_knee")
        assert hip.position_lower_limits()[0] == pytest.approx(-math.radians(51), abs=1e-5)
        assert hip.position_upper_limits()[0] == pytest.approx(math.radians(51), abs=1e-5)
        assert ankle.position_lower_limits()[0] == pytest.approx(-math.radians(26), abs=1e-5)
        assert ankle.position_upper_limits()[0] == pytest.approx(math.radians(26), abs=1e-5)
        assert knee.position_lower_limits()[0] == 0.0  # no hyper-extension


def test_effort_limits_match_params(plant):
    limits = effort_limits(plant)
    expected = [EFFORT_LIMITS_NM[n.split("_")[1]] for n in JOINT_NAMES]
    np.testing.assert_allclose(limits, expected)


def test_only_feet_collide_with_a_heel_and_a_toe_each(plant):
    biped = plant.GetModelInstanceByName("biped")
    colliding = {plant.get_body(i).name(): len(plant.GetCollisionGeometriesForBody(plant.get_body(i)))
                 for i in plant.GetBodyIndices(biped)}
    assert {name: n for name, n in colliding.items() if n} == {"left_foot": 2, "right_foot": 2}


def test_malformed_model_is_a_clear_error():
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.params import RobotModel

    broken = RobotModel("broken.urdf", "<robot name='x'><link name='a'></robot>")
    with pytest.raises(ModelError, match="could not parse the model broken.urdf"):
        add_biped(DiagramBuilder(), Ground(), 1e-3, broken)


@pytest.mark.parametrize("ground, x, expected_height", [
    (Ground(), 3.0, 0.0),
    (Ground(slope_rad=0.05), 3.0, 3.0 * math.tan(0.05)),
    (Ground(slope_rad=0.02, level_length_m=2.0), 1.5, 0.0),
    (Ground(slope_rad=0.02, level_length_m=2.0), 4.0, 2.0 * math.tan(0.02)),
    (Ground(slope_rad=0.0349, level_length_m=2.0), 7.0, 5.0 * math.tan(0.0349)),
    (Ground(slope_rad=-0.05), 3.0, -3.0 * math.tan(0.05)),
])
def test_ground_geometry_matches_its_height_function(ground, x, expected_height):
    """SceneGraph's signed distance from a point above the ground equals the height above the surface
    (measured along the normal), and its gradient is the ground's normal, for level, tilted and
    level-then-slope ground."""
    from pydrake.systems.framework import DiagramBuilder

    builder = DiagramBuilder()
    handles = add_biped(builder, ground, 1e-3)
    diagram = builder.Build()
    ctx = diagram.CreateDefaultContext()
    query = handles.scene_graph.get_query_output_port().Eval(handles.scene_graph.GetMyContextFromRoot(ctx))
    z = 1.0
    inspector = query.inspector()
    near = min((d for d in query.ComputeSignedDistanceToPoint(np.array([x, 0.0, z]))
                if inspector.GetName(d.id_G).endswith(("ground", "ground_level", "ground_slope"))),
               key=lambda d: d.distance)
    slope = ground.slope_at(x)
    assert ground.height(x) == pytest.approx(expected_height)
    assert near.distance == pytest.approx((z - expected_height) * math.cos(slope), abs=1e-9)
    nx, nz = ground.normal(x)
    np.testing.assert_allclose(near.grad_W, [nx, 0.0, nz], atol=1e-12)
    # The normal is perpendicular to the surface: along the height function's local tangent.
    h = 1e-6
    tangent = np.array([2 * h, ground.height(x + h) - ground.height(x - h)])
    assert abs(np.dot(tangent / np.linalg.norm(tangent), [nx, nz])) < 1e-6


def test_only_drakes_half_space_warning_is_dropped(caplog):
    """Drake's "half spaces are not supported for deformable contact" warning, printed once per diagram by
    every worker, is dropped by its exact text; every other message of Drake's logger passes."""
    import logging

    from drake_biped.model import HALF_SPACE_WARNING

    drake_log = logging.getLogger("drake")
    with caplog.at_level(logging.WARNING, logger="drake"):
        drake_log.warning(HALF_SPACE_WARNING)
        drake_log.warning(HALF_SPACE_WARNING + " (and something else)")
        drake_log.warning("another warning")
    assert [r.getMessage() for r in caplog.records] == [HALF_SPACE_WARNING + " (and something else)",
                                                         "another warning"]


def _model_file(tmp_path, edit, name="biped.urdf") -> Path:
    """A copy of the shipped URDF with `edit` applied to its text, in tmp_path; its path."""
    from drake_biped.resources import model_package_xml

    path = tmp_path / name
    path.write_text(edit((model_package_xml().parent / "biped.urdf").read_text()))
    return path


def test_the_shipped_body_is_read_from_the_plant_as_the_kinematics_constants():
    """The controller's body is read from the model; for the shipped one it is the documented constants,
    bit for bit (so every number of the default walk is the one the constants gave)."""
    from drake_biped.kinematics import TABLE_I_BODY
    from drake_biped.model import body_of_model

    assert np.array_equal(body_of_model(), TABLE_I_BODY)


def test_a_heavier_torso_is_the_mass_of_the_cost_of_transport(tmp_path):
    """Physics from the model: with the torso 2 kg heavier in a user's URDF, the episode reports the model's
    mass, and C_mt is the positive work over that mass's weight times the distance."""
    import drake_biped.model as model
    from drake_biped.episode import run_episode
    from drake_biped.params import GRAVITY_MPS2, RobotModel, SimulationParams

    heavier = RobotModel.from_file(_model_file(tmp_path, lambda t: t.replace('<mass value="6.646"/>',
                                                                             '<mass value="8.646"/>', 1)))
    assert model.link_masses_of(model.build_plant(model=heavier)).total == pytest.approx(TOTAL_MASS_KG + 2.0,
                                                                                        abs=1e-12)
    r = run_episode(fast_config(sim=SimulationParams(distance_m=1.0, max_time_s=6.0), model=heavier), cache=None)
    assert r.mass_kg == pytest.approx(12.202, abs=1e-12)
    assert r.distance_m > 0.3
    assert r.cost_of_transport == pytest.approx(r.total_positive_work_j / (12.202 * GRAVITY_MPS2 * r.distance_m))
    assert r.cost_of_transport_per_kg == pytest.approx(r.total_positive_work_j / (12.202 * r.distance_m))
    assert r.config["model"]["name"] == "biped.urdf"
    assert r.config["model"]["sha256"] == heavier.sha256


def _both_legs(text: str, old: str, new: str) -> str:
    assert text.count(old) == 2
    return text.replace(old, new)


@pytest.mark.parametrize("edit, field, value", [
    (lambda t: _both_legs(t, '<origin xyz="0 0 -0.317"/>', '<origin xyz="0 0 -0.337"/>'), "ankle_z_m", -0.337),
    (lambda t: _both_legs(t, '<origin xyz="0 0 -0.28"/>', '<origin xyz="0 0 -0.30"/>'), "knee_z_m", -0.30),
    (lambda t: _both_legs(t, '<origin xyz="0.0000 0 -0.1400"/>', '<origin xyz="0.0100 0 -0.1300"/>'),
     "thigh_com_offset_x_m", 0.01),
    (lambda t: _both_legs(t, '<origin xyz="0.1200 0.0000 -0.0200"/>', '<origin xyz="0.1500 0.0000 -0.0200"/>'),
     "toe_x_m", 0.15),
    (lambda t: t.replace('<origin xyz="0 0.06 0"/>', '<origin xyz="0.02 0.06 -0.01"/>')
     .replace('<origin xyz="0 -0.06 0"/>', '<origin xyz="0.02 -0.06 -0.01"/>'), "hip_x_m", 0.02),
])
def test_a_changed_body_is_read_from_the_plant_and_its_kinematics_agrees_with_it(tmp_path, edit, field, value):
    """Own robot: a model with other lengths, centres of mass or contact points is read, not refused, and the
    controller's planar kinematics of it agrees with MultibodyPlant at random configurations."""
    from drake_biped.kinematics import BODY, center_of_mass, leg_points
    from drake_biped.model import FOOT_BODIES, body_of_model
    from drake_biped.params import RobotModel

    model = RobotModel.from_file(_model_file(tmp_path, edit))
    body = body_of_model(model)
    assert body[BODY.offset(field)] == pytest.approx(value, abs=1e-12)
    plant = build_plant(model=model)
    ctx = plant.CreateDefaultContext()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q = rng.uniform(-0.6, 0.6, 9)
        plant.SetPositions(ctx, q)
        for i, leg in ((3, "left"), (6, "right")):
            p = leg_points(*q[:3], *q[i:i + 3], body)
            ankle = plant.GetJointByName(f"{leg}_ankle").frame_on_child().CalcPoseInWorld(ctx).translation()
            assert (p.ankle_x, p.ankle_z) == pytest.approx((ankle[0], ankle[2]), abs=1e-12)
            # the toe sphere's lowest point: its centre (the sole plus a radius above it) less a radius
            foot = plant.GetBodyByName(FOOT_BODIES[0 if leg == "left" else 1]).body_frame()
            radius = body[BODY.offset("toe_radius_m")]
            centre = foot.CalcPoseInWorld(ctx).multiply(np.array([body[BODY.offset("toe_x_m")], 0.0,
                                                                  body[BODY.offset("toe_sole_z_m")] + radius]))
            assert (p.toe_x, p.toe_z) == pytest.approx((centre[0], centre[2] - radius), abs=1e-12)
        com = plant.CalcCenterOfMassPositionInWorld(ctx)
        assert center_of_mass(q, body) == pytest.approx((com[0], com[2]), abs=1e-12)


@pytest.mark.parametrize("old, new, match", [
    ('<origin xyz="0 0 -0.317"/>', '<origin xyz="0 0 -0.330"/>',
     r"the legs differ: the left ankle position in the shank frame is \[0\.0, -0\.33\] m, the right \[0\.0, -0\.317\]"),
    ('<origin xyz="0.0000 0 -0.1400"/>', '<origin xyz="0.0000 0 -0.1300"/>', "the legs differ: the left thigh centre"),
    ('<origin xyz="0.1200 0.0000 -0.0200"/>', '<origin xyz="0.1300 0.0000 -0.0200"/>', "the legs differ: the left toe"),
    ('<mass value="0.707"/>', '<mass value="0.800"/>', "the legs' masses differ"),
    ('<mass value="6.646"/>', '<mass value="0"/>', "link torso has mass 0.0 kg; every link"),
    ('<joint name="left_knee" type="revolute">', '<joint name="left_knee_joint" type="revolute">',
     r"biped.urdf:\d+: .*joint 'left_knee'"),
    ('<link name="left_shank">', '<link name="left_lower_leg">', "the model has no link named 'left_shank'"),
    ('<limit lower="0.0" upper="2.4" effort="30" velocity="100"/>', '<limit effort="30" velocity="100"/>',
     r"joint left_knee has the position limits \[-inf, inf\] rad; the toolkit's controller relies on finite"),
    ('ixx="0.0680905"', 'ixx="-0.0680905"', r"link torso has the inertia \(ixx -0.0680905, .*which no body has"),
    ('izz="0.0177227"', 'izz="0.2"', r"link torso has the inertia \(.*izz 0.2, ixy 0, ixz 0, iyz 0\) kg\*m\^2"),
])
def test_a_model_the_toolkit_cannot_read_is_refused_by_name(tmp_path, old, new, match):
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.params import RobotModel

    def edit(text):
        assert old in text
        text = text.replace(old, new, 1)
        if "left_lower_leg" in new:  # a renamed link: its joints follow it
            text = text.replace('link="left_shank"', 'link="left_lower_leg"')
        return text

    model = RobotModel.from_file(_model_file(tmp_path, edit))
    with pytest.raises(ModelError, match=match):
        add_biped(DiagramBuilder(), Ground(), 1e-3, model)


def test_a_knee_turning_the_other_way_is_refused_by_name(tmp_path):
    from drake_biped.params import RobotModel

    def flip(text):
        return text.replace('<origin xyz="0 0 -0.28"/>\n    <axis xyz="0 1 0"/>',
                            '<origin xyz="0 0 -0.28"/>\n    <axis xyz="0 -1 0"/>')

    model = RobotModel.from_file(_model_file(tmp_path, flip))
    with pytest.raises(ModelError, match=r"joint left_knee turns about \[0\.0, -1\.0, 0\.0\]"):
        build_plant(model=model)


def test_package_uris_in_a_users_model_resolve_through_the_package_xml_beside_it(tmp_path):
    """A user's model may name its files by package:// URIs: the package.xml beside it resolves them."""
    from drake_biped.params import RobotModel

    (tmp_path / "package.xml").write_text('<?xml version="1.0"?><package format="2"><name>my_robot</name>'
                                          "<version>0.0.1</version><description>d</description>"
                                          '<maintainer email="a@b.c">a</maintainer><license>BSD</license></package>')
    (tmp_path / "box.obj").write_text("v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0 0 0.01\nf 1 2 3\nf 1 2 4\nf 1 3 4\n"
                                      "f 2 3 4\n")
    mesh = '<visual><geometry><mesh filename="package://my_robot/box.obj"/></geometry></visual>'
    path = _model_file(tmp_path, lambda t: t.replace('<link name="torso">', f'<link name="torso">{mesh}', 1),
                       "mine.urdf")
    model = RobotModel.from_file(path)
    assert model.package_xml == str(tmp_path / "package.xml")
    assert build_plant(model=model).num_positions() == 9
    lone = RobotModel(model.name, model.text)  # the same text without its package: the URI is named
    with pytest.raises(ModelError, match="my_robot"):
        build_plant(model=lone)


def _collision_grounds(ground):
    from pydrake.systems.framework import DiagramBuilder

    handles = add_biped(DiagramBuilder(), ground, 1e-3)
    plant = handles.plant
    return [handles.scene_graph.model_inspector().GetName(g)
            for g in plant.GetCollisionGeometriesForBody(plant.world_body())]


def test_a_ground_is_one_surface_wherever_it_is_one_surface():
    """A level length before no slope is the level ground: one half-space, not two coincident ones (each foot
    sphere met the ground twice: twice its stiffness, C_mt 0.2209 instead of 0.2246 on 1 m)."""
    assert len(_collision_grounds(Ground())) == 1
    assert len(_collision_grounds(Ground(level_length_m=5.0))) == 1
    assert len(_collision_grounds(Ground(slope_rad=0.02, level_length_m=5.0))) == 2  # a level part, then a slope


@pytest.mark.parametrize("offset_m", [-0.04, -0.02, 0.02, 0.04])
def test_near_the_kink_a_foot_meets_one_surface(offset_m):
    """Level for 2 m, then 0.02 rad: a foot sphere 2-4 cm either side of the kink, 0.5 mm into the ground
    there, meets the ground once, at the depth it has into the surface above it (two half-spaces met it twice
    within 5 cm: the level one reaches under the slope and the slope one under the level part)."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.diagram import initial_state
    from drake_biped.kinematics import leg_points

    ground = Ground(slope_rad=0.02, level_length_m=2.0)
    builder = DiagramBuilder()
    handles = add_biped(builder, ground, 1e-3)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant = handles.plant
    q, *_ = initial_state(fast_config())
    q = q.copy()
    q[1] += 0.3  # lift the robot; then put the right heel's sphere where it is wanted
    heel = leg_points(q[0], q[1], q[2], q[6], q[7], q[8])
    x = 2.0 + offset_m
    q[0] += x - heel.heel_x
    q[1] += ground.height(x) - 0.0005 - heel.heel_z
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context), q)
    query = handles.scene_graph.get_query_output_port().Eval(handles.scene_graph.GetMyContextFromRoot(context))
    inspector = handles.scene_graph.model_inspector()
    heel_id = min(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("right_foot")),
                  key=lambda g: inspector.GetPoseInFrame(g).translation()[0])  # the heel: the sphere behind
    pairs = [p for p in query.ComputePointPairPenetration() if heel_id in (p.id_A, p.id_B)]
    assert len(pairs) == 1
    surface_angle = ground.slope_at(x)
    assert pairs[0].depth == pytest.approx(0.0005 * math.cos(surface_angle), abs=2e-5)


def test_a_walk_with_a_level_length_on_level_ground_is_the_walk_without_it():
    from drake_biped.episode import run_episode
    from drake_biped.params import SimulationParams

    sim = SimulationParams(distance_m=1.0, max_time_s=5.0)
    plain = run_episode(fast_config(sim=sim))
    with_level = run_episode(fast_config(sim=sim, ground=Ground(level_length_m=5.0)))
    assert with_level.cost_of_transport == plain.cost_of_transport
    assert with_level.distance_m == plain.distance_m


def test_walk_with_a_model_file_from_another_folder(tmp_path, monkeypatch, capsys):
    """`drake-biped walk --model heavy.urdf` from a folder of the user's: the model's mass, C_mt with it, and
    the file named (with its SHA-256) in result.json; a model with longer shanks is walked, not refused."""
    import hashlib
    import json

    from drake_biped.cli import main
    from drake_biped.params import GRAVITY_MPS2

    heavy = _model_file(tmp_path, lambda t: t.replace('<mass value="6.646"/>', '<mass value="8.646"/>', 1),
                        "heavy.urdf")
    longer = _model_file(tmp_path, lambda t: _both_legs(t, '<origin xyz="0 0 -0.317"/>', '<origin xyz="0 0 -0.337"/>'),
                         "longer.urdf")
    monkeypatch.chdir(tmp_path)
    assert main(["walk", "--model", "heavy.urdf", "--distance", "1", "--no-animation", "--out", "D"]) == 0
    assert "note:" not in capsys.readouterr().err  # 12.2 kg is within a factor of 2 of Table I's mass
    r = json.loads((tmp_path / "D" / "result.json").read_text())
    assert r["mass_kg"] == pytest.approx(12.202, abs=1e-12)
    work = r["positive_work_j"]["total"]
    assert r["cost_of_transport"] == pytest.approx(work / (12.202 * GRAVITY_MPS2 * r["distance_m"]), rel=1e-12)
    assert r["config"]["model"]["name"] == "heavy.urdf"
    assert r["config"]["model"]["sha256"] == hashlib.sha256(heavy.read_bytes()).hexdigest()
    assert main(["walk", "--model", str(longer), "--distance", "1", "--no-animation", "--out", "L"]) == 0
    r = json.loads((tmp_path / "L" / "result.json").read_text())
    assert r["termination"] in ("distance", "fall") and r["config"]["model"]["name"] == "longer.urdf"
    # the result.json walks again by --params, carrying its model
    assert main(["walk", "--params", "D/result.json", "--no-animation", "--out", "D2"]) == 0
    first = json.loads((tmp_path / "D" / "result.json").read_text())
    again = json.loads((tmp_path / "D2" / "result.json").read_text())
    assert again["cost_of_transport"] == first["cost_of_transport"]
    assert again["config"]["model"]["sha256"] == first["config"]["model"]["sha256"]


def test_a_torso_too_heavy_to_carry_falls_and_its_small_c_mt_is_printed_with_the_mass_noted(tmp_path, capsys):
    """A 66,460 kg torso falls at once; its C_mt (E+ over a huge m g d) is small, not zero, and `walk` prints
    it to four significant digits (it printed 0.000), with a note that the mass is far from Table I's."""
    import json
    import re

    from drake_biped.cli import main

    huge = _model_file(tmp_path, lambda t: t.replace('<mass value="6.646"/>', '<mass value="66460"/>', 1), "huge.urdf")
    assert main(["walk", "--model", str(huge), "--no-animation", "--out", str(tmp_path / "w")]) == 0
    out, err = capsys.readouterr()
    r = json.loads((tmp_path / "w" / "result.json").read_text())
    assert r["fell"] and r["distance_m"] < 0.5 and 0 < r["cost_of_transport"] < 1e-4
    shown = float(re.search(r"C_mt (\d+\.\d+) \(E\+/\(m g d\)\)", out).group(1))
    assert shown == pytest.approx(r["cost_of_transport"], rel=1e-3)
    notes = [line for line in err.splitlines() if line.startswith("note:")]
    assert len(notes) == 1 and "total mass is 66463.6 kg" in notes[0] and "Table I's 10.202 kg" in notes[0]


def _hips_effort(value: str | None):
    """An edit of the shipped URDF's text: both hips' effort limit set to `value` (None: no effort attribute)."""
    def edit(text):
        old = '<limit lower="-0.890118" upper="0.890118" effort="40" velocity="100"/>'
        new = old.replace(' effort="40"', "") if value is None else old.replace('effort="40"', f'effort="{value}"')
        return _both_legs(text, old, new)
    return edit


def test_the_motors_limits_are_the_models_and_the_work_is_of_the_applied_torque(tmp_path):
    """A model whose hips are limited to 25 N*m: the controller clips to the model's limit (read from the
    plant), so the torque the plant applies is the torque whose work is counted: the logged hip actuation never
    exceeds 25 N*m, and the positive work integrated from the logged actuation and joint rates is the
    episode's own."""
    from drake_biped.episode import run_episode
    from drake_biped.kinematics import B_HIP_EFFORT, B_KNEE_EFFORT
    from drake_biped.model import body_of_model
    from drake_biped.params import RobotModel, SimulationParams

    weak = RobotModel.from_file(_model_file(tmp_path, _hips_effort("25")))
    body = body_of_model(weak)
    assert body[B_HIP_EFFORT] == 25.0 and body[B_KNEE_EFFORT] == 30.0
    r = run_episode(fast_config(sim=SimulationParams(distance_m=3.0, max_time_s=10.0), model=weak),
                    record_trajectory=True, cache=None)
    hips = [JOINT_NAMES.index("left_hip"), JOINT_NAMES.index("right_hip")]
    actuation = r.trajectory["actuation"]
    assert np.max(np.abs(actuation[:, hips])) <= 25.0 + 1e-12
    strong = run_episode(fast_config(sim=SimulationParams(distance_m=3.0, max_time_s=10.0)),
                         record_trajectory=True, cache=None)
    assert np.max(np.abs(strong.trajectory["actuation"][:, hips])) > 25.0  # the limit binds
    # the work of the applied torques, held over each control period, from the logged states
    q = r.trajectory["positions"][:, 3:]
    work = np.maximum(actuation[:-1] * np.diff(q, axis=0), 0.0).sum()
    assert work == pytest.approx(r.total_positive_work_j, rel=0.02)


@pytest.mark.parametrize("value, match", [
    (None, r"the motor left_hip_motor has the effort limit inf N\*m; the controller needs a finite positive"),
    ("0", r"the model has no actuator for joint left_hip"),  # Drake drops a zero-effort transmission
])
def test_a_motor_without_a_torque_limit_is_refused_by_name(tmp_path, value, match):
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.params import RobotModel

    model = RobotModel.from_file(_model_file(tmp_path, _hips_effort(value)))
    with pytest.raises(ModelError, match=match):
        add_biped(DiagramBuilder(), Ground(), 1e-3, model)


def test_the_contact_material_is_the_configurations_on_every_foot_sphere_and_the_ground():
    """The contact's physical parameters are explicit: each foot sphere and the ground carry the stiffness,
    relaxation time and Hunt & Crossley dissipation of params.ContactParams, and the plant SAP's near-rigid
    threshold; the model's friction is kept."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.params import ContactParams

    contact = ContactParams(stiffness_npm=2.5e5, relaxation_time_s=0.02, hunt_crossley_dissipation_spm=7.0,
                            sap_near_rigid_threshold=0.5)
    handles = add_biped(DiagramBuilder(), Ground(), 1e-3, contact=contact)
    plant, inspector = handles.plant, handles.scene_graph.model_inspector()
    geometries = [g for name in ("left_foot", "right_foot", "world")
                  for g in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(name))]
    assert len(geometries) == 5
    for g in geometries:
        props = inspector.GetProximityProperties(g)
        assert props.GetProperty("material", "point_contact_stiffness") == 2.5e5
        assert props.GetProperty("material", "relaxation_time") == 0.02
        assert props.GetProperty("material", "hunt_crossley_dissipation") == 7.0
        assert props.GetProperty("material", "coulomb_friction").dynamic_friction() == 1.0
    assert plant.get_sap_near_rigid_threshold() == 0.5


@pytest.mark.parametrize("sink_m", [2e-4, 4e-4])
def test_hydroelastic_feet_carry_the_pressure_fields_force(sink_m):
    """Under the hydroelastic model each foot sphere is a compliant hydroelastic sphere with the contact's
    modulus, mesh and margin, and the ground rigid: with the feet flat and sunk x into the ground (no margin),
    the four contact surfaces' pressures integrate to the hydroelastic sphere's 4 pi E x^2 (a fine mesh: within
    6 %), and no pair falls back to point contact."""
    from pydrake.geometry import HydroelasticContactRepresentation
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.kinematics import leg_points
    from drake_biped.params import ContactParams

    contact = ContactParams(model="hydroelastic", hydroelastic_modulus_pa=2e8, resolution_hint_m=5e-4)
    for margin in (0.0, 1e-4):
        handles = add_biped(DiagramBuilder(), Ground(), 1e-3, contact=dataclasses.replace(contact, margin_m=margin))
        plant, inspector = handles.plant, handles.scene_graph.model_inspector()
        for name in ("left_foot", "right_foot"):
            for g in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(name)):
                props = inspector.GetProximityProperties(g)
                assert props.GetProperty("hydroelastic", "hydroelastic_modulus") == 2e8
                assert props.GetProperty("hydroelastic", "resolution_hint") == 5e-4
                assert props.GetPropertyOrDefault("hydroelastic", "margin", 0.0) == margin
    builder = DiagramBuilder()
    handles = add_biped(builder, Ground(), 1e-3, contact=contact)
    plant = handles.plant
    diagram = builder.Build()
    plant_context = plant.GetMyMutableContextFromRoot(diagram.CreateDefaultContext())
    flat = leg_points(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, handles.body)
    q = np.zeros(9)
    q[1] = -min(flat.heel_z, flat.toe_z) - sink_m
    plant.SetPositions(plant_context, q)
    query = plant.get_geometry_query_input_port().Eval(plant_context)
    surfaces, point_pairs = query.ComputeContactSurfacesWithFallback(HydroelasticContactRepresentation.kPolygon)
    assert len(surfaces) == 4 and not point_pairs  # every foot pair is hydroelastic, none fell back
    force = sum(s.poly_mesh_W().area(f) * s.poly_e_MN().EvaluateCartesian(f, s.poly_mesh_W().element_centroid(f))
                for s in surfaces for f in range(s.poly_mesh_W().num_faces()))
    assert force == pytest.approx(4 * math.pi * 2e8 * sink_m ** 2, rel=0.06)


def test_an_unknown_contact_model_is_refused_by_name():
    from drake_biped.params import ContactParams, ParameterError

    with pytest.raises(ParameterError, match="ContactParams.model = 'soft'"):
        ContactParams(model="soft")


def test_the_default_contact_is_drakes_default_material_without_the_near_rigid_regime():
    """ContactParams' defaults are the values Drake gives a geometry that names none (the same walk to the
    last bit), with SAP's near-rigid regime off; a record written before the contact was recorded is walked
    again on Drake's defaults, near-rigid regime included."""
    from drake_biped.episode import run_episode
    from drake_biped.legacy import config_of_record
    from drake_biped.params import (
        DRAKE_DEFAULT_CONTACT,
        ContactParams,
        SimulationParams,
    )

    sim = SimulationParams(distance_m=1.0, max_time_s=5.0)
    explicit = run_episode(fast_config(sim=sim), cache=None)
    drakes = run_episode(fast_config(sim=sim, contact=ContactParams(None, None, None, 0.0)), cache=None)
    assert explicit.cost_of_transport == drakes.cost_of_transport
    old = fast_config(sim=sim).to_dict()
    old.pop("contact")
    assert config_of_record(old).contact == DRAKE_DEFAULT_CONTACT
    assert config_of_record(fast_config(sim=sim).to_dict()).contact == ContactParams()
    legacy = run_episode(config_of_record(old), cache=None)
    assert legacy.cost_of_transport != explicit.cost_of_transport  # the regime changes the contact


def test_a_link_fixed_to_the_torso_counts_in_the_torso(tmp_path):
    """A sensor bolted to the torso (a fixed joint): its mass and centre of mass count in the torso's, the
    planar kinematics agrees with the plant, and the robot's total is the plant's; a body on a joint of its own
    is refused by name."""
    from drake_biped.kinematics import masses_of
    from drake_biped.model import body_of_model
    from drake_biped.params import RobotModel

    sensor = ('  <link name="sensor"><inertial><origin xyz="0.05 0 0.2"/><mass value="1.0"/><inertia ixx="0.001" '
              'ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>\n'
              '  <joint name="sensor_mount" type="fixed"><parent link="torso"/><child link="sensor"/>'
              '<origin xyz="0 0 0.1"/></joint>\n</robot>')
    model = RobotModel.from_file(_model_file(tmp_path, lambda t: t.replace("</robot>", sensor)))
    masses = masses_of(body_of_model(model))  # ModelError if the kinematics' centre of mass disagreed
    assert masses.torso == pytest.approx(7.646) and masses.total == pytest.approx(11.202)
    swinging = sensor.replace('type="fixed"', 'type="revolute"').replace(
        "<origin xyz=\"0 0 0.1\"/></joint>", '<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><limit lower="-1" '
        'upper="1" effort="1" velocity="1"/></joint>')
    model = RobotModel.from_file(_model_file(tmp_path, lambda t: t.replace("</robot>", swinging), "swing.urdf"))
    with pytest.raises(ModelError, match="link sensor moves on a joint of its own"):
        body_of_model(model)


def test_a_mesh_named_relative_to_the_model_file_resolves(tmp_path):
    """A model parsed from its text still finds a mesh named relative to the file it came from."""
    from pydrake.systems.framework import DiagramBuilder

    from drake_biped.params import RobotModel

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "box.obj").write_text(
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")
    visual = '<visual><geometry><mesh filename="meshes/box.obj"/></geometry></visual>\n  </link>'

    def edit(text):
        i = text.index("</link>")  # the torso's
        return text[:i] + visual + text[i + len("</link>"):]

    model = RobotModel.from_file(_model_file(tmp_path, edit))
    assert model.directory == str(tmp_path.resolve())
    add_biped(DiagramBuilder(), Ground(), 1e-3, model)  # no ModelError: the relative file name resolved


def test_a_models_file_is_found_or_named_with_where_it_was_looked_for(tmp_path):
    """A mesh named by an absolute path resolves; a missing one, relative or absolute, and a package nobody
    declared are ModelError naming the file and where it was looked for, through the API as on the command line."""
    from drake_biped.episode import run_episode
    from drake_biped.params import RobotModel

    (tmp_path / "box.obj").write_text("v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n")

    def with_mesh(uri, name):
        visual = f'<visual><geometry><mesh filename="{uri}"/></geometry></visual>'
        return RobotModel.from_file(_model_file(tmp_path, lambda t: t.replace('<link name="torso">',
                                                                              f'<link name="torso">{visual}', 1), name))

    build_plant(model=with_mesh(str(tmp_path / "box.obj"), "absolute.urdf"))  # no ModelError: it resolved
    folder = tmp_path.resolve()
    cases = [("meshes/nope.obj", f"looked for {folder / 'meshes' / 'nope.obj'} (in the model file's folder)"),
             (str(tmp_path / "nope.obj"), f"looked for {tmp_path / 'nope.obj'}"),
             ("package://nopkg/box.obj", f"in the package 'nopkg', which is unknown: the model file's folder {folder} "
                                         "has no package.xml")]
    for uri, where in cases:
        model = with_mesh(uri, "mine.urdf")
        with pytest.raises(ModelError) as raised:
            run_episode(fast_config(model=model))
        assert f"the model mine.urdf names the file {uri!r}" in str(raised.value)
        assert where in str(raised.value) and "\n" not in str(raised.value)
    text = with_mesh("box.obj", "mine.urdf").text  # a relative name without the folder to read it against
    with pytest.raises(ModelError, match="relative to the model file, but the model was given as text"):
        build_plant(model=RobotModel("mine.urdf", text))


def test_an_sdformat_model_of_the_shipped_robot_walks_as_the_urdf(tmp_path):
    """SDFormat names actuators after their joints and has no planar joint of its own: the shipped robot written
    as SDFormat (tests/sdf_of_urdf.py) is read to the same body (to rounding: its planar frames are turned by a
    rotation in floating point) and walks the default gait's 10 m as the URDF does."""
    from sdf_of_urdf import urdf_to_sdf

    from drake_biped.episode import run_episode
    from drake_biped.kinematics import TABLE_I_BODY
    from drake_biped.model import body_of_model
    from drake_biped.params import RobotModel
    from drake_biped.resources import shipped_model_file

    path = tmp_path / "biped.sdf"
    path.write_text(urdf_to_sdf(shipped_model_file().read_text()))
    model = RobotModel.from_file(path)
    assert np.max(np.abs(body_of_model(model) - TABLE_I_BODY)) < 1e-12
    sdf, urdf = run_episode(fast_config(model=model)), run_episode(fast_config())
    assert sdf.termination == urdf.termination == "distance" and len(sdf.steps) == len(urdf.steps)
    assert sdf.cost_of_transport == pytest.approx(urdf.cost_of_transport, rel=2e-3)
