"""The shipped gaits' `about` texts: each claim that a short walk can check, checked. Every phrase below stands in
its gait's about, and the walk beside it (a few metres) does what the phrase says; every shipped gait has one."""

import math

import pytest

from drake_biped.episode import run_episode
from drake_biped.resources import gait_about, gait_names, load_gait

METRES = 2.0


def _walk(name: str, metres: float = METRES, **changes):
    return run_episode(load_gait(name).override({"sim.distance_m": metres, "sim.max_time_s": 20.0, **changes}))


def walks(name: str, metres: float = METRES, **changes) -> bool:
    r = _walk(name, metres, **changes)
    return not r.fell and r.distance_m >= metres - 1e-6


def falls_after(name: str, steps: int, **changes) -> bool:
    """Falls with exactly `steps` touchdowns recorded (a walk of 3 m: a fall, not the distance, ends it)."""
    r = _walk(name, 3.0, **changes)
    return r.fell and len(r.steps) == steps


def climbs(name: str, slope_rad: float) -> bool:
    """Walks 2 m level and 1 m up `slope_rad` (the slope story's ground, shortened)."""
    return walks(name, 3.0, **{"ground.slope_rad": slope_rad, "ground.level_length_m": 2.0})


# gait: [(a phrase of its about, the short walk that checks it)]
CLAIMS = {
    "fast_servo": [("a walker of our own", lambda: walks("fast_servo")),
                   ("0.43 s steps at a 1 ms plant step",
                    lambda: load_gait("fast_servo").sim.time_step_s == 0.001
                    and abs(_walk("fast_servo", 4.0).step_period_s / 0.43 - 1.0) < 0.05)],
    "paper": [("Table III walks: 100 m at 0.5 ms",
               lambda: load_gait("paper").sim.time_step_s == 0.0005 and walks("paper"))],
    "paper_entrained": [
        ("falls in its first step at a 1 ms plant step",
         lambda: falls_after("paper_entrained", 1, **{"sim.time_step_s": 0.001})),
        ("and at 0.5 ms under the paper's clock",
         lambda: falls_after("paper_entrained", 1, **{"sim.time_step_s": 0.0005})),
        ("walks at 0.5 ms only with the controller kept a 1 kHz loop",
         lambda: walks("paper_entrained", **{"sim.time_step_s": 0.0005, "sim.control_period_s": 0.001})),
    ],
    "paper_servo": [("it falls after three steps", lambda: falls_after("paper_servo", 3))],
    "climbing": [("it climbs 0.02 rad without a window", lambda: climbs("climbing", 0.02))],
    "climbing_2deg": [("it climbs 2.0 deg", lambda: climbs("climbing_2deg", math.radians(2.0)))],
}


def test_every_shipped_gait_has_its_claims_checked():
    assert set(CLAIMS) == set(gait_names())


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CLAIMS))
def test_a_gaits_cheap_claims_hold_on_a_short_walk(name):
    about = gait_about(name)
    for phrase, check in CLAIMS[name]:
        assert phrase in about, (name, phrase)
        assert check(), f"{name}: {phrase!r} does not hold on a {METRES:g} m walk"
