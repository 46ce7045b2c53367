"""The (1 + lambda) gait search: mutation bounds, monotone parent score, resume."""

import json
import random

from drake_biped.experiments.gait_search import MUTATIONS, GaitSearchSettings, _read_log, mutate, run
from drake_biped.params import EpisodeConfig, SimulationParams


def test_mutation_changes_every_listed_parameter_within_bounds():
    c = EpisodeConfig()
    child = mutate(c, random.Random(1), sigma=0.5)
    for (section, name), (_, _, lo, hi) in MUTATIONS.items():
        before, after = getattr(getattr(c, section), name), getattr(getattr(child, section), name)
        assert lo <= after <= hi
        assert after != before
    assert child.initial == c.initial and child.sim == c.sim


def test_search_keeps_the_best_parent_and_resumes(tmp_path, client):
    start = EpisodeConfig(sim=SimulationParams(distance_m=0.3, max_time_s=3.0))
    kwargs = dict(offspring=2, sigma=0.3, seed=4, distance_m=0.3, windows=((0.1, 0.2),))
    run(GaitSearchSettings(start, generations=2, **kwargs), tmp_path, client, progress=False)
    records = _read_log(tmp_path / "search.jsonl")
    assert [r["generation"] for r in records] == [0, 1, 2]
    scores = [r["parent_score"] for r in records]
    assert scores == sorted(scores)  # a parent is only replaced by a child at least as good
    for prev, r in zip(records, records[1:]):
        assert r["parent_score"] == max(prev["parent_score"], r["best_child_score"])
    # A kill mid-write leaves a cut line: the resume drops it and goes on from generation 2.
    with open(tmp_path / "search.jsonl", "a") as f:
        f.write('{"generation": 3, "par')
    run(GaitSearchSettings(start, generations=3, **kwargs), tmp_path, client, progress=False)
    records = _read_log(tmp_path / "search.jsonl")
    assert [r["generation"] for r in records] == [0, 1, 2, 3]
    best = EpisodeConfig.from_dict(json.loads((tmp_path / "best_config.json").read_text()))
    assert best.to_dict() == records[-1]["parent"]
