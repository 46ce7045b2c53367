"""Learned torque-free periods re-walked where the learner did not walk them: with the plant step halved, and
from 0.95 and 1.05 x the initiation speed, each against the walk without a window under the same change.

A learner scores windows in one simulation, from one start; a saving that holds only there is an edge of that
simulation, not a property of the robot. Every learning run (`drake-biped learn`, `compare-learners`,
`reproduce`) re-walks each trial's final policy mean so, and `drake-biped rewalk --policy learning.json` does it
for any learning record. What a saving, a trial's figure and holding mean: `drake_biped.analysis.rewalks`.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from drake_biped.common.learning_record import check_learning_record
from drake_biped.common.options import (
    add_cluster_options,
    out_folder,
    run_command,
)
from drake_biped.common.walks import rewalk
from drake_biped.legacy import config_of_record
from drake_biped.params import (
    ParameterError,
    check_settings,
)
from drake_biped.records import read_json, write_record
from drake_biped.versions import versions

__all__ = ["RewalkSettings", "rewalk_record", "run"]








def rewalk_record(source: Path, client, keep: Path | None = None) -> dict[str, Any]:
    """The re-walks of a learning record's final policy means (`source`: a learning.json), with what they
    were made from; each walk kept in the folder `keep` as it finishes (a rerun resumes), when one is given."""
    record = check_learning_record(read_json(source, "--policy"), f"--policy {source}")
    try:
        config = config_of_record(record["settings"]["config"])
        learned = [{"trial": int(t["trial"]), "t1": float(t["final_mean"][0]), "t2": float(t["final_mean"][1])}
                   for t in record["trials"]]
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise ParameterError(f"--policy {source}: a learning record without its final means ({exc})") from None
    # walked as the record's own re-walks were (a record from before re-walks were long: its episodes' length)
    before = (record.get("evaluation") or {}).get("rewalks") or {}
    distance = before.get("distance_m", config.sim.distance_m)
    return {"source": str(source), "config": config.to_dict(), **rewalk(config, learned, client, distance, keep=keep),
            "versions": versions()}


@dataclass(frozen=True)
class RewalkSettings:
    """The learning record (a learning.json) whose final policy means are re-walked."""

    policy: Path


def run(settings: RewalkSettings, out: Path, client=None, progress: bool = True) -> dict[str, Any]:
    """The re-walks of the record's final policy means on `client` (a LocalCluster when None); writes
    rewalk.json and rewalk.md into `out`, each walk kept in `out`/walks as it finishes (a rerun resumes). The
    record."""
    from drake_biped.analysis.rewalks import markdown
    from drake_biped.common.executor import client_or_local

    check_settings(settings, RewalkSettings, "rewalk.run")
    with client_or_local(client) as c:
        record = rewalk_record(Path(settings.policy), c, keep=Path(out) / "walks")
    out = Path(out)
    write_record(out, "rewalk", record, markdown)
    return record


COMMAND = "rewalk"
PARSER = dict(help="a learning run's final policy means re-walked with the plant step halved "
              "and from 0.95 and 1.05 x the initiation speed, each against no window under the same "
              "change, on Dask")


def add_arguments(p: argparse.ArgumentParser) -> None:
    """`drake-biped rewalk`'s options."""
    p.add_argument("--policy", required=True, help="the learning.json of drake-biped learn")
    add_cluster_options(p)
    p.add_argument("--out", required=True, type=out_folder, help="output folder")


def settings_from_args(args: argparse.Namespace) -> RewalkSettings:
    """The re-walks' settings from the command's options; what is not a learning record is refused here,
    before a cluster starts."""
    from drake_biped.records import read_json

    check_learning_record(read_json(Path(args.policy), "--policy"), f"--policy {args.policy}")
    return RewalkSettings(Path(args.policy))


def command(args: argparse.Namespace) -> int:
    """Run the command of `args` (its options parsed by add_arguments); the exit code."""
    from drake_biped.analysis.rewalks import markdown

    record = run_command(args, settings_from_args, run)
    print(markdown(record))
    print(f"wrote {args.out}/rewalk.json, rewalk.md")
    return 0
