import pytest

from drake_biped.episode import run_episode
from drake_biped.params import EpisodeConfig, SimulationParams


@pytest.fixture(scope="session")
def short_walk():
    """A 3 m walk of the default gait, recorded once for several tests."""
    config = EpisodeConfig(sim=SimulationParams(distance_m=3.0, max_time_s=15.0))
    return run_episode(config, record_trajectory=True)
