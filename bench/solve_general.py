"""Solve generated multi-robot scenarios of 15 to 1000 jobs and print makespan, bound and gap.

Usage: python bench/solve_general.py [--sizes 15 30 60 120 500] [--seeds 101 102]
                                     [--time-limit 30] [--workers 2] [--reference 300]
                                     [--repairs 20] [--no-peer]
Scenarios come from `model.generator.random_scenario` shaped like users' own: 3-4 robot
types and 4-7 robots up to 120 jobs, 4 types and 20 robots from 500 jobs on, 30-50 % of jobs
needing 2-3 robots at once, alternative plans, a layered precedence DAG, holding arcs, start
locations and release times. The default seeds are kept out of every tuning run.

Prints, never asserts, per scenario: time to first and best schedule, status, makespan,
bound, gap and whether the validator accepts the schedule; the median and 95th percentile
time of `execution.replan.repair` (the planner's instant re-plan, in-process) after a robot
fails at a random time, `--repairs` times; then, with `--reference S`, the makespan of our
own run of S seconds and how far the first run's makespan is above it; then PyJobShop's
makespan, bound and gap on the same scenario and limits (which does not map start locations
and release times: its figures are of an easier problem).
"""

import argparse
import os
import platform
import random
import statistics
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))

from fjsp_planner.execution.replan import repair, simulated_state  # noqa: E402
from fjsp_planner.model.generator import Shape, random_scenario  # noqa: E402
from fjsp_planner.model.scenario import parse_scenario  # noqa: E402
from fjsp_planner.model.validate import validate  # noqa: E402
from fjsp_planner.solving.solve import solve  # noqa: E402

sys.path.insert(0, str(REPO / 'bench'))
from pyjobshop_peer import run_peer  # noqa: E402


def issue_shape(jobs: int, seed: int) -> Shape:
    """The shape of the scenarios users reported: 3-4 robot types, 4-7 robots (20 robots
    and 4 types from 500 jobs on), drawn from the seed."""
    if jobs >= 500:
        return Shape(jobs=jobs, robots=20, robot_types=4)
    rng = random.Random(seed)
    return Shape(jobs=jobs, robots=rng.randint(4, 7), robot_types=rng.randint(3, 4))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--sizes', type=int, nargs='+', default=[15, 30, 60, 120, 500])
    parser.add_argument('--seeds', type=int, nargs='+', default=[101, 102])
    parser.add_argument('--time-limit', type=float, default=30.0)
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--reference', type=float, default=0.0, metavar='S',
                        help='also solve each scenario for S seconds (0: do not)')
    parser.add_argument('--repairs', type=int, default=20,
                        help='robot failures re-planned by repair() per scenario')
    parser.add_argument('--no-peer', action='store_true', help='skip PyJobShop')
    args = parser.parse_args()
    print(f'machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, '
          f'load {os.getloadavg()[0]:.2f}; {args.workers} workers, limit {args.time_limit:g} s')
    print(f"{'jobs':>5} {'seed':>5} {'robots':>6} {'first s':>8} {'best s':>8} {'total s':>8} "
          f"{'status':>9} {'makespan':>9} {'bound':>8} {'gap':>6} valid | repair p50 p95 | "
          f"{'ref':>8} {'above':>6} | PyJobShop: {'makespan':>9} {'bound':>8} {'gap':>6} status")
    gaps = []
    for jobs in args.sizes:
        for seed in args.seeds:
            scenario = random_scenario(seed, issue_shape(jobs, seed))
            problem = parse_scenario(scenario)
            result = solve(problem, time_limit=args.time_limit, workers=args.workers)
            valid = result.schedule is not None and not validate(problem, result.schedule)
            if result.gap is not None:
                gaps.append(result.gap)
            print(f'{jobs:>5} {seed:>5} {len(problem.robots):>6} '
                  f'{_s(result.first_solution_seconds)} {_s(result.best_solution_seconds)} '
                  f'{result.solve_seconds:>8.2f} {result.status.value:>9} '
                  f'{_f(result.makespan, 9)} {_f(result.lower_bound, 8)} '
                  f'{_pct(result.gap)} {valid!s:>5} | {_repairs(args, problem, result, seed)} | '
                  f'{_reference(args, problem, result)} | '
                  f'{"" if args.no_peer else _peer(args, scenario)}', flush=True)
    if gaps:
        print(f'mean gap {100 * sum(gaps) / len(gaps):.1f}% over {len(gaps)} scenarios')


def _repairs(args, problem, result, seed):
    """repair() after a random robot fails at a random time: median and 95th percentile."""
    if not args.repairs or result.schedule is None:
        return f"{'-':>10} {'-':>5}"
    rng = random.Random(seed)
    robots = [r.name for r in problem.robots]
    seconds = []
    for _ in range(args.repairs):
        now = Fraction(rng.randrange(0, int(result.makespan * 10)), 10)
        state = simulated_state(problem, result.schedule, now, {rng.choice(robots)})
        began = time.monotonic()
        repair(problem, result.schedule, state)
        seconds.append(time.monotonic() - began)
    p95 = statistics.quantiles(seconds, n=20)[-1] if len(seconds) > 1 else seconds[0]
    return f'{statistics.median(seconds):>10.2f} {p95:>5.2f}'


def _reference(args, problem, result):
    if not args.reference:
        return f"{'-':>8} {'':>6}"
    longer = solve(problem, time_limit=args.reference, workers=args.workers)
    best = min(longer.makespan, result.makespan)
    return f'{float(best):>8.2f} {_pct(float((result.makespan - best) / best))}'


def _peer(args, scenario):
    with tempfile.NamedTemporaryFile('w', suffix='.yaml', delete=False) as stream:
        yaml.safe_dump(scenario, stream, sort_keys=False)
    try:
        peer = run_peer(stream.name, args.time_limit, args.workers)
    finally:
        os.unlink(stream.name)
    if peer['makespan'] is None:
        return f"{'-':>9} {'':>8} {'':>6} {peer['status']}"
    gap = (peer['makespan'] - peer['bound']) / peer['makespan']
    return f"{peer['makespan']:>9.2f} {peer['bound']:>8.2f} {_pct(gap)} {peer['status']}"


def _s(seconds):
    return f"{'-':>8}" if seconds is None else f'{seconds:>8.2f}'


def _f(value, width):
    return f"{'-':>{width}}" if value is None else f'{float(value):>{width}.2f}'


def _pct(gap):
    return f"{'-':>6}" if gap is None else f'{100 * gap:>5.1f}%'


if __name__ == '__main__':
    main()
