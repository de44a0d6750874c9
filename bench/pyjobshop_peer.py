"""PyJobShop, the closest generic peer, on our instances: the side-by-side figures of the benches.

PyJobShop is a bench-only dependency: `ensure_venv()` installs it into a venv of its own
(`ros2_ws/.pyjobshop-venv`, git-ignored), so the product's pinned requirements stay as they are,
and `run_peer()` solves in a subprocess of that venv. The subprocess runs this file with
`--serve`: it reads the instance with our own loaders and builds PyJobShop's model of it.

How our problem maps onto PyJobShop's (every mapping keeps the optimum, except where noted):
- robot -> machine; job -> task whose modes are every staffing of every plan (distinct able
  robots), lasting the slowest operation, as our model's robots are busy for the whole job;
- travel -> sequence-dependent setup times on each machine (no setup before a first task, as
  a robot without a start location may start anywhere);
- precedence -> end-before-start; holding arc (a, b, q) -> a mode dependency (a's type-q robots
  are b's type-q robots) plus `consecutive(a, b)`, which PyJobShop applies to every robot the
  two tasks share, not only the holders (stricter than ours when a non-holder of a also works
  on b; never the case in the paper's panels);
- times on an integer grid: the least common multiple of the denominators (30 for the paper),
  durations rounded up; figures are reported back in schedule units.
Start locations, release times and fixed jobs (re-planning) are not mapped: the benches that
call this solve from scratch.
"""

import argparse
import itertools
import json
import math
import subprocess
import sys
import venv
from fractions import Fraction
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
VENV = REPO / 'ros2_ws' / '.pyjobshop-venv'
PACKAGES = ('pyjobshop==0.0.9', 'PyYAML==6.0.3')
MAX_GRID = 1000


def ensure_venv() -> Path:
    """The peer's python, installing PyJobShop into its own venv on first use."""
    python = VENV / 'bin' / 'python'
    marker = VENV / 'installed.txt'
    if not marker.exists() or marker.read_text() != '\n'.join(PACKAGES):
        print(f'installing {", ".join(PACKAGES)} into {VENV} (bench only) ...', flush=True)
        venv.create(VENV, with_pip=True, clear=True)
        subprocess.run([str(python), '-m', 'pip', 'install', '-q', *PACKAGES], check=True)
        marker.write_text('\n'.join(PACKAGES))
    return python


def run_peer(instance: str, time_limit: float, workers: int, panels: int = 1) -> dict:
    """Solve `instance` (scenario .yaml or .fjs) with PyJobShop; a dict of its figures.

    Keys: status (`error: ` and the peer's last line of error when it failed), makespan,
    bound (schedule units, None without a solution), seconds, grid.
    """
    python = ensure_venv()
    command = [str(python), __file__, '--serve', instance, '--time-limit', str(time_limit),
               '--workers', str(workers), '--panels', str(panels)]
    # Model building counts too: allow it a generous margin before giving up on the peer.
    done = subprocess.run(command, capture_output=True, text=True,
                          timeout=time_limit * 3 + 120)
    if done.returncode != 0:
        reason = (done.stderr.strip().splitlines() or [f'exit status {done.returncode}'])[-1]
        return {'status': f'error: {reason}', 'makespan': None, 'bound': None, 'seconds': None}
    return json.loads(done.stdout.strip().splitlines()[-1])


def _load(instance: str, panels: int):
    sys.path.insert(0, str(REPO / 'src' / 'fjsp_planner'))
    if instance.endswith('.fjs'):
        from fjsp_planner.model.fjs import load_fjs

        return load_fjs(instance)
    from fjsp_planner.model.scenario import load_scenario

    return load_scenario(instance, panels=panels)


def _grid(problem) -> int:
    values = [problem.duration(r.name, q) for r in problem.robots for q in problem.operation_types]
    locations = problem.locations()
    values += [problem.travel(r.name, a, b) for r in problem.robots for a in locations
               for b in locations]
    scale = math.lcm(*{v.denominator for v in values if v is not None})
    return min(scale, MAX_GRID)


def _staffings(problem, plan):
    """Every way to give the plan's operations to distinct able robots: {robot: type}."""
    robots = [r.name for r in problem.robots]
    seen = set()
    for chosen in itertools.permutations(robots, len(plan)):
        staffing = tuple(sorted(zip(chosen, plan, strict=True)))
        if staffing in seen or any(problem.duration(r, q) is None for r, q in staffing):
            continue
        seen.add(staffing)
        yield dict(staffing)


def _holders(staffing, q) -> frozenset:
    return frozenset(r for r, t in staffing.items() if t == q)


def _held_staffings(problem) -> dict:
    """Every job's staffings, less those of a holding arc's first job whose q-robots staff
    no way of doing the held job: that staffing has no schedule, and PyJobShop takes no mode
    dependency on an empty set of modes."""
    options = {job.name: [s for plan in job.plans for s in _staffings(problem, plan)]
               for job in problem.jobs}
    changed = True
    while changed:
        changed = False
        for a, b, q in problem.holding:
            held = {_holders(s, q) for s in options[b]}
            kept = [s for s in options[a] if _holders(s, q) in held]
            changed |= len(kept) < len(options[a])
            options[a] = kept
    return options


def _serve(instance, time_limit, workers, panels):
    from pyjobshop import Model

    problem = _load(instance, panels)
    scale = _grid(problem)

    def ticks(value: Fraction) -> int:
        return math.ceil(value * scale)

    model = Model()
    machines = {r.name: model.add_machine(name=r.name) for r in problem.robots}
    tasks, modes = {}, {}
    staffings = _held_staffings(problem)
    for job in problem.jobs:
        task = tasks[job.name] = model.add_task(name=job.name)
        for staffing in staffings[job.name]:
            duration = max(ticks(problem.duration(r, q)) for r, q in staffing.items())
            mode = model.add_mode(task, [machines[r] for r in staffing], duration)
            modes.setdefault(job.name, []).append((staffing, mode))
    for a, b in problem.precedence:
        model.add_end_before_start(tasks[a], tasks[b])
    for a, b, q in problem.holding:
        for staffing, mode in modes[a]:
            model.add_mode_dependency(mode, [m for s, m in modes[b]
                                             if _holders(s, q) == _holders(staffing, q)])
        model.add_consecutive(tasks[a], tasks[b])
    if problem.locomote is not None:
        for robot in problem.robots:
            able = [j for j in problem.jobs
                    if any(robot.name in s for s, _ in modes[j.name])]
            for a, b in itertools.permutations(able, 2):
                leg = ticks(problem.travel(robot.name, a.location, b.location))
                if leg > 0:
                    model.add_setup_time(machines[robot.name], tasks[a.name], tasks[b.name], leg)
    model.set_objective(weight_makespan=1)
    result = model.solve('ortools', time_limit=time_limit, display=False, num_workers=workers)
    found = math.isfinite(result.objective)
    print(json.dumps({
        'status': result.status.value,
        'makespan': result.objective / scale if found else None,
        'bound': result.lower_bound / scale if found else None,
        'seconds': result.runtime, 'grid': scale}))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--serve', metavar='INSTANCE', required=True)
    parser.add_argument('--time-limit', type=float, default=10.0)
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--panels', type=int, default=1)
    args = parser.parse_args()
    _serve(args.serve, args.time_limit, args.workers, args.panels)


if __name__ == '__main__':
    main()
