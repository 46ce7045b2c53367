"""The one executor of every parallel experiment: Dask, on an embedded LocalCluster by default, or on an
existing scheduler given its address (`--workers N | --scheduler ADDR` on every parallel command).

Workers receive numbers (EpisodeConfig dictionaries), never Drake objects (they do not pickle), and build
their own diagrams; the toolkit must be installed on every worker. Scripts that start a LocalCluster spawn
worker processes, so their entry point needs the `if __name__ == "__main__":` guard.
"""

from __future__ import annotations

import logging
import os
import re
import resource
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from drake_biped.params import ParameterError

SCHEDULER_TIMEOUT = "10s"
# How long a scheduler may be without a worker before the run says so and stops (s).
WORKER_WAIT_S = 10.0
_ADDRESS = re.compile(r"^(tcp|tls|inproc|ucx)://[^\s/]+(:\d+)?$")
# A local worker is one process running one CPU-bound episode at a time (a Drake diagram of its own, a few
# hundred MB): more than this many per core only adds memory and switching. A scheduler's workers are that
# cluster's business.
MAX_LOCAL_WORKERS_PER_CORE = 2


def max_local_workers() -> int:
    """The most local workers this machine is asked to hold without --force."""
    return MAX_LOCAL_WORKERS_PER_CORE * max(1, os.cpu_count() or 1)


def check_scheduler_address(address: str) -> str:
    """The address unchanged, or ParameterError naming it (expected form: tcp://HOST:PORT)."""
    if not isinstance(address, str) or not _ADDRESS.match(address):
        raise ParameterError(f"--scheduler {address!r}: expected an address like tcp://HOST:PORT")
    return address


def check_cluster_options(workers: int | None, scheduler: str | None, force: bool = False) -> None:
    """ParameterError unless the options name one cluster: --scheduler ADDR, or a local one of --workers N
    that this machine can hold (at most `max_local_workers()`, unless `force`)."""
    if scheduler is not None:
        if workers is not None:
            raise ParameterError("--workers sizes the local cluster; it cannot be combined with --scheduler")
        check_scheduler_address(scheduler)
    elif workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ParameterError(f"--workers {workers!r}: must be an integer >= 1")
    elif workers is not None and workers > max_local_workers() and not force:
        raise ParameterError(f"--workers {workers}: more local worker processes than this machine holds (limit "
                             f"{max_local_workers()}: {MAX_LOCAL_WORKERS_PER_CORE} per core, {os.cpu_count()} "
                             "cores); give --force (force=True) to start them anyway, or --scheduler for a cluster")


@contextmanager
def client_or_local(client: Any = None) -> Iterator[Any]:
    """`client` itself when given, else a LocalCluster's client for the duration of the block."""
    if client is not None:
        yield client
        return
    with dask_client() as local:
        yield local


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None, force: bool = False) -> Iterator[Any]:
    """A `distributed.Client`: on `scheduler` when given, else on a LocalCluster of `workers` processes.

    The local cluster binds to 127.0.0.1 only, runs one thread per worker (Drake episodes are CPU-bound
    and hold the GIL), and has no dashboard. Defaults to one worker per core; more than `max_local_workers()`
    only with `force`.
    """
    from distributed import Client

    logging.getLogger("distributed").setLevel(logging.WARNING)
    check_cluster_options(workers, scheduler, force)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
        except (OSError, TimeoutError) as exc:
            raise ParameterError(f"--scheduler {scheduler}: no Dask scheduler answered within "
                                 f"{SCHEDULER_TIMEOUT} ({type(exc).__name__}); start one (dask scheduler) or "
                                 "check the address") from None
        try:
            client.wait_for_workers(1, timeout=WORKER_WAIT_S)
        except (OSError, TimeoutError):
            client.close()
            raise ParameterError(f"--scheduler {scheduler}: the scheduler answers but has no workers (none joined "
                                 f"within {WORKER_WAIT_S:g} s); start one: dask worker {scheduler}") from None
        watch = WorkerWatch(client, scheduler)
        interrupted = False
        try:
            yield client
        except BaseException as exc:
            interrupted = isinstance(exc, KeyboardInterrupt)
            if watch.lost is not None and not isinstance(exc, (KeyboardInterrupt, SystemExit)):
                raise ClusterLost(watch.lost) from exc  # its tasks were cancelled: the workers were gone
            raise
        finally:
            watch.stop()
            _close(client, None, interrupted)
        return
    n = workers or max(1, os.cpu_count() or 1)
    with _workers_ignore_ctrl_c():
        cluster = _local_cluster(n)
    client = Client(cluster)
    interrupted = False
    try:
        yield client
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        _close(client, cluster, interrupted)


