"""GARB on problems whose answers are known."""

import json

import numpy as np
import pytest

from drake_biped.learners.garb import TABLE_II, GarbLearner, learning_rate


def test_one_update_equals_the_hand_computed_step():
    g = GarbLearner(mean=(0.5, 0.5), beta=0.8, seed=1)
    # Episode 1: e = (0.1, -0.2), Z = e, B = 2.0 (the first reward), advantage 0: mean unchanged.
    g.update((0.6, 0.3), 2.0)
    np.testing.assert_allclose(g.mean, [0.5, 0.5])
    np.testing.assert_allclose(g.trace, [0.1, -0.2])
    assert g.baseline == pytest.approx(2.0)
    # Episode 2: e = (-0.1, 0.1), Z = e + 0.8 * (0.1, -0.2) = (-0.02, -0.06), B = 2 + (4 - 2) / 2 = 3,
    # mean += 0.1 * (4 - 3) * Z.
    g.update((0.4, 0.6), 4.0)
    np.testing.assert_allclose(g.trace, [-0.02, -0.06])
    assert g.baseline == pytest.approx(3.0)
    np.testing.assert_allclose(g.mean, [0.5 - 0.002, 0.5 - 0.006])
    assert g.episodes == 2


@pytest.mark.parametrize("episode, rate", [(1, 0.1), (100, 0.1), (101, 0.05), (200, 0.05), (201, 0.01),
                                           (300, 0.01), (301, 0.005), (400, 0.005), (401, 0.001), (5000, 0.001)])
def test_table_ii_schedule_boundaries(episode, rate):
    assert learning_rate(episode) == rate
    assert learning_rate(episode, TABLE_II) == rate


def test_learner_climbs_to_a_known_optimum():
    """Reward -|t - (0.2, 0.6)|^2: the mean moves there from (0.5, 0.5) (20 seeds tried: within 0.032)."""
    target = np.array([0.2, 0.6])
    g = GarbLearner(seed=3, schedule=[(1000, 0.1), (None, 0.02)])
    for _ in range(3000):
        t = g.sample()
        g.update(t, float(-np.sum((t - target) ** 2)))
    assert np.linalg.norm(g.mean - target) < 0.05
    assert np.linalg.norm(np.array([0.5, 0.5]) - target) > 0.3


def test_samples_have_the_policy_variance():
    g = GarbLearner(mean=(1.0, -1.0), variance=0.04, seed=0)
    s = np.array([g.sample() for _ in range(20000)])
    np.testing.assert_allclose(s.mean(axis=0), [1.0, -1.0], atol=0.01)
    np.testing.assert_allclose(s.var(axis=0), [0.04, 0.04], rtol=0.05)


def test_state_round_trips_through_json_and_continues_identically():
    a = GarbLearner(seed=7)
    for r in (1.0, 3.0, 2.0):
        a.update(a.sample(), r)
    b = GarbLearner.from_state(json.loads(json.dumps(a.state())))
    for r in (5.0, 0.5, 4.0):
        ta, tb = a.sample(), b.sample()
        np.testing.assert_array_equal(ta, tb)
        a.update(ta, r)
        b.update(tb, r)
    assert a.state() == b.state()


def test_same_seed_same_samples():
    assert np.array_equal(GarbLearner(seed=5).sample(), GarbLearner(seed=5).sample())


@pytest.mark.parametrize("kwargs, match", [
    ({"mean": (0.5,)}, "mean"), ({"variance": 0.0}, "variance"), ({"beta": 1.0}, "beta"),
    ({"schedule": [(100, 0.1), (50, 0.05)]}, "increasing"), ({"schedule": [(None, 0.1), (10, 0.1)]}, "last band"),
    ({"schedule": [(10, float("nan"))]}, "learning rate"),
])
def test_bad_settings_are_refused(kwargs, match):
    with pytest.raises(ValueError, match=match):
        GarbLearner(**kwargs)


def test_non_finite_reward_is_refused():
    with pytest.raises(ValueError, match="reward"):
        GarbLearner().update((0.5, 0.5), float("inf"))
