"""analysis.attractor on series and maps whose answer is known: the period a walk's step periods show, and the
largest Lyapunov exponent of a map from its Jacobians and from two nearby orbits."""

import math

import numpy as np
import pytest

from drake_biped.analysis.attractor import (
    lyapunov_from_jacobians,
    lyapunov_from_neighbours,
    step_period_label,
)


@pytest.mark.parametrize("pattern, expected", [
    ([0.426], "period-1"), ([0.41, 0.47], "period-2"), ([0.40, 0.45, 0.52, 0.43], "period-4"),
])
def test_repeating_step_periods_are_named_by_their_period(pattern, expected):
    rng = np.random.default_rng(0)
    periods = np.tile(pattern, 60)[:60] + rng.uniform(-0.0009, 0.0009, 60)  # within the 2 ms tolerance
    assert step_period_label(periods)["attractor"] == expected


def test_step_periods_that_do_not_repeat_are_irregular_and_a_fall_is_a_fall():
    rng = np.random.default_rng(1)
    periods = 0.41 + 0.2 * rng.random(60)
    label = step_period_label(periods)
    assert label["attractor"] == "irregular" and label["period"] is None and label["spread_s"] > 0.1
    assert step_period_label(periods, fell=True)["attractor"] == "fell"
    assert step_period_label(periods[:10])["attractor"] == "too short"
    # period-1 exactly where the last 20 periods vary by less than 2 ms
    steady = np.full(40, 0.426)
    steady[-7] += 0.0025
    assert step_period_label(steady)["attractor"] != "period-1"
    drifting = 0.426 + 0.00015 * np.arange(40)  # each step within 2 ms of the last, the last 20 spread 2.85 ms
    assert step_period_label(drifting)["attractor"] != "period-1"
    assert step_period_label(drifting[:-14], window=6)["attractor"] == "period-1"


# The last 40 step periods of a measured 32 m walk (the 2.0 deg grid's best gait on 0.005 rad with a window):
# a steady step rounded by the 1 kHz controller, spread 3.7 ms.
JITTERED = [0.4378, 0.4369, 0.4375, 0.4372, 0.4387, 0.4369, 0.437, 0.4366, 0.4374, 0.4372, 0.4381, 0.4374,
            0.4371, 0.4369, 0.4377, 0.4373, 0.4383, 0.4354, 0.4391, 0.4362, 0.4379, 0.4364, 0.4378, 0.4368,
            0.4376, 0.4375, 0.4383, 0.4375, 0.4381, 0.4375, 0.4363, 0.4382, 0.4368, 0.4387, 0.4366, 0.4376,
            0.4376, 0.4368, 0.4374, 0.4373]


def test_a_period_1_walk_jittering_past_the_tolerance_is_not_a_longer_period():
    """Every 5th of JITTERED's last 20 periods stays within 2 ms by chance, but the five "points" lie 0.4 ms
    apart: irregular at 2 ms, period-1 at 10 ms; the same walk alternating by 10.7 ms is a period-2 orbit."""
    periods = np.array(JITTERED)
    tail = periods[-20:]
    assert all(np.ptp(tail[r::5]) < 0.002 for r in range(5))  # what once named it period-5
    assert step_period_label(periods)["attractor"] == "irregular"
    assert step_period_label(periods, tolerance_s=0.010)["attractor"] == "period-1"
    alternating = periods + np.tile([0.0, 0.0107], 20)
    assert step_period_label(alternating, tolerance_s=0.010, max_period=2)["attractor"] == "period-2"


def _logistic_orbit(r, x0, n):
    xs = [x0]
    for _ in range(n - 1):
        xs.append(r * xs[-1] * (1 - xs[-1]))
    return np.array(xs)


def test_the_logistic_map_at_4_has_the_exponent_ln_2():
    xs = _logistic_orbit(4.0, 0.1234, 20000)
    jacobians = [np.array([[4.0 * (1 - 2 * x)]]) for x in xs]
    assert lyapunov_from_jacobians(jacobians, discard=10) == pytest.approx(math.log(2.0), abs=0.02)


def test_a_contracting_linear_map_has_the_log_of_its_largest_eigenvalue():
    a = np.array([[0.8, 0.3], [0.0, -0.5]])
    assert lyapunov_from_jacobians([a] * 400, discard=50) == pytest.approx(math.log(0.8), abs=1e-6)


def test_nearby_orbits_of_the_henon_map_part_at_its_exponent():
    """The Hénon map (a 1.4, b 0.3), largest exponent about 0.42 per step: two orbits 1e-9 apart."""
    def henon(s):
        return np.array([1 - 1.4 * s[0] ** 2 + s[1], 0.3 * s[0]])

    x = np.array([0.1, 0.1])
    for _ in range(1000):
        x = henon(x)
    estimates = []
    for _ in range(20):
        a, b = [x], [x + np.array([1e-9, 0.0])]
        for _ in range(40):
            a.append(henon(a[-1]))
            b.append(henon(b[-1]))
        estimates.append(lyapunov_from_neighbours(np.array(a), np.array(b))["exponent"])
        x = a[7]
    assert np.median(estimates) == pytest.approx(0.42, abs=0.08)
