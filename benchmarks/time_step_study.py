"""The time-step study as a script: `drake-biped time-step-study` with the same options.

    python benchmarks/time_step_study.py --out out/time-step-study       # about 2 minutes on 2 workers
    python benchmarks/time_step_study.py --out DIR --replot              # redraw from DIR's JSON
"""

import sys

from drake_biped.cli import main

if __name__ == "__main__":
    raise SystemExit(main(["time-step-study", *sys.argv[1:]]))
