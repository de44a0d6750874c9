"""Solve 1, 2, 3, 5 and 10 solar panels with CP-SAT, beside PyJobShop, and print both.

Usage: python bench/solve_panels.py [--time-limit 60] [--workers 2] [--panels 1 2 3 5 10]
                                    [--no-peer]
Prints, never asserts: time to first solution, to best, status, makespan, bound and gap per
size, then PyJobShop's makespan, bound and status on the same instance and limits (installed
on first use into a venv of its own, see bench/pyjobshop_peer.py).
"""

import argparse
import os
import platform
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))

from fjsp_planner.model.scenario import load_scenario  # noqa: E402
from fjsp_planner.model.validate import validate  # noqa: E402
from fjsp_planner.solving.solve import solve  # noqa: E402

sys.path.insert(0, str(REPO / 'bench'))
from pyjobshop_peer import run_peer  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--time-limit', type=float, default=60.0)
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--panels', type=int, nargs='+', default=[1, 2, 3, 5, 10])
    parser.add_argument('--no-peer', action='store_true', help='skip PyJobShop')
    parser.add_argument('--scenario', default=str(REPO / 'config/scenarios/solar_panel.yaml'))
    args = parser.parse_args()
    print(f'machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; '
          f'CP-SAT {args.workers} workers, limit {args.time_limit:g} s')
    print(f"{'panels':>6} {'jobs':>5} {'first s':>8} {'best s':>8} {'total s':>8} "
          f"{'status':>9} {'makespan':>9} {'bound':>8} {'gap':>7} valid | PyJobShop: "
          f"{'makespan':>9} {'bound':>8} {'gap':>7} status")
    for panels in args.panels:
        problem = load_scenario(args.scenario, panels=panels)
        result = solve(problem, time_limit=args.time_limit, workers=args.workers)
        valid = result.schedule is not None and not validate(problem, result.schedule)
        print(f'{panels:>6} {len(problem.jobs):>5} {_s(result.first_solution_seconds)} '
              f'{_s(result.best_solution_seconds)} {result.solve_seconds:>8.2f} '
              f'{result.status.value:>9} {float(result.makespan):>9.2f} '
              f'{float(result.lower_bound):>8.2f} {100 * result.gap:>6.1f}% {valid!s:>5} | '
              f'{"" if args.no_peer else _peer(args, panels)}', flush=True)


def _peer(args, panels):
    peer = run_peer(args.scenario, args.time_limit, args.workers, panels)
    if peer['makespan'] is None:
        return f"{'-':>20} {'':>8}    {peer['status']}"
    gap = 100 * (peer['makespan'] - peer['bound']) / peer['makespan']
    return (f"{peer['makespan']:>20.2f} {peer['bound']:>8.2f} {gap:>6.1f}% "
            f"{peer['status']}")


def _s(seconds):
    return f'{seconds:>8.2f}' if seconds is not None else f"{'-':>8}"


if __name__ == '__main__':
    main()
