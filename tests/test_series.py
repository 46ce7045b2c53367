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
