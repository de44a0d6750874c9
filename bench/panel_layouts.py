"""Search the panel sequence bound's relaxation layout by layout, each to its end or a limit.

Usage: python bench/panel_layouts.py [--panels 5] [--incumbent 848/3] [--solve-limit 60]
                                     [--time-limit 900] [--max-open N]

The bound (`solving/bounds/sequence.py`) takes every set of panels where the slow-crossing robots
(the paper's Assembler) may work, its *layout*, and is the least value over them. Searched
together in a solve, they share its time limit; here each gets `--time-limit` seconds of its
own and, by default, no cap on open orders, so that a layout that ends shows the most the
relaxation can ever give there. The least value over layouts searched to their ends is the
relaxation's own value: no speed-up of the search raises the bound above it.

Without `--incumbent`, the instance is first solved for `--solve-limit` seconds and its
makespan taken. Prints each layout (its panels numbered from 1), the value reached, the
seconds, whether it ended or was cut at the limit, and the process's peak memory so far;
then the least value and the gap it leaves to the incumbent. Never asserts.
"""

import argparse
import resource
import sys
import time
from fractions import Fraction
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))

from fjsp_planner.model.scenario import load_scenario  # noqa: E402
from fjsp_planner.solving.bounds import sequence as sequence_bound  # noqa: E402
from fjsp_planner.solving.solve import solve  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--panels', type=int, default=5)
    parser.add_argument('--scenario', default=str(REPO / 'config/scenarios/solar_panel.yaml'))
    parser.add_argument('--incumbent', type=Fraction,
                        help='a known makespan, e.g. 848/3 (default: solve first)')
    parser.add_argument('--solve-limit', type=float, default=60.0)
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--time-limit', type=float, default=900.0,
                        help='seconds per layout')
    parser.add_argument('--max-open', type=int, default=10 ** 9,
                        help='open orders before some are let go (the product: '
                             f'{sequence_bound.MAX_OPEN})')
    args = parser.parse_args()
    problem = load_scenario(args.scenario, panels=args.panels)
    incumbent = args.incumbent
    if incumbent is not None and incumbent <= 0:
        parser.error(f'--incumbent must be positive, not {incumbent}')
    if incumbent is None:
        result = solve(problem, time_limit=args.solve_limit, workers=args.workers)
        if result.schedule is None:
            sys.exit(f'no schedule of {args.panels} panels in {args.solve_limit:g} s')
        incumbent = result.makespan
        print(f'incumbent: {_show(incumbent)} (solved in {result.solve_seconds:.0f} s)')
    layouts = sequence_bound.layouts(problem, incumbent)
    if not layouts:
        sys.exit('the panel sequence bound does not apply to this instance')
    print(f"{'layout (panels)':>16} {'value':>10} {'seconds':>8} {'search':>7} {'peak MB':>8}",
          flush=True)
    values = []
    for helped in layouts:
        began = time.monotonic()
        value = sequence_bound.layout_value(problem, incumbent, helped, args.time_limit,
                                            args.max_open)
        seconds = time.monotonic() - began
        values.append(value)
        memory = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024
        print(f"{_panels(helped):>16} {_show(value):>10} {seconds:>8.1f} "
              f"{'cut' if seconds >= args.time_limit else 'ended':>7} {memory:>8}", flush=True)
    least = min(values)
    print(f'least over layouts: {_show(least)}; gap to {_show(incumbent)}: '
          f'{100 * float((incumbent - least) / incumbent):.2f} %')


def _panels(helped):
    return ','.join(str(k + 1) for k in helped) or 'none'


def _show(value: Fraction) -> str:
    whole, part = divmod(value, 1)
    return f'{whole}' if not part else f'{whole} {part.numerator}/{part.denominator}'


if __name__ == '__main__':
    main()
