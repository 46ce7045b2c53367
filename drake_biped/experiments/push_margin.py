"""Push margins: the largest forward and backward push the gait survives, with and without a torque-free
period, by bisection on Dask (beyond the paper, which pushes with 20 N only)."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from drake_biped.experiments.stability import CONDITIONS, condition_window, survives
from drake_biped.paper import PUSH_DURATION_S, PUSH_START_S
from drake_biped.params import EpisodeConfig, ParameterError, Push
from drake_biped.records import write_atomic, write_text_atomic
from drake_biped.versions import versions

__all__ = ["PushMarginSettings", "markdown", "push_margin", "run"]


@dataclass(frozen=True)
class PushMarginSettings:
    """The gait, the torque-free period compared with none, and the bisection's range and tolerance."""

    config: EpisodeConfig = field(default_factory=EpisodeConfig)
    window: tuple[float, float] = (0.2, 0.5)
    max_force_n: float = 200.0
    tolerance_n: float = 1.0
    push_start_s: float = PUSH_START_S
    push_duration_s: float = PUSH_DURATION_S


def push_margin(base: EpisodeConfig, window: tuple[float, float], client, max_force_n: float = 200.0,
                tolerance_n: float = 1.0, push_start_s: float = 0.4, push_duration_s: float = 0.1,
                progress: Callable[[int], None] | None = None) -> dict[str, Any]:
    """The largest forward and backward push (N over `push_duration_s`, from `push_start_s`) after which the
    gait still walks its distance, without and with the torque-free period `window`, by bisection.

    Four bisections (condition x direction) advance together, one round of four episodes at a time. Each
    assumes survival is monotonic in the force between 0 and `max_force_n`; the record keeps every episode
    tried, so a non-monotonic case shows. The margin is the largest force that survived (its bracket's
    upper end is the smallest that fell, or `max_force_n` if none fell)."""
    from drake_biped.experiments.executor import episode_task

    if not (math.isfinite(max_force_n) and max_force_n > 0 and math.isfinite(tolerance_n) and tolerance_n > 0):
        raise ParameterError(f"max force {max_force_n!r} and tolerance {tolerance_n!r} must be > 0")
    distance = base.sim.distance_m
    chains = {}
    for condition in CONDITIONS:
        w = condition_window(condition, window)
        for direction, sign in (("forward", 1.0), ("backward", -1.0)):
            chains[(condition, direction)] = {"window": w, "sign": sign, "lo": 0.0, "hi": None, "tried": []}

    def config(chain, force):
        return base.replace(window=chain["window"],
                            push=Push(chain["sign"] * force, push_start_s, push_duration_s)).to_dict()

    # First round: the largest force; then bisect where it fell.
    rounds = 0
    pending = {key: max_force_n for key in chains}
    while pending:
        keys = list(pending)
        futures = [client.submit(episode_task, config(chains[k], pending[k]), pure=False) for k in keys]
        for key, result in zip(keys, client.gather(futures)):
            c, force = chains[key], pending[key]
            ok = survives(result, distance)
            c["tried"].append({"force_n": force, "survived": ok, "distance_m": result["distance_m"],
                               "fall_reason": result["fall_reason"]})
            if ok:
                c["lo"] = max(c["lo"], force)
            else:
                c["hi"] = force if c["hi"] is None else min(c["hi"], force)
        rounds += 1
        if progress:
            progress(rounds)
        pending = {}
        for key, c in chains.items():
            if c["hi"] is not None and c["hi"] - c["lo"] > tolerance_n:
                pending[key] = 0.5 * (c["lo"] + c["hi"])
    out: dict[str, Any] = {"window": list(window), "max_force_n": max_force_n, "tolerance_n": tolerance_n,
                           "push_start_s": push_start_s, "push_duration_s": push_duration_s, "margins": {}}
    for (condition, direction), c in chains.items():
        out["margins"].setdefault(condition, {})[direction] = {
            "survived_n": c["lo"], "fell_n": c["hi"], "impulse_ns": c["lo"] * push_duration_s,
            "tried": c["tried"]}
    return out


def markdown(record: dict[str, Any], tolerance_n: float, max_force_n: float) -> str:
    """push_margin.md: the margins as a table."""
    window = record["window"]
    lines = ["| | forward push survived (N) | backward push survived (N) |", "|---|---|---|"]
    for condition, name in (("without", "without torque-free period"),
                            ("with", f"with torque-free period {window[0]:.3f}-{window[1]:.3f} s")):
        m = record["margins"][condition]
        lines.append(f"| {name} | {m['forward']['survived_n']:.1f} | {m['backward']['survived_n']:.1f} |")
    return "\n".join(lines) + (f"\n\nPush for {record['push_duration_s']:g} s from {record['push_start_s']:g} s; "
                               f"bisection to {tolerance_n:g} N, up to {max_force_n:g} N.\n")


def run(settings: PushMarginSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The four bisections on `client` (a LocalCluster when None); writes push_margin.json and
    push_margin.md into `out`. The record."""
    import sys

    from drake_biped.experiments.executor import client_or_local

    out = Path(out)
    code = versions()
    with client_or_local(client) as c:
        record = push_margin(settings.config, settings.window, c, max_force_n=settings.max_force_n,
                             tolerance_n=settings.tolerance_n, push_start_s=settings.push_start_s,
                             push_duration_s=settings.push_duration_s,
                             progress=(lambda n: print(f"round {n}", file=sys.stderr)) if progress else None)
    record.update(config=settings.config.to_dict(), versions=code)
    out.mkdir(parents=True, exist_ok=True)
    write_atomic(out / "push_margin.json", record)
    write_text_atomic(out / "push_margin.md", markdown(record, settings.tolerance_n, settings.max_force_n))
    return record
