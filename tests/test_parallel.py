"""Episodes on Dask give the numbers they give in this process; bad cluster options are refused."""

import pytest
from walkers import fast_config

from drake_biped.common.executor import check_scheduler_address, dask_client, episode_task, map_ordered
from drake_biped.episode import run_episode
from drake_biped.params import ParameterError, SimulationParams, TorqueFreeWindow


def test_episodes_on_a_local_cluster_equal_the_same_episodes_here():
    configs = [
        fast_config(sim=SimulationParams(distance_m=0.6, max_time_s=5.0), window=TorqueFreeWindow(*w))
        for w in ((0.0, 0.0), (0.2, 0.5))
    ]
    seen = []
    with dask_client(workers=1) as client:
        remote = map_ordered(client, episode_task, [c.to_dict() for c in configs], lambda n, r: seen.append(n))
    assert seen == [1, 2]
    for config, r in zip(configs, remote):
        local = run_episode(config)
        assert r["config"] == config.to_dict()  # results come back in the order of the inputs
        assert r["cost_of_transport"] == local.cost_of_transport
        assert r["duration_s"] == local.duration_s
        assert r["worker_peak_rss_mb"] > 50  # a worker that imported Drake


@pytest.mark.parametrize("address", ["localhost:8786", "http://host:8786", "tcp://", "tcp://a b:1", ""])
def test_malformed_scheduler_address_is_refused(address):
    with pytest.raises(ParameterError, match="scheduler"):
        check_scheduler_address(address)


def test_well_formed_scheduler_address_passes():
    assert check_scheduler_address("tcp://127.0.0.1:8786") == "tcp://127.0.0.1:8786"


@pytest.mark.parametrize("workers", [0, -1, 1.5])
def test_bad_worker_count_is_refused(workers):
    with pytest.raises(ParameterError, match="workers"):
        with dask_client(workers=workers):
            pass


def test_workers_and_scheduler_together_are_refused():
    with pytest.raises(ParameterError, match="workers"):
        with dask_client(workers=2, scheduler="tcp://127.0.0.1:1"):
            pass
