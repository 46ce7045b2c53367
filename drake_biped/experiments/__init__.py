"""The experiments, one module each, none importing another (`reproduce`, which runs them all, aside): walk,
window_map, gait_search, learning, grid, slope, stability, push_margin, floquet, time_step, landscape, rewalk,
bifurcation, basins, compare_learners, reproduce. Each has its settings dataclass and `run(settings, out, client)`
that writes every file its command writes, and declares its command for drake_biped/cli.py: `COMMAND` (its name),
`PARSER` (its help), `add_arguments(parser)`, `settings_from_args(args)` and `command(args)` (the exit code).
What they share (options, the Dask executor, progress, the learning and Floquet runs, the walks of a window) is
drake_biped/common/; what they compute from records is drake_biped.analysis."""
