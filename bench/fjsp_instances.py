"""Solve every FJSP benchmark file (`.fjs`, Brandimarte/Hurink format) in a folder.

    python bench/fjsp_instances.py DIR [--time-limit S] [--solver cpsat|mip-scip|mip-highs]

Prints one row per instance: benchmark jobs, operations, machines, makespan, lower bound,
gap, status and wall time. Solves go through `solve()` (greedy start and fallback); every
schedule is checked by the independent validator.
"""

import argparse
import sys
import time
from pathlib import Path

# Runs from a checkout, without building the ROS workspace.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'src' / 'fjsp_planner'))

from fjsp_planner.core.fjs import load_fjs  # noqa: E402
from fjsp_planner.core.problem import ProblemError  # noqa: E402
from fjsp_planner.core.solve import solve  # noqa: E402
from fjsp_planner.core.validate import validate  # noqa: E402

SOLVERS = ('cpsat', 'mip-scip', 'mip-highs')
COLUMNS = ('instance', 'jobs', 'ops', 'machines', 'makespan', 'bound', 'gap', 'status',
           'by', 'seconds')
"""`by` names the solver whose schedule it is: `greedy` when the exact one found none."""


def run(problem, solver, time_limit, workers):
    name, _, backend = solver.partition('-')
    return solve(problem, solver=name, time_limit=time_limit, workers=workers,
                 mip_backend=backend.upper() or 'SCIP')


def number(value):
    return '-' if value is None else f'{float(value):g}'


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('folder', type=Path)
    parser.add_argument('--time-limit', type=float, default=10.0, metavar='S',
                        help='seconds per instance (default 10)')
    parser.add_argument('--solver', choices=SOLVERS, default='cpsat')
    parser.add_argument('--workers', type=int, default=2)
    args = parser.parse_args(argv)
    if args.time_limit <= 0:
        parser.error(f'--time-limit must be positive, got {args.time_limit}')
    if not args.folder.is_dir():
        parser.error(f'{args.folder} is not a folder')
    files = sorted(args.folder.glob('*.fjs'))
    if not files:
        parser.error(f'no .fjs files in {args.folder}')

    rows = []
    for path in files:
        try:
            problem = load_fjs(path)
        except ProblemError as error:
            print(f'{path.name}: skipped: {error}', file=sys.stderr)
            continue
        began = time.perf_counter()
        result = run(problem, args.solver, args.time_limit, args.workers)
        seconds = time.perf_counter() - began
        if result.schedule is not None and validate(problem, result.schedule):
            print(f'{path.name}: INVALID schedule: {validate(problem, result.schedule)}',
                  file=sys.stderr)
        jobs = len({j.name.split('.')[0] for j in problem.jobs})
        gap = '-' if result.gap is None else f'{100 * result.gap:.1f}%'
        rows.append((path.stem, str(jobs), str(len(problem.jobs)), str(len(problem.robots)),
                     number(result.makespan), number(result.lower_bound), gap,
                     str(result.status), result.solver, f'{seconds:.1f}'))
    widths = [max(len(c), *(len(r[i]) for r in rows)) if rows else len(c)
              for i, c in enumerate(COLUMNS)]
    print(f'# solver {args.solver}, time limit {args.time_limit:g} s, {args.workers} workers')
    for row in [COLUMNS, *rows]:
        print('  '.join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)))
    return 0


if __name__ == '__main__':
    sys.exit(main())
