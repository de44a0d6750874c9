"""Property test: on small random instances the MIP and CP-SAT prove the same optimum.

Each seeded instance has 3-5 jobs, 2-3 robots with rational speeds, multi-robot jobs,
alternative plans, one holding arc and travel between three locations; some add a robot
with a start location and release time, or a job already running (fixed), maybe with one of
its robots released only after it ends.
"""

import random
from fractions import Fraction

import pytest

from fjsp_planner.model.problem import FixedJob, Job, Problem, ProblemError, Robot
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.mip import solve_mip
from fjsp_planner.solving.solve import solve

LOCOMOTE = 3
LOCATIONS = ('A', 'B', 'C')


def random_problem(seed: int) -> Problem:
    """The first well-formed instance drawn from `seed` (some draws cannot be staffed)."""
    rng = random.Random(seed)
    while True:
        try:
            return _draw(rng, seed)
        except ProblemError:
            continue


def _draw(rng: random.Random, seed: int) -> Problem:
    n_robots = rng.randint(2, 3)
    robot_types = {}
    for i in range(n_robots):
        efficiency = {q: Fraction(rng.randint(1, 6)) for q in (0, 1, 2) if rng.random() < 0.85}
        efficiency[LOCOMOTE] = Fraction(rng.randint(1, 3))
        robot_types[f'T{i}'] = efficiency
    robots = [Robot(f'R{i}', f'T{i}', speed=Fraction(rng.choice((1, 2, 3)))) for i in
              range(n_robots)]
    if rng.random() < 0.3:
        robots[0] = Robot('R0', 'T0', robots[0].speed, rng.choice(LOCATIONS),
                          Fraction(rng.randint(0, 3)))

    n_jobs = rng.randint(3, 5)
    names = [f'j{i}' for i in range(n_jobs)]
    plans = []
    for _ in names:
        count = 2 if rng.random() < 0.4 else 1
        plans.append([[rng.randint(0, 2) for _ in range(rng.randint(1, min(2, n_robots)))]
                      for _ in range(count)])
    # One holding arc between two jobs, with exactly one type-q operation in every plan of
    # both, so the holder set can match whatever plans are chosen.
    a, b = sorted(rng.sample(range(n_jobs), 2))
    q = rng.randint(0, 2)
    for index in (a, b):
        for plan in plans[index]:
            plan[:] = [q] + [t for t in plan[1:] if t != q]
    precedence = [(names[i], names[k]) for i in range(n_jobs) for k in range(i + 1, n_jobs)
                  if (i, k) != (a, b) and rng.random() < 0.3]
    jobs = [Job(name, rng.choice(LOCATIONS), tuple(tuple(p) for p in plan))
            for name, plan in zip(names, plans, strict=True)]
    distances = {}
    for i, x in enumerate(LOCATIONS):
        for y in LOCATIONS[i + 1:]:
            distances[x, y] = distances[y, x] = Fraction(rng.randint(0, 4))

    fixed = {}
    roots = [n for n in names if not any(after == n for _, after in precedence)
             and n not in (names[a], names[b])]
    if roots and rng.random() < 0.3:
        fixed = _running(rng, roots[0], jobs, robots, robot_types)
        if fixed and rng.random() < 0.5:
            robots = _late_release(rng, robots, fixed)

    return Problem(
        operation_types={0: 'hold', 1: 'carry', 2: 'weld', LOCOMOTE: 'locomote'},
        robot_types=robot_types, robots=tuple(robots), jobs=tuple(jobs),
        distances=distances, precedence=tuple(precedence),
        holding=((names[a], names[b], q),), locomote=LOCOMOTE,
        fixed=fixed, name=f'random-{seed}')


def _running(rng, name, jobs, robots, robot_types):
    """Fix `name` as started at 0 with plan 0, staffed greedily, if its robots allow."""
    plan = next(j for j in jobs if j.name == name).plans[0]
    free = [r for r in robots if r.start_location is None]
    rng.shuffle(free)
    staff, longest = {}, Fraction(0)
    for q in plan:
        robot = next((r for r in free if q in robot_types[r.type] and r.name not in staff),
                     None)
        if robot is None:
            return {}
        staff[robot.name] = q
        longest = max(longest, robot_types[robot.type][q])
    return {name: FixedJob(0, Fraction(0), longest + 1, staff)}


def _late_release(rng, robots, fixed):
    """Release one robot of the running job after it ends (it reports back late)."""
    (job,) = fixed.values()
    late = rng.choice(sorted(job.robots))
    return [Robot(r.name, r.type, r.speed, r.start_location, job.end + rng.randint(1, 3))
            if r.name == late else r for r in robots]


SEEDS = range(20)


@pytest.mark.parametrize('seed', SEEDS)
def test_mip_and_cpsat_prove_the_same_optimum(seed):
    problem = random_problem(seed)
    cpsat = solve(problem, solver='cpsat', time_limit=10.0, workers=1)
    mip = solve_mip(problem, time_limit=10.0, backend='SCIP')
    assert cpsat.status == Status.OPTIMAL
    assert mip.status == Status.OPTIMAL
    assert mip.makespan == cpsat.makespan
    assert mip.lower_bound == mip.makespan
    assert validate(problem, cpsat.schedule) == []
    assert validate(problem, mip.schedule) == []


def test_highs_backend_agrees_on_one_instance():
    problem = random_problem(0)
    scip = solve_mip(problem, time_limit=10.0, backend='SCIP')
    highs = solve_mip(problem, time_limit=10.0, backend='HIGHS')
    assert highs.status == scip.status == Status.OPTIMAL
    assert highs.makespan == scip.makespan
    assert validate(problem, highs.schedule) == []


def test_generator_covers_the_features():
    problems = [random_problem(seed) for seed in SEEDS]
    assert any(len(j.plans) > 1 for p in problems for j in p.jobs)
    assert any(len(plan) > 1 for p in problems for j in p.jobs for plan in j.plans)
    assert any(p.fixed for p in problems)
    assert any(r.start_location for p in problems for r in p.robots)
    assert any(r.release_time > 0 for p in problems for r in p.robots)
    assert any(r.release_time > f.end for p in problems for f in p.fixed.values()
               for r in p.robots if r.name in f.robots)
    assert any(p.travel(r.name, a, b).denominator > 1 for p in problems for r in p.robots
               for a in LOCATIONS for b in LOCATIONS)


def test_unknown_backend_is_named():
    with pytest.raises(ValueError, match="unknown MIP backend 'GUROBI'"):
        solve_mip(random_problem(0), backend='gurobi')
