"""The leg laws: knee bang-bang with its clearance guard, touchdown, torso and ankle signs."""

import dataclasses
import math

import pytest

from drake_biped import gait
from drake_biped.params import GaitParams

# The knee law's every field given (the defaults are the paper's walker's): flexing until extension, no hold torque.
KNEE = dict(knee_flex_until_phase=math.pi, knee_hold_torque=0.0)
G = GaitParams(knee_flex_torque=5.0, knee_extend_torque=7.0, knee_extend_phase=2.0, knee_flex_max_rad=0.6,
               knee_extend_thigh_rad=0.2, **KNEE)


@pytest.mark.parametrize("gamma, knee, thigh, expected", [
    (1.0, 0.3, -0.2, 5.0),   # early swing: flex
    (1.0, 0.7, -0.2, -7.0),  # past the flexion limit: push back (bang-bang about the limit)
    (2.5, 0.3, 0.0, 5.0),    # phase has passed, but the thigh is not yet ahead: keep the foot up
    (2.5, 0.3, 0.25, -7.0),  # phase passed and thigh ahead: extend for touchdown
])
def test_swing_knee(gamma, knee, thigh, expected):
    assert gait.swing_knee_torque(G, gamma, knee, thigh) == expected


def test_swing_knee_passive_middle():
    g = GaitParams(knee_flex_torque=5.0, knee_extend_torque=7.0, knee_extend_phase=2.5, knee_flex_max_rad=1.2,
                   knee_extend_thigh_rad=0.2, knee_flex_until_phase=1.0, knee_hold_torque=0.0)
    assert gait.swing_knee_torque(g, 0.5, 0.3, -0.3) == 5.0  # flexion burst
    assert gait.swing_knee_torque(g, 1.5, 0.8, -0.1) == 0.0  # passive
    assert gait.swing_knee_torque(g, 1.5, 1.3, -0.1) == -7.0  # limit guard
    assert gait.swing_knee_torque(g, 2.6, 0.8, 0.3) == -7.0  # extension
    held = dataclasses.replace(g, knee_hold_torque=1.5)  # the passive middle held flexed, nothing else
    assert [gait.swing_knee_torque(held, *x) for x in ((0.5, 0.3, -0.3), (1.5, 0.8, -0.1), (1.5, 1.3, -0.1),
                                                      (2.6, 0.8, 0.3))] == [5.0, 1.5, -7.0, -7.0]


def test_swing_knee_switch_inside_a_period_blends_by_the_time_each_branch_holds():
    g = GaitParams(knee_flex_torque=5.0, knee_extend_torque=7.0, knee_extend_phase=2.5, knee_flex_max_rad=1.2,
                   knee_extend_thigh_rad=0.2, knee_flex_until_phase=1.0, knee_hold_torque=0.0)
    # the phase crosses knee_flex_until_phase a quarter of the way through: flex for 1/4, passive for 3/4
    assert gait.swing_knee_torque_over(g, (0.9, 0.5, -0.2), (1.3, 0.5, -0.2)) == pytest.approx(1.25, abs=1e-5)
    # the thigh reaches knee_extend_thigh_rad at 60 % of the period (phase already past 2.5): passive, then extend
    assert gait.swing_knee_torque_over(g, (2.6, 0.5, 0.14), (2.6, 0.5, 0.24)) == pytest.approx(-7.0 * 0.4, abs=1e-5)
    # no switch: the branch's torque exactly; and the blend is continuous as the crossing leaves the period
    assert gait.swing_knee_torque_over(g, (1.5, 0.5, 0.0), (1.6, 0.5, 0.0)) == 0.0
    assert gait.swing_knee_torque_over(g, (0.5, 0.5, 0.0), (1.0 - 1e-9, 0.5, 0.0)) == 5.0
    assert gait.swing_knee_torque_over(g, (0.5, 0.5, 0.0), (1.0 + 1e-9, 0.5, 0.0)) == pytest.approx(5.0, abs=1e-5)


def test_touchdown_needs_every_condition():
    ok = dict(time_in_step_s=0.5, swing_clearance_m=0.001, swing_ankle_advance_m=0.2, gamma=2.0)
    g = GaitParams(touchdown_min_step_s=0.15, touchdown_height_m=0.002, touchdown_min_advance_m=0.05,
                   touchdown_min_phase=1.0)
    assert gait.is_touchdown(g, **ok)
    for key, bad in (("time_in_step_s", 0.1), ("swing_clearance_m", 0.01), ("swing_ankle_advance_m", 0.0),
                     ("gamma", 0.5)):
        assert not gait.is_touchdown(g, **{**ok, key: bad})


def test_torso_and_ankle_signs():
    g = GaitParams(torso_kp=100.0, torso_kd=10.0, torso_pitch_rad=-0.1, ankle_kp=20.0, ankle_kd=1.0)
    # Torso leaning back of its reference: positive hip torque turns it forward (clockwise).
    assert gait.torso_torque(g, 0.0, 0.0) == pytest.approx(10.0)
    assert gait.torso_torque(g, -0.1, 1.0) == pytest.approx(10.0)
    # Toe up relative to the ground: torque pushes it down.
    assert gait.ankle_torque(g, 0.1, 0.0, 0.0) == pytest.approx(-2.0)
    assert gait.ankle_torque(g, 0.02, 0.0, 0.02) == pytest.approx(0.0)
    assert gait.clip(50.0, 40.0) == 40.0 and gait.clip(-50.0, 40.0) == -40.0
