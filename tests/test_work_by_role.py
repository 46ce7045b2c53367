"""The motors' work by the joints' roles (EpisodeResult.work_by_role): the per-joint work regrouped by swing and
stance leg, each control period by the roles held when it began, agreeing with the torques the plant applied."""

import json

import numpy as np
import pytest
from walkers import fast_config

from drake_biped.episode import EpisodeResult, run_episode
from drake_biped.model import JOINT_NAMES, ROLES
from drake_biped.params import SimulationParams, TorqueFreeWindow
from drake_biped.resources import load_gait

WALKS = {
    "default, a window": fast_config(sim=SimulationParams(distance_m=3.0, max_time_s=15.0),
                                       window=TorqueFreeWindow(0.2, 0.35)),
    "paper, the plant's motor": load_gait("paper").override({"gait.motor_solve": "plant", "sim.distance_m": 1.5}),
}


@pytest.mark.parametrize("name", list(WALKS))
def test_the_work_by_role_is_the_applied_torques_work_regrouped_by_role(name):
    """Offline, from the recorded walk: each period's torque the plant applied times the joint's displacement
    over it, given to the role the joint's leg held when the period began (the controller's logged roles): the
    same sums as the controller's at its last logged update, positive and negative apart; and over the whole
    episode the roles' sums are the joints' totals."""
    r = run_episode(WALKS[name], record_trajectory=True, cache=None)
    assert not r.fell and len(r.steps) >= 2
    T = r.trajectory
    work = T["actuation"][:-1] * np.diff(T["positions"][:, 3:], axis=0)
    right = T["stance_right"][:-1] > 0.5
    offline = {role: [0.0, 0.0] for role in ROLES}
    for i, joint in enumerate(JOINT_NAMES):
        leg, kind = joint.split("_")
        stance = right if leg == "right" else ~right
        for held, part in ((stance, "stance"), (~stance, "swing")):
            w = work[held, i]
            offline[f"{part}_{kind}"][0] += w[w > 0].sum()
            offline[f"{part}_{kind}"][1] += w[w <= 0].sum()
    for k, role in enumerate(ROLES):  # the controller's sums at the last logged update
        np.testing.assert_allclose([T["positive_work_by_role"][-1, k], T["negative_work_by_role"][-1, k]],
                                   offline[role], rtol=1e-9, atol=1e-9, err_msg=role)
    positive = sum(v["positive_j"] for v in r.work_by_role.values())
    signed = sum(v["positive_j"] + v["negative_j"] for v in r.work_by_role.values())
    assert positive == pytest.approx(r.positive_work_j["total"], rel=1e-12)
    assert signed == pytest.approx(r.signed_work_j["total"], rel=1e-12, abs=1e-9)
    assert r.work_by_role["swing_hip"]["positive_j"] > 0.0 and r.work_by_role["stance_hip"]["positive_j"] > 0.0


def test_the_work_by_role_is_in_the_record_and_an_older_record_reads_without_it(tmp_path):
    r = run_episode(fast_config(sim=SimulationParams(distance_m=0.3, max_time_s=5.0)))
    r.to_json(tmp_path / "result.json")
    data = json.loads((tmp_path / "result.json").read_text())
    assert set(data["work_by_role"]) == set(ROLES)
    assert EpisodeResult.from_dict(data).work_by_role == r.work_by_role
    del data["work_by_role"]
    assert EpisodeResult.from_dict(data).work_by_role is None