# The loggers silenced while a client closes after an interrupt (Dask's, and asyncio's and tornado's under it).
_SHUTDOWN_LOGGERS = ("distributed", "asyncio", "tornado")


class _AbandonedWaits(logging.Filter):
    """Drops asyncio's "Task exception was never retrieved" for the waits of a gather that Ctrl-C (or SIGTERM)
    abandoned: distributed's AllExit, raised in each as the client closes and cancels their futures, whenever the
    tasks are collected, which may be after the client is gone."""

    def filter(self, record: logging.LogRecord) -> bool:
        from distributed.client import AllExit

        exc = record.exc_info[1] if record.exc_info else None
        return not isinstance(exc, AllExit)


_ABANDONED_WAITS = _AbandonedWaits()


def _close(client: Any, cluster: Any, interrupted: bool) -> None:
    """Close the client, then its local cluster (None: a scheduler's, left running). After an interrupt, quietly:
    the run has already stopped and says so in one line, so what Dask logs and raises while closing under the
    abandoned tasks (cancelled futures, closed comms) is not news."""
    if not interrupted:
        client.close()
        if cluster is not None:
            cluster.close()
        return
    import asyncio

    from distributed.comm import CommClosedError

    logging.getLogger("asyncio").addFilter(_ABANDONED_WAITS)
    loggers = [logging.getLogger(name) for name in _SHUTDOWN_LOGGERS]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        for closing in (client, cluster):
            if closing is None:
                continue
            try:
                closing.close()
            except (asyncio.CancelledError, CommClosedError, OSError, TimeoutError, RuntimeError):
                pass
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


class ClusterLost(RuntimeError):
    """The cluster had no worker for WORKER_WAIT_S while a run waited on it: the run stops and says so."""


class WorkerWatch:
    """Watches a scheduler's workers from a thread while a run uses it: when none is left for WORKER_WAIT_S,
    the client's pending tasks are cancelled (the run waiting on them stops at once) and `lost` says why."""

    def __init__(self, client: Any, scheduler: str, poll_s: float = 1.0):
        self.client, self.scheduler, self.poll_s = client, scheduler, poll_s
        self.lost: str | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="drake-biped-worker-watch", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        import time

        since = None
        while not self._stop.wait(self.poll_s):
            try:
                n = len(self.client.scheduler_info().get("workers", {}))
            except Exception:  # the client is closing
                return
            if n > 0:
                since = None
                continue
            since = since or time.monotonic()
            if time.monotonic() - since >= WORKER_WAIT_S and self.client.futures:
                self.lost = (f"--scheduler {self.scheduler}: every worker left the cluster and none came back within "
                             f"{WORKER_WAIT_S:g} s; start one (dask worker {self.scheduler}) and rerun the command "
                             "to resume")
                from distributed import Future

                self.client.cancel([Future(key, self.client) for key in list(self.client.futures)])
                return

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5.0)


