"""The plant read back from models/biped.urdf against Table I and the documented limits."""

import math
from pathlib import Path

import numpy as np
import pytest

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


def test_malformed_model_is_a_clear_error(tmp_path):
    from pydrake.systems.framework import DiagramBuilder

    bad = tmp_path / "package.xml"
    bad.write_text('<?xml version="1.0"?><package format="2"><name>drake_biped</name></package>')
    (tmp_path / "biped.urdf").write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(ModelError, match="could not parse"):
        add_biped(DiagramBuilder(), Ground(), 1e-3, package_xml=bad)


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


def _model_copy(tmp_path, edit) -> Path:
    """A copy of the shipped model package with `edit` applied to the URDF text; its package.xml."""
    from drake_biped.resources import model_package_xml

    shipped = model_package_xml().parent
    for name in ("package.xml", "biped.urdf"):
        text = (shipped / name).read_text()
        (tmp_path / name).write_text(edit(text) if name == "biped.urdf" else text)
    return tmp_path / "package.xml"


def test_a_heavier_torso_is_the_mass_of_the_cost_of_transport(tmp_path, monkeypatch):
    """Physics from the model: with the torso 2 kg heavier in the URDF, the episode reports the model's
    mass, and C_mt is the positive work over that mass's weight times the distance."""
    import drake_biped.model as model
    from drake_biped.episode import run_episode
    from drake_biped.params import GRAVITY_MPS2, EpisodeConfig, SimulationParams

    heavier = _model_copy(tmp_path, lambda t: t.replace('<mass value="6.646"/>', '<mass value="8.646"/>', 1))
    monkeypatch.setattr(model, "model_package_xml", lambda: heavier)
    assert model.link_masses_of(model.build_plant()).total == pytest.approx(TOTAL_MASS_KG + 2.0, abs=1e-12)
    r = run_episode(EpisodeConfig(sim=SimulationParams(distance_m=1.0, max_time_s=6.0)), cache=None)
    assert r.mass_kg == pytest.approx(12.202, abs=1e-12)
    assert r.distance_m > 0.3
    assert r.cost_of_transport == pytest.approx(r.total_positive_work_j / (12.202 * GRAVITY_MPS2 * r.distance_m))
    assert r.cost_of_transport_per_kg == pytest.approx(r.total_positive_work_j / (12.202 * r.distance_m))


@pytest.mark.parametrize("old, new, match", [
    ('<origin xyz="0 0 -0.317"/>', '<origin xyz="0 0 -0.330"/>', r"left ankle position in the shank frame .* is \[0\.0, -0\.33\]"),
    ('<origin xyz="0.0000 0 -0.1400"/>', '<origin xyz="0.0000 0 -0.1300"/>', "left thigh centre of mass"),
    ('<origin xyz="0.1200 0.0000 -0.0200"/>', '<origin xyz="0.1300 0.0000 -0.0200"/>', "left foot contact spheres"),
    ('<mass value="0.707"/>', '<mass value="0.800"/>', "the legs' masses differ"),
    ('<joint name="left_knee" type="revolute">', '<joint name="left_knee_joint" type="revolute">',
     "left_knee"),
])
def test_a_model_the_kinematics_does_not_match_is_refused_by_name(tmp_path, old, new, match):
    from pydrake.systems.framework import DiagramBuilder

    package = _model_copy(tmp_path, lambda t: t.replace(old, new, 1))
    with pytest.raises(ModelError, match=match):
        add_biped(DiagramBuilder(), Ground(), 1e-3, package_xml=package)


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
    from drake_biped.params import EpisodeConfig

    ground = Ground(slope_rad=0.02, level_length_m=2.0)
    builder = DiagramBuilder()
    handles = add_biped(builder, ground, 1e-3)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant = handles.plant
    q, *_ = initial_state(EpisodeConfig())
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
    from drake_biped.params import EpisodeConfig, SimulationParams

    sim = SimulationParams(distance_m=1.0, max_time_s=5.0)
    plain = run_episode(EpisodeConfig(sim=sim))
    with_level = run_episode(EpisodeConfig(sim=sim, ground=Ground(level_length_m=5.0)))
    assert with_level.cost_of_transport == plain.cost_of_transport
    assert with_level.distance_m == plain.distance_m
