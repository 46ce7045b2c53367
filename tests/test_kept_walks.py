"""A sweep keeps each walk as it finishes and a rerun reads it back: an interrupted time-step study, push-margin
map or re-walk resumes where it stopped and writes the record an uninterrupted run writes."""

import json

from walkers import fast_config


def _mark_and_lose(folder, marked: str, lost: str, **fields) -> None:
    """Overwrite fields of one kept walk (a rerun that reads it back shows them) and delete another (a rerun
    that was interrupted before it finished walks it again)."""
    path = folder / marked
    path.write_text(json.dumps({**json.loads(path.read_text()), **fields}))
    (folder / lost).unlink()


def test_an_interrupted_time_step_study_resumes_from_its_kept_walks(tmp_path, client):
    from drake_biped.experiments import time_step

    settings = time_step.TimeStepSettings((0.002, 0.001), 0.001, 1.5, windows=((0.2, 0.5),), measure="episode")
    first = time_step.run(settings, tmp_path, client, progress=False)
    walks = tmp_path / "walks"
    assert sorted(p.name for p in walks.iterdir()) == ["1ms-0.2-0.5s.json", "1ms-no_window.json",
                                                       "2ms-0.2-0.5s.json", "2ms-no_window.json"]
    _mark_and_lose(walks, "2ms-no_window.json", "1ms-0.2-0.5s.json", cost_of_transport=9.0)
    again = time_step.run(settings, tmp_path, client, progress=False)
    rows = {(r["time_step_s"], tuple(r["window"] or ())): r for r in again["rows"]}
    assert rows[0.002, ()]["cost_of_transport"] == 9.0  # read back, not walked again
    def physics(record):  # each other row, less the wall clock's real-time factor
        return [{k: v for k, v in r.items() if k != "real_time_factor"} for r in record["rows"]
                if (r["time_step_s"], r["window"]) != (0.002, None)]

    assert physics(again) == physics(first)


def test_an_interrupted_push_margin_map_resumes_from_its_kept_walks(tmp_path, client):
    from drake_biped.experiments import push_margin

    config = fast_config().override({"sim.distance_m": 3.0, "sim.max_time_s": 10.0})
    settings = push_margin.PushMarginSettings(config, (0.2, 0.5), max_force_n=10.0, force_step_n=10.0, phases=1,
                                              settle_s=1.0)
    first = push_margin.run(settings, tmp_path, client, progress=False)
    walks = tmp_path / "walks"
    assert len(list(walks.iterdir())) == 2 + 4  # the two unpushed walks, 2 conditions x 2 directions x 1 x 1
    assert first["margins"]["with"]["forward"]["survived"] == [[True]]
    _mark_and_lose(walks, "with-forward-10N-phase0.json", "without-backward-10N-phase0.json", fell=True,
                   distance_m=1.0)
    again = push_margin.run(settings, tmp_path, client, progress=False)
    assert again["margins"]["with"]["forward"]["survived"] == [[False]]  # read back, not walked again
    assert again["margins"]["without"] == first["margins"]["without"]
