"""Every learner of the torque-free window on rewards with a known optimum, and its exact resume."""

import json
import math

import numpy as np
import pytest

from drake_biped.learners import (
    LEARNERS,
    CmaesLearner,
    GarbLearner,
    Learner,
    PgpeLearner,
    learner_from_state,
    make_learner,
    register_learner,
)

OPTIMUM = np.array([0.3, 0.7])


def bowl(t) -> float:
    """A smooth reward with its maximum 5 at OPTIMUM (the scale of 1 / C_mt)."""
    return 5.0 * math.exp(-float(np.sum((np.asarray(t) - OPTIMUM) ** 2)) / (2 * 0.25 ** 2))


def learn(learner, episodes: int, reward=bowl):
    for _ in range(episodes):
        t = learner.ask()
        learner.tell(t, reward(t))
    return learner


# Each learner's own step: GARB's Table II rates are for the paper's reward scale and 500 episodes; on
# this bowl a schedule of the same shape, five times faster, shows the same update finding the optimum.
OPTIONS = {"garb": {"schedule": [(100, 0.05), (200, 0.025), (None, 0.005)]}, "cmaes": {}, "pgpe": {}}


@pytest.mark.parametrize("name", ["garb", "cmaes", "pgpe"])
def test_each_learner_finds_the_known_optimum(name):
    learner = learn(make_learner(name, mean=(0.5, 0.5), variance=0.04, seed=5, **OPTIONS[name]), 500)
    assert np.linalg.norm(learner.mean - OPTIMUM) < 0.05, learner.mean
    assert bowl(learner.mean) > 0.95 * 5.0


@pytest.mark.parametrize("name", ["garb", "cmaes", "pgpe"])
def test_a_resumed_learner_continues_exactly(name):
    """Saved after 37 episodes (inside a CMA-ES generation, inside a PGPE pair), through JSON, restored:
    the next samples and means are those of the learner that never stopped."""
    whole = make_learner(name, seed=11, **OPTIONS[name])
    part = make_learner(name, seed=11, **OPTIONS[name])
    learn(whole, 37)
    learn(part, 37)
    t = part.ask()  # one handed out and not yet told
    saved = json.loads(json.dumps(part.state()))
    resumed = learner_from_state(saved)
    assert type(resumed) is LEARNERS[name]
    t_whole = whole.ask()
    np.testing.assert_array_equal(t, t_whole)
    for learner, sample in ((whole, t_whole), (resumed, t)):  # the driver keeps the pending sample
        learner.tell(sample, bowl(sample))
        learn(learner, 25)
    np.testing.assert_array_equal(whole.mean, resumed.mean)
    np.testing.assert_array_equal(whole.ask(), resumed.ask())


def test_garb_through_the_interface_is_the_paper_update():
    a, b = GarbLearner(seed=5), make_learner("garb", seed=5)
    for _ in range(20):
        t = a.sample()
        a.update(t, bowl(t))
        s = b.ask()
        b.tell(s, bowl(s))
    np.testing.assert_array_equal(a.mean, b.mean)
    assert b.info() == {"baseline": a.baseline}


def test_cmaes_hands_out_its_population_in_order_and_refuses_a_wrong_tell():
    learner = CmaesLearner(seed=1)
    first = [learner.ask() for _ in range(6)]  # pycma's population for two parameters
    with pytest.raises(RuntimeError, match="tell their rewards"):
        learner.ask()
    with pytest.raises(ValueError, match="not the next sample"):
        learner.tell(first[1], 1.0)
    for t in first:
        learner.tell(t, bowl(t))
    assert learner.episodes == 6 and not np.allclose(learner.mean, (0.5, 0.5))
    assert learner.step == pytest.approx(learner.info()["step"])


def test_cmaes_starts_with_garbs_exploration():
    samples = np.array([CmaesLearner(seed=s).ask() for s in range(400)])
    assert np.mean(samples, axis=0) == pytest.approx([0.5, 0.5], abs=0.03)
    assert np.std(samples, axis=0) == pytest.approx([0.2, 0.2], rel=0.1)


def test_pgpe_samples_in_mirrored_pairs_and_adapts_sigma():
    learner = PgpeLearner(seed=2)
    a, b = learner.ask(), learner.ask()
    np.testing.assert_allclose(a + b, 2 * np.array([0.5, 0.5]))
    learner.tell(a, bowl(a))
    learner.tell(b, bowl(b))
    learn(learner, 300)
    assert np.all(learner.sigma < 0.2)  # exploration shrinks once the optimum is found


def test_make_learner_refuses_an_unknown_name():
    with pytest.raises(ValueError, match="learner 'sgd' is not one of"):
        make_learner("sgd")


def test_a_registered_learner_is_made_by_name():
    class RandomSearch(Learner):
        name = "random-test"

        def __init__(self, mean, variance, seed=None):
            self.mean, self._sd, self._rng, self._best = np.asarray(mean, float), math.sqrt(variance), \
                np.random.default_rng(seed), -math.inf

        def ask(self):
            return self.mean + self._sd * self._rng.standard_normal(2)

        def tell(self, sample, reward):
            if reward > self._best:
                self._best, self.mean = reward, np.asarray(sample, float)

        def info(self):
            return {"best": self._best}

        def state(self):
            return {"learner": self.name, "mean": self.mean.tolist()}

        @classmethod
        def from_state(cls, state):
            return cls(state["mean"], 0.04)

    try:
        register_learner(RandomSearch)
        learner = learn(make_learner("random-test", seed=0), 200)
        assert np.linalg.norm(learner.mean - OPTIMUM) < 0.1
    finally:
        LEARNERS.pop("random-test", None)
    with pytest.raises(TypeError, match="not a subclass of drake_biped.learners.Learner"):
        register_learner(type("Nothing", (), {"name": "nothing", "ask": None, "tell": None}))

    class Half(Learner):  # declares the interface, implements part of it
        name = "half-test"

        def ask(self):
            return np.zeros(2)

    with pytest.raises(TypeError, match=r"Half leaves \['from_state', 'info', 'state', 'tell'\]"):
        register_learner(Half)
    assert "half-test" not in LEARNERS


def test_every_shipped_learner_declares_the_interface():
    for name, cls in LEARNERS.items():
        assert issubclass(cls, Learner) and cls.name == name and not cls.__abstractmethods__
        learner = cls.from_settings({"mean": [0.4, 0.6], "variance": 0.01, "beta": 0.8,
                                     "schedule": [[None, 0.01]], "options": {}}, seed=3)
        np.testing.assert_allclose(learner.mean, [0.4, 0.6])
        restored = learner_from_state(learner.state())
        assert type(restored) is cls and np.array_equal(restored.ask(), learner.ask())
