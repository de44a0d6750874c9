"""Prove generated scenarios of 10-20 jobs optimal: how many within the limit, and how soon.

Usage: python bench/small_proofs.py [--set tuning|held-out] [--time-limit 5] [--workers 2]
                                    [--reference 30]
The issue's target: every scenario of up to 20 jobs proven optimal within 5 s at 2 workers.
Scenarios come from `model.generator.random_scenario` with the issue's shape
(`solve_general.issue_shape`), 10, 15 and 20 jobs for each of four seeds: seeds 11-14 for
tuning, 301-304 held out of every tuning run.

Prints, never asserts, per scenario: status, solve time, makespan, bound, when the best
schedule was found and whether the validator accepts it; with `--reference S`, for each
scenario not proven within the limit, the makespan and bound of a run of S seconds (the
optimum when that run proves it), so that a miss reads as a late schedule (the reference
is shorter) or a stuck proof (it is not). Then the number proven and the load average.
"""

import argparse
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))
sys.path.insert(0, str(REPO / 'bench'))

from solve_general import issue_shape  # noqa: E402

from fjsp_planner.model.generator import random_scenario  # noqa: E402
from fjsp_planner.model.scenario import parse_scenario  # noqa: E402
from fjsp_planner.model.schedule import Status  # noqa: E402
from fjsp_planner.model.validate import validate  # noqa: E402
from fjsp_planner.solving.solve import solve  # noqa: E402

SIZES = (10, 15, 20)
SEEDS = {'tuning': (11, 12, 13, 14), 'held-out': (301, 302, 303, 304)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--set', choices=sorted(SEEDS), default='held-out')
    parser.add_argument('--time-limit', type=float, default=5.0)
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--reference', type=float, default=0.0, metavar='S',
                        help='also solve each scenario not proven for S seconds (0: do not)')
    args = parser.parse_args()
    print(f'{args.set} seeds, {args.workers} workers, limit {args.time_limit:g} s, '
          f'load {os.getloadavg()[0]:.2f}')
    print(f"{'jobs':>5} {'seed':>5} {'status':>9} {'total s':>8} {'best s':>8} "
          f"{'makespan':>9} {'bound':>8} valid | {'ref':>8} {'ref bound':>9} ref status")
    proven = 0
    for seed in SEEDS[args.set]:
        for jobs in SIZES:
            problem = parse_scenario(random_scenario(seed, issue_shape(jobs, seed)))
            result = solve(problem, time_limit=args.time_limit, workers=args.workers)
            valid = result.schedule is not None and not validate(problem, result.schedule)
            proven += result.status == Status.OPTIMAL
            print(f'{jobs:>5} {seed:>5} {result.status.value:>9} {result.solve_seconds:>8.2f} '
                  f'{_figure(result.best_solution_seconds, 8)} {_figure(result.makespan, 9)} '
                  f'{_figure(result.lower_bound, 8)} {valid!s:>5} | '
                  f'{_reference(args, problem, result)}', flush=True)
    print(f'proven {proven} of {len(SEEDS[args.set]) * len(SIZES)}, '
          f'load {os.getloadavg()[0]:.2f}')


def _reference(args, problem, result):
    if not args.reference or result.status == Status.OPTIMAL:
        return ''
    longer = solve(problem, time_limit=args.reference, workers=args.workers)
    return (f'{_figure(longer.makespan, 8)} {_figure(longer.lower_bound, 9)} '
            f'{longer.status.value} {longer.solve_seconds:.1f} s')


def _figure(value, width):
    return f"{'-':>{width}}" if value is None else f'{float(value):>{width}.2f}'


if __name__ == '__main__':
    main()
