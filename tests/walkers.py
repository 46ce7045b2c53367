"""The gaits tests walk, named. `EpisodeConfig()` is the paper's walker (0.90 s steps at a 0.5 ms plant step); a
test that needs its walks quick walks our own faster gait, `fast_servo` (0.43 s steps at 1 ms), by name."""

import dataclasses

from drake_biped.params import EpisodeConfig, SimulationParams
from drake_biped.resources import load_gait

FAST = load_gait("fast_servo")


def fast_config(**sections) -> EpisodeConfig:
    """`fast_servo` with whole sections replaced, as `EpisodeConfig(**sections)` replaces the default's. A sim given
    at the class's default plant step walks fast_servo's own step (1 ms): name another with `.override`."""
    sim = sections.get("sim")
    if sim is not None and sim.time_step_s == SimulationParams().time_step_s:
        sections["sim"] = dataclasses.replace(sim, time_step_s=FAST.sim.time_step_s)
    return FAST.replace(**sections)
