"""analysis.floquet.periodic_orbit on maps whose orbits are known: the period, the points and the multipliers
of the k-fold map."""

import numpy as np
import pytest

from drake_biped.analysis.floquet import NoPeriodicOrbit, periodic_orbit, repeat_period


def logistic(r):
    return lambda x: r * x * (1.0 - x)


def test_a_linear_map_has_its_fixed_point_and_its_eigenvalues():
    a = np.array([[0.5, 0.2], [0.0, -0.3]])
    c = np.array([1.0, -2.0])
    orbit = periodic_orbit(lambda x: c + a @ (x - c), np.array([3.0, 4.0]))
    assert orbit.period == 1 and orbit.detected == 1 and orbit.converged
    assert np.allclose(orbit.points[0], c, atol=1e-9)
    assert np.allclose(sorted(orbit.multipliers.real), [-0.3, 0.5], atol=1e-8) and orbit.attracting


def test_the_logistic_map_past_its_first_doubling_has_the_two_cycle_of_its_formula():
    """r = 3.2: x± = ((r + 1) ± sqrt((r - 3)(r + 1))) / (2 r), the 2-fold map's multiplier -r² + 2r + 4."""
    r = 3.2
    orbit = periodic_orbit(lambda x: logistic(r)(x), np.array([0.3]))
    root = np.sqrt((r - 3.0) * (r + 1.0))
    assert orbit.period == 2 and orbit.converged
    assert np.allclose(sorted(orbit.points[:, 0]), [(r + 1 - root) / (2 * r), (r + 1 + root) / (2 * r)], atol=1e-9)
    assert orbit.multipliers[0].real == pytest.approx(-r * r + 2 * r + 4, abs=1e-6)


def test_a_four_cycle_in_two_dimensions_has_the_chain_rules_multipliers():
    """The logistic map at r = 3.5 (an attracting 4-cycle) driving a contracting second coordinate: the 4-fold
    map's multipliers are the product of f'(x_i) = r (1 - 2 x_i) over the cycle and 0.5⁴."""
    r = 3.5

    def step(s):
        return np.array([r * s[0] * (1.0 - s[0]), 0.5 * s[1] + s[0]])

    orbit = periodic_orbit(step, np.array([0.2, 0.0]))
    assert orbit.period == 4 and orbit.converged
    xs = orbit.points[:, 0]
    assert len(set(np.round(xs, 6))) == 4  # four distinct points: no shorter period
    for i in range(4):
        assert np.allclose(orbit.points[(i + 1) % 4], step(orbit.points[i]), atol=1e-9)
    chain = np.prod(r * (1.0 - 2.0 * xs))
    assert sorted(orbit.multipliers.real) == pytest.approx(sorted([chain, 0.5 ** 4]), abs=1e-6)


def test_a_repelling_orbit_is_found_when_its_period_is_given_and_chaos_is_named():
    """r = 3.2's fixed point 1 - 1/r repels (f' = 2 - r): found with period=1 from near it, multiplier
    2 - r; at r = 3.9 (chaos) the iterates repeat with no period up to 8."""
    r = 3.2
    orbit = periodic_orbit(lambda x: logistic(r)(x), np.array([0.69]), period=1)
    assert orbit.points[0, 0] == pytest.approx(1 - 1 / r, abs=1e-9) and orbit.detected is None
    assert orbit.multipliers[0].real == pytest.approx(2 - r, abs=1e-6) and not orbit.attracting
    with pytest.raises(NoPeriodicOrbit, match="no period up to 8"):
        periodic_orbit(lambda x: logistic(3.9)(x), np.array([0.3]))


def test_repeat_period_needs_the_repeat_over_the_whole_window():
    x = np.array([[v] for v in [0.1, 0.2] * 20])
    assert repeat_period(x) == 2
    x[-1, 0] += 1e-3
    assert repeat_period(x) is None
