import pytest
from walkers import fast_config

from drake_biped.episode import run_episode
from drake_biped.params import SimulationParams


@pytest.fixture(scope="session")
def client():
    """A LocalCluster of two workers, shared by the tests that run episodes in parallel."""
    from drake_biped.common.executor import dask_client

    with dask_client(workers=2) as c:
        yield c


@pytest.fixture(scope="session")
def short_walk():
    """A 3 m walk of the default gait, recorded once for several tests."""
    config = fast_config(sim=SimulationParams(distance_m=3.0, max_time_s=15.0))
    return run_episode(config, record_trajectory=True)
