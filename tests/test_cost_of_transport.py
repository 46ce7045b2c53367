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


@pytest.mark.parametrize("value, shown", [(0.5564869788508277, "0.5565"), (5.683e-06, "0.000005683"),
                                          (12.3, "12.30"), (0.0, "0.000"), (None, "n/a"), (0.3, "0.3000")])
def test_a_cost_is_printed_to_four_significant_digits_never_a_small_one_as_zero(value, shown):
    from drake_biped.analysis.cost_of_transport import format_cost, format_cost_interval

    assert format_cost(value) == shown
    if value:
        assert float(format_cost(value)) == pytest.approx(value, rel=1e-3)
    assert format_cost_interval(0.60511, 0.00171) == "0.6051 ± 0.0017"
    assert format_cost_interval(2.3e-5, 1.1e-7) == "0.00002300 ± 0.00000011"
