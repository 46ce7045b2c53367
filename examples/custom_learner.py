"""Plug a new learner of the torque-free window in: a (1+1) evolution strategy with the 1/5th success rule.

    python examples/custom_learner.py [--episodes 12] [--distance 10]

A learner subclasses drake_biped.Learner: ask() -> (t1, t2), tell(sample, reward), mean, info(), state() and
from_state().
Registered, it is made by name like the shipped ones, and `drake-biped learn --learner NAME` could use it
(in a process that has registered it).
"""

import numpy as np

import drake_biped as db
from drake_biped.analysis.series import window_text  # a sample as the window it walks
from drake_biped.cli import integer, number, run_script, script_parser  # the commands' option checks


@db.register_learner
class OnePlusOne(db.Learner):
    name = "one-plus-one"

    def __init__(self, mean, variance, seed=None):
        self.mean, self.sigma, self.best = np.asarray(mean, float), float(np.sqrt(variance)), None
        self.rng = np.random.default_rng(seed)

    def ask(self):
        return self.mean if self.best is None else self.mean + self.sigma * self.rng.standard_normal(2)

    def tell(self, sample, reward):
        better = self.best is None or reward > self.best
        if better:
            self.mean, self.best = np.asarray(sample, float), reward
        self.sigma *= 1.5 if better else 1.5 ** -0.25  # the 1/5th success rule

    def info(self):
        return {"sigma": self.sigma, "best_reward": self.best}

    def state(self):
        return {"learner": self.name, "mean": self.mean.tolist(), "sigma": self.sigma, "best": self.best,
                "rng": self.rng.bit_generator.state}

    @classmethod
    def from_state(cls, state):
        learner = cls(state["mean"], state["sigma"] ** 2)
        learner.best, learner.rng.bit_generator.state = state["best"], state["rng"]
        return learner


parser = script_parser(__doc__)
parser.add_argument("--episodes", type=integer(1), default=12)
parser.add_argument("--distance", type=number("positive"), default=10.0, help="each episode's length (m)")
args = parser.parse_args()


def main() -> None:
    base = db.EpisodeConfig().override({"sim.distance_m": args.distance})
    learner = db.make_learner("one-plus-one", mean=(0.1, 0.2), variance=0.01, seed=0)
    for episode in range(1, args.episodes + 1):
        t1, t2 = learner.ask()
        result = db.run_episode(base.replace(window=db.TorqueFreeWindow(max(0.0, t1), max(0.0, t2))))
        learner.tell((t1, t2), db.reward(result.cost_of_transport, result.distance_m, args.distance))
        print(f"episode {episode:2d}: window {window_text(t1, t2)}, C_mt {result.cost_of_transport or float('nan'):.4f}, "
              f"best window so far {window_text(*learner.mean)}, sigma {learner.sigma:.3f}")


run_script(main)  # a bad value is one line and exit code 2, a failed run one line and 1, as for drake-biped
