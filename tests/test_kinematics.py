"""Hand-written planar kinematics against MultibodyPlant."""

import numpy as np
import pytest

from drake_biped.kinematics import center_of_mass, leg_points
from drake_biped.model import build_plant


@pytest.fixture(scope="module")
def plant():
    return build_plant()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_points_and_com_match_plant(plant, seed):
    rng = np.random.default_rng(seed)
    q = np.array([0.3, 0.7, 0.2, 0.4, 0.6, -0.2, -0.3, 0.1, 0.3]) * rng.uniform(0.5, 1.5, 9)
    ctx = plant.CreateDefaultContext()
    plant.SetPositions(ctx, q)
    world = plant.world_frame()
    for side, i in (("left", 3), ("right", 6)):
        p = leg_points(*q[:3], *q[i:i + 3])
        ankle = plant.GetBodyByName(f"{side}_foot").EvalPoseInWorld(ctx).translation()
        knee = plant.GetBodyByName(f"{side}_shank").EvalPoseInWorld(ctx).translation()
        assert (p.ankle_x, p.ankle_z) == pytest.approx((ankle[0], ankle[2]), abs=1e-9)
        assert (p.knee_x, p.knee_z) == pytest.approx((knee[0], knee[2]), abs=1e-9)
        foot = plant.GetBodyByName(f"{side}_foot").body_frame()
        heel = plant.CalcPointsPositions(ctx, foot, np.array([[-0.06], [0], [-0.02]]), world).ravel()
        # Lowest point of the heel sphere (r = 0.01) is 1 cm below its centre.
        assert (p.heel_x, p.heel_z) == pytest.approx((heel[0], heel[2] - 0.01), abs=1e-9)
    com = plant.CalcCenterOfMassPositionInWorld(ctx)
    assert center_of_mass(q) == pytest.approx((com[0], com[2]), abs=1e-9)
