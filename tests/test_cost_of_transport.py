import math

import numpy as np
import pytest

from drake_biped.analysis.cost_of_transport import cost_of_transport, cost_of_transport_per_kg, positive_work


def test_positive_work_hand_computed():
    torque = np.array([[2.0, -1.0], [2.0, -1.0], [-3.0, 0.5]])
    omega = np.array([[1.0, 1.0], [-1.0, -2.0], [-2.0, 4.0]])
    # joint 0: 2, (-2 -> 0), 6 ; joint 1: (-1 -> 0), 2, 2 ; dt = 0.1
    np.testing.assert_allclose(positive_work(torque, omega, 0.1), [0.8, 0.4])


def test_cost_of_transport_definitions():
    assert cost_of_transport(100.0, 10.0, 10.0, g=10.0) == pytest.approx(0.1)
    assert cost_of_transport_per_kg(100.0, 10.0, 10.0) == pytest.approx(1.0)
    assert cost_of_transport_per_kg(50.0, 10.2, 3.0) == pytest.approx(9.81 * cost_of_transport(50.0, 10.2, 3.0))
    assert math.isinf(cost_of_transport(1.0, 10.0, 0.0))
    assert math.isinf(cost_of_transport(1.0, 10.0, -1.0))
    with pytest.raises(ValueError, match="mass_kg"):
        cost_of_transport(1.0, 0.0, 1.0)
