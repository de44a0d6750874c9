"""Solving a `Problem` for the least makespan (docs/solver.md). No ROS.

- `solve`: the one entry point, `solve(problem, time_limit, ...) -> Result`; it only picks
  the backend;
- `start`: what every backend starts from and falls back on (greedy schedule, hint);
- `portfolio`: several identical panels: CP-SAT beside the panel bounds;
- `classic`: the classic flexible job shop: CP-SAT beside the tabu search;
- `routed`: multi-robot jobs with travel: CP-SAT up to 40 jobs, beyond two runs of the local
  search (`local`), the second in a process of its own (`local_process`);
- `large`: problems too large for the CP-SAT routing model: the local search as beyond 40
  routed jobs;
- `compact`: left-shifting a schedule (every job as early as its robots allow);
- `beside`: work run in threads beside the main search;
- `cpsat/`: the CP-SAT model and search, split by concern;
- `greedy`: list scheduling, a valid schedule in milliseconds (horizons, hints, fallback);
- `panels`: a schedule for identical panels stitched from one-panel optima;
- `tabu`: a tabu search for the classic flexible job shop;
- `mip`: the paper's mixed integer program through OR-Tools' MIP backends;
- `bounds/`: lower bounds that hold whatever a solver found, for honest gaps.
"""
