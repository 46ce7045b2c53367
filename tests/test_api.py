"""The public Python API: what `import drake_biped` gives, typed configuration, overrides, shipped gaits."""

import json
import subprocess
import sys

import numpy as np
import pytest

import drake_biped
from drake_biped.params import CpgParams, EpisodeConfig, ParameterError, Push, TorqueFreeWindow

CORE = ("EpisodeConfig", "CpgParams", "GaitParams", "InitialConditions", "TorqueFreeWindow", "Push", "Ground",
        "SimulationParams", "run_episode", "EpisodeResult", "build_diagram", "GarbLearner", "cost_of_transport",
        "fit_return_map", "load_gait")


def test_the_package_exports_the_core_without_dask_or_matplotlib():
    code = ("import sys, drake_biped as db; [getattr(db, n) for n in db.__all__]; "
            "print(sorted(m for m in ('dask', 'distributed', 'matplotlib', 'tqdm') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
    for name in CORE:
        assert name in drake_biped.__all__ and getattr(drake_biped, name) is not None
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        drake_biped.nothing  # noqa: B018


def test_wrong_types_are_refused_at_construction_naming_the_field():
    with pytest.raises(ParameterError, match=r"EpisodeConfig\.cpg must be a CpgParams, got dict"):
        EpisodeConfig(cpg={"u_a": 1.0})
    with pytest.raises(ParameterError, match=r"CpgParams\.u_a must be a number, got '2'"):
        CpgParams(u_a="2")
    with pytest.raises(ParameterError, match=r"TorqueFreeWindow\.start_s must be a number, got True"):
        TorqueFreeWindow(True, 0.5)
    with pytest.raises(ParameterError, match=r"EpisodeConfig\.seed must be an integer"):
        EpisodeConfig(seed=1.5)
    assert CpgParams(u_a=2).u_a == 2.0 and isinstance(CpgParams(u_a=2).u_a, float)
    assert EpisodeConfig(push=None).push is None


def test_override_by_dotted_and_short_names():
    base = EpisodeConfig()
    c = base.override({"u_a": 1.7, "cpg.kappa": 2.0, "gait.torso_pitch_rad": -0.3, "t1": 0.2, "t2": 0.5,
                       "sim.distance_m": 4})
    assert (c.cpg.u_a, c.cpg.kappa, c.gait.torso_pitch_rad) == (1.7, 2.0, -0.3)
    assert c.window == TorqueFreeWindow(0.2, 0.5) and c.sim.distance_m == 4.0
    assert c.cpg.u_r == base.cpg.u_r and c.initial == base.initial  # nothing else moves
    assert base.override({"push.force_n": 20.0}).push == Push(20.0)  # a missing section starts at its defaults
    with pytest.raises(ParameterError, match="'cpg.u_q' is not an EpisodeConfig field"):
        base.override({"cpg.u_q": 1.0})
    with pytest.raises(ParameterError, match=r"CpgParams\.alpha = 9\.0 is outside \[-2, 2\]"):
        base.override({"alpha": 9.0})


def test_steps_as_arrays(short_walk):
    td = short_walk.touchdowns
    assert len(td) == len(short_walk.steps) >= 3
    np.testing.assert_array_equal(td["hip_angle_rad"], [s.hip_angle_rad for s in short_walk.steps])
    np.testing.assert_array_equal(td["stance_right"], [s.stance_leg == "right" for s in short_walk.steps])
    assert np.all(np.diff(td["touchdown_time_s"]) > 0)
    np.testing.assert_array_equal(short_walk.sections, np.column_stack([td["hip_angle_rad"], td["hip_rate_radps"]]))


def test_shipped_gaits_load_by_name_or_path(tmp_path):
    from drake_biped.resources import gait_path

    climbing = drake_biped.load_gait("climbing")
    assert climbing == EpisodeConfig.from_dict(json.loads(gait_path("climbing").read_text()))
    assert climbing.gait.torso_pitch_rad != EpisodeConfig().gait.torso_pitch_rad
    result_like = tmp_path / "result.json"
    result_like.write_text(json.dumps({"config": climbing.to_dict(), "distance_m": 1.0}))
    assert drake_biped.load_gait(result_like) == climbing
    with pytest.raises(ParameterError, match=r"--params 'nope': neither a file nor a shipped name.*climbing"):
        drake_biped.load_gait("nope")


def test_controller_state_is_read_by_name():
    from drake_biped.control_kernel import CONTROLLER_STATE, N_STATE, POSITIVE_WORK, TAU

    assert N_STATE == CONTROLLER_STATE.size == 68
    assert CONTROLLER_STATE.slice("torques_nm") == slice(TAU, TAU + 6)
    vector = np.arange(N_STATE, dtype=float)
    view = CONTROLLER_STATE.view(vector)
    assert view.cpg_phase == 0.0 and view.torque_reversals == N_STATE - 26 and view.swing_travel_rad == N_STATE - 27
    np.testing.assert_array_equal(view.positive_work_j, vector[POSITIVE_WORK:POSITIVE_WORK + 6])
    log = np.vstack([vector, vector + 100]).T  # two samples, as VectorLog.data() holds them
    np.testing.assert_array_equal(CONTROLLER_STATE.rows(log, "cpg_phase"), [0.0, 100.0])
    assert CONTROLLER_STATE.rows(log, "signed_work_j").shape == (2, 6)
    with pytest.raises(AttributeError, match="no field 'gamma'"):
        view.gamma  # noqa: B018


def test_the_paper_gait_holds_table_iii_and_the_paper_initiation_as_printed():
    """`--params paper`: Table III's CPG and the initiation exactly, the hip the paper's ODE motor on the swing hip
    joint; `paper_servo`, the same CPG and initiation under the soft servo of the thigh's angle (integrated)."""
    from drake_biped.paper import INITIAL_HIP_ANGLE_RAD, INITIAL_SPEED_MPS, TABLE_III

    for name in ("paper", "paper_servo"):
        paper = drake_biped.load_gait(name)
        assert paper.cpg.to_dict() == TABLE_III
        assert paper.initial.hip_angle_rad == INITIAL_HIP_ANGLE_RAD and paper.initial.speed_mps == INITIAL_SPEED_MPS
    assert drake_biped.load_gait("paper").gait.hip_drive == "motor"
    assert drake_biped.load_gait("paper").gait.hip_joint == "swing"
    assert drake_biped.load_gait("paper_servo").gait.swing_reading == "integrated"


def test_learners_from_the_top_level_api():
    import drake_biped as db

    # After one episode neither moves: GARB's first baseline is that reward (r - B = 0), and CMA-ES updates
    # only once its whole generation is told. A second, better GARB episode moves the mean along the
    # eligibility trace by Table II's first rate: 0.1 * (r - B) * (e2 + 0.8 e1).
    for name in ("garb", "cmaes"):
        learner = db.make_learner(name, mean=(0.5, 0.5), variance=0.04, seed=0)
        t = learner.ask()
        assert t.shape == (2,) and not np.allclose(t, (0.5, 0.5))
        learner.tell(t, 4.0)
        np.testing.assert_array_equal(learner.mean, (0.5, 0.5))
    garb = db.make_learner("garb", seed=0)
    t1 = garb.ask()
    garb.tell(t1, 4.0)
    t2 = garb.ask()
    garb.tell(t2, 6.0)  # baseline (4 + 6) / 2 = 5
    np.testing.assert_allclose(garb.mean, 0.5 + 0.1 * (6.0 - 5.0) * ((t2 - 0.5) + 0.8 * (t1 - 0.5)), rtol=1e-12)
