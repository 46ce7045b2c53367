"""Helpers on per-episode series (analysis.series), on signals whose answer is known."""

import numpy as np
import pytest

from drake_biped.analysis.series import sign_changes_per_s


def test_sign_changes_count_flips_within_a_segment_and_not_across_zero_or_a_swap():
    t = np.arange(11) * 0.1  # 1 s
    assert sign_changes_per_s(t, [1, -1] * 5 + [1]) == 10.0
    assert sign_changes_per_s(t, [1, 0, -1, 0, 1, 0, -1, 0, 1, 0, -1]) == 0.0  # a zero between: no flip
    assert sign_changes_per_s(t, np.sin(2 * np.pi * t + 0.1)) == 2.0  # a smooth 1 Hz torque: twice a second
    roles = [0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1]
    assert sign_changes_per_s(t, [1, 1, -1, -1, 1, 1, -1, -1, 1, 1, -1], roles) == 0.0  # flips only at swaps
    with pytest.raises(ValueError, match="same length"):
        sign_changes_per_s(t, [1, 2])


def test_the_swing_hips_sign_changes_follow_the_roles_in_a_trajectory():
    """In a recorded walk's trajectory the swing hip is the left one while the right leg stands, and the right one
    otherwise: only its torque's flips count, from `after_s` on."""
    from drake_biped.analysis.series import swing_hip_sign_changes_per_s

    t = np.arange(21) * 0.1  # 2 s
    right_stands = (t < 1.0).astype(float)
    act = np.zeros((21, 6))
    act[:, 0] = np.where(t < 1.0, [1, -1] * 10 + [1], 5.0)  # left hip: flips while it swings, then steady
    act[:, 3] = np.where(t < 1.0, 7.0, [1, 1, -1, -1] * 5 + [1])  # right hip: steady, then flips while it swings
    trajectory = {"time": t, "actuation": act, "stance_right": right_stands,
                  "actuator_names": np.array([f"{leg}_{j}_motor" for leg in ("left", "right")
                                              for j in ("hip", "knee", "ankle")])}
    assert swing_hip_sign_changes_per_s(trajectory, after_s=1.0) == pytest.approx(5 / 1.0)
    assert swing_hip_sign_changes_per_s(trajectory, after_s=0.0) == pytest.approx((9 + 5) / 2.0)
