"""The pictures under docs/, drawn from committed records (tests/test_docs_figures.py runs this and checks that
docs/ holds exactly these pictures, each linked from a document):

    python benchmarks/docs_figures.py --out docs        # make docs-figures

- report_summary_full.png: the full reproduction's verdict table (README, docs/RESULTS.md), from its
  verdicts.json (the shipped full run's records, benchmarks/results/reproduce-GAIT/), drawn as `drake-biped reproduce` draws report_summary.png.
- walk_frame.png: the README's picture, a still of the full run's 10 m walk at 5 s: its result.json's
  configuration walked again (an episode is deterministic: on the record's machine a walk whose C_mt is not the
  recorded one to the last digit is refused, on another one that is not within versions.CROSS_MACHINE_RTOL, so the
  picture is of the recorded walk; the line printed says which rule applied).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def _full_run() -> Path:
    """The committed full run whose verdicts the package ships (analysis.reproduce_report.full_run_records)."""
    from drake_biped.analysis.reproduce_report import full_run_records
    from drake_biped.resources import full_run_digest

    return Path(__file__).resolve().parents[1] / full_run_records(full_run_digest())


FULL_RUN = _full_run()
FIGURES = ("report_summary_full.png", "walk_frame.png")
WALK_FRAME_S = 5.0


def report_summary(out: Path) -> Path:
    from drake_biped.analysis.reproduce_report import summary_figure

    digest = json.loads((FULL_RUN / "verdicts.json").read_text())
    rows = [(r["what"], r["paper"], r["ours"], r["verdict"]) for r in digest["rows"]]
    path = out / "report_summary_full.png"
    summary_figure(rows, f"drake-biped reproduce ({digest['profile']}): the paper's claims, measured on one gait",
                   path)
    return path


def walk_frame(out: Path) -> tuple[Path, str]:
    from drake_biped.analysis.figures import walk_frame as draw
    from drake_biped.episode import run_episode
    from drake_biped.legacy import config_of_record
    from drake_biped.model import body_of_model
    from drake_biped.versions import compare_with_record

    record = json.loads((FULL_RUN / "walk" / "result.json").read_text())
    config = config_of_record(record["config"])
    result = run_episode(config, record_trajectory=True)
    comparison = compare_with_record(record["cost_of_transport"], result.cost_of_transport, record.get("versions"))
    if not comparison.agrees:
        raise RuntimeError(f"the recorded walk ({FULL_RUN / 'walk' / 'result.json'}): {comparison.text}: its picture "
                           "would not be of it")
    path = out / "walk_frame.png"
    draw(result.trajectory, WALK_FRAME_S, path, ground_height=config.ground.height, body=body_of_model(config.model))
    return path, comparison.text


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("docs"), help="folder to draw into (default docs)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"wrote {report_summary(args.out)}")
    path, comparison = walk_frame(args.out)
    print(f"wrote {path}: the recorded walk's {comparison}")


if __name__ == "__main__":
    main()
