"""Solve every FJSP benchmark file (`.fjs`, Brandimarte/Hurink format) in a folder tree.

    python bench/fjsp_instances.py DIR [--time-limit S] [--solver cpsat|mip-scip|mip-highs]
                                       [--vs-pyjobshop] [--best-known CSV]

Prints one row per instance: benchmark jobs, operations, machines, makespan, lower bound,
gap, status and wall time, and, when the instance has a best-known makespan (`best_known.csv`
in DIR or a folder above it, columns family,instance,best_known,...), the gap to it. With
--vs-pyjobshop, PyJobShop solves the same instance with the same limits beside ours (in a venv
of its own, see bench/pyjobshop_peer.py), and the closing lines give the mean gap to the
best-known value per family and overall for both. Solves go through `solve()` (greedy start
and fallback); every schedule is checked by the independent validator.
"""

import argparse
import csv
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
# Runs from a checkout, without building the ROS workspace.
sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))
sys.path.insert(0, str(REPO / 'bench'))

from pyjobshop_peer import run_peer  # noqa: E402

from fjsp_planner.model.fjs import load_fjs  # noqa: E402
from fjsp_planner.model.problem import ProblemError  # noqa: E402
from fjsp_planner.model.validate import validate  # noqa: E402
from fjsp_planner.solving.solve import solve  # noqa: E402

SOLVERS = ('cpsat', 'mip-scip', 'mip-highs')
COLUMNS = ('instance', 'jobs', 'ops', 'machines', 'makespan', 'bound', 'gap', 'status',
           'by', 'seconds', 'best', 'vs best', 'PyJobShop', 'vs best')
"""`by` names the solver whose schedule it is: `greedy` when the exact one found none."""


def run(problem, solver, time_limit, workers):
    name, _, backend = solver.partition('-')
    return solve(problem, solver=name, time_limit=time_limit, workers=workers,
                 mip_backend=backend.upper() or 'SCIP')


def number(value):
    return '-' if value is None else f'{float(value):g}'


def best_known(folder: Path, given: Path | None) -> dict:
    """(family, instance) -> best-known makespan, from the first best_known.csv found."""
    candidates = [given] if given else [d / 'best_known.csv' for d in (folder, *folder.parents)]
    for path in candidates:
        if path is not None and path.is_file():
            with path.open() as handle:
                return {(row['family'], row['instance']): float(row['best_known'])
                        for row in csv.DictReader(handle)}
    return {}


def gap_to(value, best):
    return None if value is None or best is None else 100 * (float(value) - best) / best


def percent(value):
    return '-' if value is None else f'{value:.1f}%'


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('folder', type=Path)
    parser.add_argument('--time-limit', type=float, default=10.0, metavar='S',
                        help='seconds per instance (default 10)')
    parser.add_argument('--solver', choices=SOLVERS, default='cpsat')
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--vs-pyjobshop', action='store_true',
                        help='solve each instance with PyJobShop too, same limits')
    parser.add_argument('--best-known', type=Path, metavar='CSV')
    args = parser.parse_args(argv)
    if args.time_limit <= 0:
        parser.error(f'--time-limit must be positive, got {args.time_limit}')
    if not args.folder.is_dir():
        parser.error(f'{args.folder} is not a folder')
    files = sorted(args.folder.rglob('*.fjs'))
    if not files:
        parser.error(f'no .fjs files in {args.folder}')
    known = best_known(args.folder, args.best_known)

    rows, gaps = [], {}
    print(f'# solver {args.solver}, time limit {args.time_limit:g} s, {args.workers} workers',
          flush=True)
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
        family = path.parent.name
        best = known.get((family, path.stem))
        ours = gap_to(result.makespan, best)
        peer = peer_gap = None
        if args.vs_pyjobshop:
            peer = run_peer(str(path), args.time_limit, args.workers)['makespan']
            peer_gap = gap_to(peer, best)
        if ours is not None:
            gaps.setdefault(family, []).append((ours, peer_gap))
        jobs = len({j.name.split('.')[0] for j in problem.jobs})
        gap = '-' if result.gap is None else f'{100 * result.gap:.1f}%'
        row = (f'{family}/{path.stem}', str(jobs), str(len(problem.jobs)),
               str(len(problem.robots)), number(result.makespan), number(result.lower_bound),
               gap, str(result.status), result.solver, f'{seconds:.1f}', number(best),
               percent(ours), number(peer), percent(peer_gap))
        rows.append(row)
        print('  '.join(row), flush=True)
    widths = [max(len(c), *(len(r[i]) for r in rows)) if rows else len(c)
              for i, c in enumerate(COLUMNS)]
    print()
    for row in [COLUMNS, *rows]:
        print('  '.join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)))
    if gaps:
        print('\nmean gap to best-known: family, instances, ours' +
              (', PyJobShop' if args.vs_pyjobshop else ''))
        every = [g for values in gaps.values() for g in values]
        for family, values in [*sorted(gaps.items()), ('all', every)]:
            line = f'  {family:14} {len(values):3}  {statistics.mean(v[0] for v in values):6.2f}%'
            if args.vs_pyjobshop:
                peers = [v[1] for v in values if v[1] is not None]
                missing = len(values) - len(peers)
                line += (f'  {statistics.mean(peers):6.2f}%' if peers else '       -')
                if missing:
                    line += f' ({missing} without a schedule)'
            print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
