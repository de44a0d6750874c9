"""Solving a `Problem` for the least makespan (docs/solver.md). No ROS.

- `solve`: the one entry point, `solve(problem, time_limit, ...) -> Result`; it picks the
  backends and runs them;
- `cpsat/`: the CP-SAT model and search, split by concern;
- `greedy`: list scheduling, a valid schedule in milliseconds (horizons, hints, fallback);
- `panels`: a schedule for identical panels stitched from one-panel optima;
- `tabu`: a tabu search for the classic flexible job shop;
- `mip`: the paper's mixed integer program through OR-Tools' MIP backends;
- `bounds/`: lower bounds that hold whatever a solver found, for honest gaps.
"""
