"""fjsp-solve: plan a scenario from the command line.

Ctrl-C (SIGINT) and SIGTERM stop it at once at any stage, with one line on stderr and exit
code 128 + the signal number. The work runs on a worker thread while the main thread only
waits: Python runs signal handlers on the main thread between bytecodes, and CP-SAT solves in
C++ without returning to the interpreter (and is told not to catch SIGINT itself), so a
handler on a main thread busy solving would wait for the whole time limit.
"""

import argparse
import json
import math
import os
import signal
import sys
import threading
from fractions import Fraction
from pathlib import Path

from fjsp_common.decimals import decimal, decimals
from fjsp_planner.model.limits import MAX_WORKERS
from fjsp_planner.model.problem import ProblemError, listed
from fjsp_planner.model.schedule import Result
from fjsp_planner.model.validate import validate

EXIT_BAD_INPUT = 2
EXIT_INVALID_SCHEDULE = 3

_stage = 'starting'
"""What the worker is doing, for the message of an interruption."""


def main(argv=None) -> int:
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _interrupted)
    # Imported after the handlers are in place: loading OR-Tools takes a noticeable moment.
    from fjsp_planner.solving.solve import SOLVERS

    parser = argparse.ArgumentParser(
        prog='fjsp-solve', description='Plan which robot does what, when, for a scenario '
        '(YAML, see docs/scenario-format.md) or a standard .fjs instance.')
    parser.add_argument('scenario', help='scenario .yaml or FJSP .fjs file')
    parser.add_argument('--panels', type=_positive_int, help='repeat the jobs N times')
    parser.add_argument('--shift', type=_non_negative, help='distance between panels')
    parser.add_argument('--time-limit', type=_positive, default=10.0, metavar='S')
    parser.add_argument('--workers', type=_workers, default=2, metavar='K',
                        help=f'solver threads, 1 to {MAX_WORKERS}')
    parser.add_argument('--solver', choices=SOLVERS, default='cpsat')
    parser.add_argument('--mip-backend', choices=('SCIP', 'HIGHS'), default='SCIP')
    parser.add_argument('--json', type=Path, metavar='OUT', help='write the result as JSON')
    parser.add_argument('--gantt', type=Path, metavar='OUT.png', help='draw the schedule')
    parser.add_argument('--check', action='store_true',
                        help='only check the file: exit 0 if it is fine, 2 naming every '
                        'problem; nothing is solved')
    parser.add_argument('--fragment-of', type=Path, metavar='SCENARIO',
                        help='with --check: the file is a fragment of jobs to add to a '
                        'mission of SCENARIO (as `mission add` sends it)')
    args = parser.parse_args(argv)
    if args.fragment_of is not None and not args.check:
        parser.error('--fragment-of goes with --check')
    if args.check:
        return _in_worker(lambda: _check(args), 'checking')
    return _in_worker(lambda: _plan(args), 'loading the scenario')


def _interrupted(signum, frame):
    name = signal.Signals(signum).name
    # Straight to the file descriptor: the worker may hold a stream's lock mid-write, and a
    # handler waiting for it would not stop at once.
    os.write(2, f'fjsp-solve: stopped by {name} while {_stage}\n'.encode())
    # Exit at once, whatever the worker thread (maybe inside CP-SAT) is doing.
    os._exit(128 + signum)


def _in_worker(work, stage: str) -> int:
    """`work()`'s exit code, computed on a worker thread while this one waits for it. The
    worker is at `stage` from the moment it exists, before it first runs."""
    global _stage
    outcome = {}

    def run():
        try:
            outcome['code'] = work()
        except BaseException as error:  # handed to the main thread, which raises it
            outcome['error'] = error

    worker = threading.Thread(target=run, name='fjsp-solve', daemon=True)
    _stage = stage
    worker.start()
    # In short waits: a signal the kernel hands to another thread (a worker, a CP-SAT thread)
    # only flags the main thread, which runs the handler at its next bytecode; blocked in a
    # join without a timeout it would have none until the worker ended.
    while worker.is_alive():
        worker.join(0.1)
    if 'error' in outcome:
        raise outcome['error']
    return outcome['code']


