"""The experiments, one module each, each with its settings dataclass and `run(settings, out, client)` that
writes every file its command writes: walk, window_map, gait_search, learning, grid, slope, stability,
push_margin, time_step, landscape, reproduce. `executor` is their one parallel executor (Dask) and `progress`
their progress bars and run logs."""