@contextmanager
def _workers_ignore_ctrl_c() -> Iterator[None]:
    """Worker processes started inside this block ignore SIGINT (they inherit its disposition), so Ctrl-C
    reaches the driver alone: it stops the run, closes the cluster and says how to resume, while the workers
    print no tracebacks of their own."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _local_cluster(n: int):
    import dask
    from distributed import LocalCluster

    # The worker processes log only what is critical (set in their environment before they start, as Dask
    # reads its logging levels on import): a task's failure reaches the driver, which says it in one line, and
    # what a worker logs at ERROR when the cluster closes under it (a heartbeat to a scheduler already gone,
    # after Ctrl-C) is not a failure of the run.
    # The scheduler never drops a worker for a late heartbeat (Dask's worker-ttl, 5 minutes): its workers are this
    # machine's processes, whose deaths it sees when their connections close, and a run suspended longer (Ctrl-Z,
    # a laptop asleep) would otherwise lose every task running when it wakes, the workers removed before they
    # could beat again.
    environ = {**dask.config.get("distributed.nanny.pre-spawn-environ", {}), "DASK_LOGGING__DISTRIBUTED": "critical"}
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ, "distributed.scheduler.worker-ttl": None}):
        return LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            # The scheduler's HTTP endpoints (health, metrics) on a free port, not 8787: no clash, and no
            # warning, when another cluster runs on the machine.
            scheduler_kwargs={"dashboard": False, "dashboard_address": "127.0.0.1:0"},
            silence_logs=logging.ERROR,
        )


def peak_rss_mb() -> float:
    """Peak resident memory of this process (MB)."""
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 1024.0 if sys.platform != "darwin" else rss / 2**20


class DrakeGuarded:
    """`fn` as a Dask task: a failed check inside Drake (pydrake's SystemExit, which would end the worker, not
    the task) is raised as DrakeFailure naming `fn`, and reaches the driver as any task error does."""

    def __init__(self, fn: Callable[..., Any]):
        self.fn = fn
        self.__name__ = getattr(fn, "__name__", "task")  # what Dask names the task's keys by

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        from drake_biped.api_guard import drake_failures_raised

        with drake_failures_raised(f"{self.__name__} on a Dask worker"):
            return self.fn(*args, **kwargs)


def episode_task(config: dict[str, Any], kick: dict[str, float] | None = None) -> dict[str, Any]:
    """Run one episode from an EpisodeConfig dictionary (with an optional swing-hip kick: the fields of
    drake_biped.episode.Kick); its result dictionary plus worker bookkeeping."""
    from drake_biped.api_guard import drake_failures_raised
    from drake_biped.episode import Kick, run_episode
    from drake_biped.legacy import config_of_record

    t0 = time.perf_counter()
    with drake_failures_raised("episode on a Dask worker"):  # a SystemExit would end the worker, not the task
        result = run_episode(config_of_record(config), kick=Kick(**kick) if kick else None).to_dict()
    result["task_wall_time_s"] = time.perf_counter() - t0
    result["worker_peak_rss_mb"] = peak_rss_mb()
    return result


def run_kept(
    client: Any,
    jobs: dict[Any, tuple[Any, ...]],
    progress: Callable[[int, int], None] | None = None,
) -> dict[Any, dict[str, Any]]:
    """One episode per job {key: (path, EpisodeConfig dict)} or {key: (path, config dict, kick)} (a kick: the
    fields of drake_biped.episode.Kick), each result kept at its path (atomically): a result already there for
    the same configuration and kick is read back instead of run. Results by key; progress(done, total) as they
    come."""

    from distributed import as_completed

    from drake_biped.records import read_kept, write_atomic

    results: dict[Any, dict[str, Any]] = {}
    todo = {}
    for key, (path, config, *rest) in jobs.items():
        kick = rest[0] if rest else None
        saved = read_kept(path)
        if isinstance(saved, dict):
            if saved.get("config") == config and saved.get("kick") == kick:
                results[key] = saved
                continue
        todo[key] = (path, config, kick)
    if progress:
        progress(len(results), len(jobs))
    futures = {client.submit(episode_task, config, kick, pure=False): key for key, (_, config, kick) in todo.items()}
    for future in as_completed(list(futures)):
        key = futures[future]
        r = future.result()
        r.pop("task_wall_time_s", None)
        r.pop("worker_peak_rss_mb", None)
        if todo[key][2] is not None:
            r["kick"] = todo[key][2]
        todo[key][0].parent.mkdir(parents=True, exist_ok=True)
        write_atomic(todo[key][0], r)
        results[key] = r
        if progress:
            progress(len(results), len(jobs))
    return results


def map_episodes(
    client: Any,
    configs: Sequence[dict[str, Any]],
    keep: Sequence[Any] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """One episode per EpisodeConfig dict, results in the configurations' order; with `keep` (a path per
    configuration), each result kept at its path as it finishes and read back by a rerun (`run_kept`), so that
    an interrupted run resumes. progress(done, total) as they come."""
    if keep is None:
        return map_ordered(client, episode_task, list(configs),
                           (lambda n, r: progress(n, len(configs))) if progress else None)
    if len(keep) != len(configs):
        raise ValueError(f"map_episodes: {len(keep)} paths for {len(configs)} configurations")
    kept = run_kept(client, {i: (path, config) for i, (path, config) in enumerate(zip(keep, configs))}, progress)
    return [kept[i] for i in range(len(configs))]


def map_ordered(
    client: Any,
    fn: Callable[[Any], Any],
    items: Sequence[Any],
    progress: Callable[[int, Any], None] | None = None,
) -> list[Any]:
    """fn over items on the cluster, results in the items' order; progress(done, result) as each finishes.
    A failed check inside Drake in `fn` is a DrakeFailure (`DrakeGuarded`)."""
    from distributed import as_completed

    futures = client.map(DrakeGuarded(fn), list(items), pure=False)
    index = {f.key: i for i, f in enumerate(futures)}
    results: list[Any] = [None] * len(futures)
    for done, future in enumerate(as_completed(futures), start=1):
        results[index[future.key]] = future.result()
        if progress is not None:
            progress(done, results[index[future.key]])
    return results