def _plan(args) -> int:
    global _stage
    from fjsp_planner.solving.solve import solve

    try:
        problem = _load(args)
    except ProblemError as error:
        return _invalid('scenario', error)
    _warn(args, problem)
    _stage = 'solving'
    result = solve(problem, solver=args.solver, time_limit=args.time_limit,
                   workers=args.workers, mip_backend=args.mip_backend)
    _stage = 'writing the result'
    if result.schedule is not None:
        violations = validate(problem, result.schedule)
        if violations:
            print('fjsp-solve: the solver returned an invalid schedule:', file=sys.stderr)
            for violation in violations:
                print(f'  - {violation}', file=sys.stderr)
            return EXIT_INVALID_SCHEDULE
        print(format_table(problem, result))
    print(status_line(result))
    for note in result.notes:
        print(f'note: {note}')
    try:
        if args.json:
            args.json.write_text(json.dumps(result_json(problem, result), indent=2) + '\n')
        if args.gantt and result.schedule is not None:
            from fjsp_planner.observe.plan_chart import draw_gantt

            draw_gantt(problem, result.schedule, args.gantt,
                       title=f'{problem.name}: makespan {decimal(result.makespan)}')
    except OSError as error:
        print(f'fjsp-solve: cannot write {error.filename}: {error.strerror}', file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0 if result.schedule is not None else 1


def _check(args) -> int:
    """Read the scenario (or the fragment against its scenario) and say what is wrong."""
    from fjsp_planner.model.extension import extend
    from fjsp_planner.model.limits import read_input_file
    from fjsp_planner.model.scenario import load_scenario

    try:
        if args.fragment_of is None:
            problem = _load(args)
        else:
            problem = load_scenario(args.fragment_of, panels=args.panels, shift=args.shift)
    except ProblemError as error:
        return _invalid('scenario', error)
    if args.fragment_of is None:
        _warn(args, problem)
        print(f'{args.scenario}: fine: {len(problem.jobs)} jobs, {len(problem.robots)} '
              f'robots, {len(problem.locations())} locations')
        return 0
    try:
        extended, added = extend(problem, read_input_file(args.scenario, 'fragment'))
    except ProblemError as error:
        return _invalid('fragment', error)
    _warn(args, extended)
    print(f'{args.scenario}: fine: adds {len(added)} job{"s" if len(added) != 1 else ""} '
          f'({listed(added)}) to {args.fragment_of}')
    return 0


def _invalid(what: str, error: ProblemError) -> int:
    print(f'fjsp-solve: invalid {what}:', file=sys.stderr)
    for problem_text in error.problems:
        print(f'  - {problem_text}', file=sys.stderr)
    return EXIT_BAD_INPUT


def _warn(args, problem) -> None:
    """A scenario's warnings (`scenario_warnings`), on stderr; `.fjs` files have none."""
    if Path(args.scenario).suffix == '.fjs':
        return
    from fjsp_planner.model.scenario import scenario_warnings

    for warning in scenario_warnings(problem):
        print(f'fjsp-solve: warning: {warning}', file=sys.stderr)


def _load(args):
    path = Path(args.scenario)
    if path.suffix == '.fjs':
        from fjsp_planner.model.fjs import load_fjs
        from fjsp_planner.model.scenario import repeat_panels

        problem = load_fjs(path)
        return repeat_panels(problem, args.panels or 1, args.shift or 0)
    from fjsp_planner.model.scenario import load_scenario

    return load_scenario(path, panels=args.panels, shift=args.shift)


def status_line(result: Result) -> str:
    parts = [f'status {result.status.value}', f'solver {result.solver}']
    makespan, bound = decimals(result.makespan, result.lower_bound)
    if result.makespan is not None:
        parts.append(f'makespan {makespan}')
    if result.lower_bound is not None:
        parts.append(f'bound {bound}')
    if result.gap is not None:
        parts.append(f'gap {100 * result.gap:.1f}%')
    parts.append(f'time {result.solve_seconds:.2f} s')
    return ', '.join(parts)


def format_table(problem, result: Result) -> str:
    """One row per robot visit: robot, job, operation, travel leg, start, end; each column
    as wide as its longest cell, names aligned left, numbers right."""
    rows = [('robot', 'job', 'operation', 'travel', 'start', 'end')]
    idle = set()
    for robot in problem.robots:
        for visit in result.schedule.visits(problem, robot.name):
            q = result.schedule.jobs[visit.job].robots[robot.name]
            left, arrival, start, end = decimals(visit.travel_start, visit.arrival,
                                                 visit.start, visit.end)
            travel = f'{left}-{arrival}' if visit.arrival > visit.travel_start else '-'
            rows.append((robot.name, visit.job, problem.operation_types[q], travel, start,
                         end))
        if not result.schedule.sequences.get(robot.name):
            idle.add(len(rows))
            rows.append((robot.name, '(no jobs)'))
    widths = [max(len(row[i]) for row in rows if len(row) > i) for i in range(6)]
    lines = []
    for number, row in enumerate(rows):
        names = [f'{cell:<{width}}' for cell, width in zip(row[:3], widths, strict=False)]
        if number in idle:
            lines.append(f'{names[0]}  {row[1]}')
            continue
        numbers = [f'{cell:>{width}}' for cell, width in zip(row[3:], widths[3:], strict=True)]
        lines.append('  '.join(names) + '  ' + '  '.join(numbers))
    return '\n'.join(lines)


def result_json(problem, result: Result) -> dict:
    schedule = result.schedule
    return {
        'scenario': problem.name,
        'solver': result.solver,
        'status': result.status.value,
        'makespan': _number(result.makespan),
        'lower_bound': _number(result.lower_bound),
        'gap': result.gap,
        'solve_seconds': result.solve_seconds,
        'first_solution_seconds': result.first_solution_seconds,
        'notes': list(result.notes),
        'jobs': [] if schedule is None else [
            {'name': a.job, 'plan': a.plan, 'start': _number(a.start), 'end': _number(a.end),
             'robots': dict(a.robots)}
            for a in sorted(schedule.jobs.values(), key=lambda a: (a.start, a.job))],
        'robots': {} if schedule is None else {
            r.name: [{'job': v.job, 'travel_start': _number(v.travel_start),
                      'arrival': _number(v.arrival), 'start': _number(v.start),
                      'end': _number(v.end)} for v in schedule.visits(problem, r.name)]
            for r in problem.robots},
    }


def _number(value: Fraction | None):
    """Exact integers stay integers; other times become floats (JSON has no fractions)."""
    if value is None:
        return None
    return int(value) if value.denominator == 1 else float(value)


def _positive_int(text):
    value = _parse(text, int)
    if value < 1:
        raise argparse.ArgumentTypeError(f'must be a positive integer, got {text!r}')
    return value


def _workers(text):
    value = _positive_int(text)
    if value > MAX_WORKERS:
        raise argparse.ArgumentTypeError(f'must be at most {MAX_WORKERS}, got {text!r}')
    return value


def _positive(text):
    value = _parse(text, float)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f'must be a finite number > 0, got {text!r}')
    return value


def _non_negative(text):
    from fjsp_planner.model import limits

    try:
        return limits.number(text, 'shift', Fraction(0), limits.MAX_TIME)
    except ProblemError as error:
        raise argparse.ArgumentTypeError(error.problems[0]) from None


def _parse(text, kind):
    try:
        return kind(text)
    except (ValueError, ZeroDivisionError):
        raise argparse.ArgumentTypeError(f'not a number: {text!r}') from None


if __name__ == '__main__':
    sys.exit(main())
