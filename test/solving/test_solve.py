"""CP-SAT and greedy on the paper instance and on instances where one constraint decides.

Each small instance has a unique optimum worked out by hand in its docstring.
"""

import re
import time
from fractions import Fraction

import pytest

from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import Result, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds.jobs import critical_path_bound
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.solve import solve
from fjsp_planner.solving.start import find_start, run_from

from repo_paths import PAPER

OPS = {0: 'hold', 1: 'weld', 2: 'move'}


def small(robots, jobs, **extra):
    """Robots given as (name, {op: time}) each get a type of their own."""
    types = {name: {q: Fraction(t) for q, t in times.items()} for name, times in robots}
    fleet = tuple(extra.pop('fleet', None) or (Robot(name, name) for name, _ in robots))
    return Problem(operation_types=OPS, robot_types=types, robots=fleet,
                   jobs=tuple(Job(n, extra.pop(f'loc_{n}', 'here'), p) for n, p in jobs),
                   **extra)


def optimal(problem, **kwargs):
    result = solve(problem, time_limit=10, workers=2, **kwargs)
    assert result.status == Status.OPTIMAL
    assert validate(problem, result.schedule) == []
    assert result.makespan == result.lower_bound == result.schedule.makespan
    return result


def test_paper_instance_proven_optimal_at_32():
    problem = load_scenario(PAPER)
    result = optimal(problem)
    assert result.makespan == 32
    assert result.gap == 0


def test_greedy_is_valid_and_no_better_than_optimum():
    problem = load_scenario(PAPER, panels=2)
    schedule = greedy_schedule(problem)
    assert validate(problem, schedule) == []
    assert schedule.makespan >= 64


def test_alternative_plan_wins():
    """Plan 0 needs one robot for 7; plan 1 two robots for 2 each: plan 1, makespan 2."""
    problem = small([('r1', {0: 2, 1: 7}), ('r2', {0: 2, 1: 7})], [('x', ((1,), (0, 0)))])
    result = optimal(problem)
    assert result.makespan == 2
    assert result.schedule.jobs['x'].plan == 1
    assert set(result.schedule.jobs['x'].robots) == {'r1', 'r2'}


def test_multi_robot_job_lasts_as_long_as_its_slowest_operation():
    """One plan [hold, weld]: r1 holds fast but welds slowly, r2 the reverse: 3, not 9."""
    problem = small([('r1', {0: 1, 1: 9}), ('r2', {0: 9, 1: 3})], [('x', ((0, 1),))])
    result = optimal(problem)
    assert result.makespan == 3
    assert result.schedule.jobs['x'].robots == {'r1': 0, 'r2': 1}


def test_holding_keeps_the_holder_from_other_work():
    """Chain j -> k -> a, j held into a (type 0). Without the hold fast r1 does all: 3.
    With it r1 holds from j to a, so slow r2 does k in 1-4 and a runs 4-5: 5."""
    jobs = [('j', ((0,),)), ('k', ((0,),)), ('a', ((0,),))]
    robots = [('r1', {0: 1}), ('r2', {0: 3})]
    chain = (('j', 'k'), ('k', 'a'))
    assert optimal(small(robots, jobs, precedence=chain)).makespan == 3
    result = optimal(small(robots, jobs, precedence=chain, holding=(('j', 'a', 0),)))
    assert result.makespan == 5
    holder = next(iter(result.schedule.jobs['j'].robots))
    assert result.schedule.jobs['a'].robots == {holder: 0}
    route = result.schedule.sequences[holder]
    assert route[route.index('j') + 1] == 'a'


def travel_problem(**robot):
    distances = {}
    for a, b, d in (('base', 'far', 10), ('base', 'near', 1), ('far', 'near', 1)):
        distances[a, b] = distances[b, a] = Fraction(d)
    fleet = (Robot('r1', 'r1', Fraction(1), 'base', Fraction(robot.get('release', 0))),)
    return small([('r1', {0: 1, 2: 1})], [('x', ((0,),)), ('y', ((0,),))], fleet=fleet,
                 distances=distances, locomote=2, loc_x='far', loc_y='near')


def test_travel_decides_the_order():
    """From base: near (1), y 1-2, on to far (1), x 3-4 = 4; far first would be 13."""
    result = optimal(travel_problem())
    assert result.makespan == 4
    assert result.schedule.sequences['r1'] == ('y', 'x')


def test_release_time_and_start_location_delay_the_start():
    """Released at 5 at base: near at 6, y 6-7, far at 8, x 8-9."""
    result = optimal(travel_problem(release=5))
    assert result.makespan == 9
    assert result.schedule.jobs['y'].start == 6


def test_per_robot_override_picks_the_faster_robot():
    """Same type, time 10; r2 overridden to 2 for holding."""
    problem = Problem(operation_types=OPS, robot_types={'arm': {0: Fraction(10)}},
                      robots=(Robot('r1', 'arm'), Robot('r2', 'arm')),
                      jobs=(Job('x', 'here', ((0,),)),),
                      time_overrides={('r2', 0): Fraction(2)})
    result = optimal(problem)
    assert result.makespan == 2
    assert result.schedule.jobs['x'].robots == {'r2': 0}


def test_fixed_job_keeps_its_robot_until_it_ends():
    """r1 is busy on x until 5 and is the only one able to weld y: y runs 5-6."""
    problem = small([('r1', {0: 5, 1: 1}), ('r2', {0: 1})], [('x', ((0,),)), ('y', ((1,),))],
                    fixed={'x': FixedJob(0, Fraction(0), Fraction(5), {'r1': 0})})
    result = optimal(problem)
    assert result.makespan == 6
    assert result.schedule.jobs['x'].start == 0


def test_rational_travel_is_exact():
    """Speed 3: a leg of 1 takes 1/3; one robot, y then x: 1/3 + 1 + 1/3 + 1 = 8/3."""
    distances = {('a', 'b'): Fraction(1), ('b', 'a'): Fraction(1), ('base', 'a'): Fraction(1),
                 ('a', 'base'): Fraction(1), ('base', 'b'): Fraction(2),
                 ('b', 'base'): Fraction(2)}
    problem = small([('r1', {0: 1, 2: 1})], [('x', ((0,),)), ('y', ((0,),))],
                    fleet=(Robot('r1', 'r1', Fraction(3), 'base'),), distances=distances,
                    locomote=2, loc_x='b', loc_y='a')
    result = optimal(problem)
    assert result.makespan == Fraction(8, 3)


@pytest.mark.slow
def test_a_tight_limit_still_returns_a_valid_schedule():
    """Ten panels in 4 s: CP-SAT alone needs longer for a first schedule (6 s unloaded); the
    greedy one (0.1-2 s, within its 1.6 s share even on a loaded machine) is returned, or
    CP-SAT's from it."""
    problem = load_scenario(PAPER, panels=10)
    result = solve(problem, time_limit=4.0, workers=1)
    assert result.schedule is not None
    assert validate(problem, result.schedule) == []


def test_time_limit_bounds_the_whole_call_on_a_large_instance():
    """30 panels (360 jobs) once took 20 s with a 5 s limit: a full greedy pass, then the
    model building, each ran past it. The margin is wide for a shared machine: alone the
    call takes about 3.4 s, beside the whole suite on two cores up to 7 s."""
    problem = load_scenario(PAPER, panels=30)
    began = time.monotonic()
    result = solve(problem, time_limit=2.0, workers=1)
    assert time.monotonic() - began < 10.0
    assert result.schedule is None or validate(problem, result.schedule) == []


@pytest.mark.parametrize('workers', [0, -1, 65, 999999, 2.5, True])
def test_workers_out_of_range_are_refused_naming_the_value(workers):
    message = f'workers must be an integer from 1 to 64, got {workers!r}'
    with pytest.raises(ValueError, match=re.escape(message)):
        solve(load_scenario(PAPER), workers=workers)


@pytest.mark.parametrize('limit', [0, -1.0, float('nan')])
def test_time_limit_must_be_positive(limit):
    with pytest.raises(ValueError, match='time_limit must be a positive number'):
        solve(load_scenario(PAPER), time_limit=limit)


def test_greedy_solver_reports_a_valid_bound():
    problem = load_scenario(PAPER)
    result = solve(problem, solver='greedy')
    assert result.status == Status.FEASIBLE
    assert critical_path_bound(problem) <= result.lower_bound <= 32 <= result.makespan


def test_keep_prefers_previous_assignments_at_equal_makespan():
    """Two identical robots, two independent jobs: both optima are fine; keep picks one."""
    problem = small([('r1', {0: 1}), ('r2', {0: 1})], [('x', ((0,),)), ('y', ((0,),))])
    first = optimal(problem)
    swapped = {'x': 'r2', 'y': 'r1'} if first.schedule.jobs['x'].robots == {'r1': 0} else {
        'x': 'r1', 'y': 'r2'}
    previous = first.schedule.__class__(
        {j: a.__class__(j, 0, a.start, a.end, {swapped[j]: 0})
         for j, a in first.schedule.jobs.items()},
        {r: tuple(j for j, who in swapped.items() if who == r) for r in ('r1', 'r2')})
    kept = optimal(problem, keep=previous)
    assert {j: next(iter(a.robots)) for j, a in kept.schedule.jobs.items()} == swapped


def test_unknown_solver_is_rejected():
    with pytest.raises(ValueError, match="unknown solver 'gurobi'"):
        solve(load_scenario(PAPER), solver='gurobi')


def test_release_time_binds_after_a_running_job():
    """r1 runs x until 2 but is released (re-planned) at 5: y, which only r1 can do, 5-6."""
    problem = small([('r1', {0: 2, 1: 1})], [('x', ((0,),)), ('y', ((1,),))],
                    fleet=(Robot('r1', 'r1', release_time=Fraction(5)),),
                    fixed={'x': FixedJob(0, Fraction(0), Fraction(2), {'r1': 0})})
    result = optimal(problem)
    assert result.makespan == 6
    early = result.schedule.__class__(
        {**result.schedule.jobs, 'y': result.schedule.jobs['y'].__class__(
            'y', 0, Fraction(2), Fraction(3), {'r1': 1})}, result.schedule.sequences)
    assert any("job 'y' starts at 2 before its release time 5" in m
               for m in validate(problem, early))


def test_a_broken_hint_is_ignored_not_trusted():
    problem = load_scenario(PAPER)
    broken = greedy_schedule(problem)
    broken = broken.__class__({j: a for j, a in broken.jobs.items() if j != 'Ad'},
                              broken.sequences)
    result = solve(problem, time_limit=10, hint=broken)
    assert result.makespan == 32 and validate(problem, result.schedule) == []
    assert any('hint is not a valid schedule' in note for note in result.notes)


def test_a_search_wrongly_claiming_infeasibility_still_yields_the_valid_start():
    """The start schedules are validated, so a search calling the problem infeasible was
    misled (a bound too high): the caller gets the start's schedule and a note saying so."""
    problem = load_scenario(PAPER)
    began = time.monotonic()
    start = find_start(problem, None, began, greedy_time=5, time_limit=5)

    def misled(seconds):
        return Result(Status.INFEASIBLE, None, None, 0.01, None, 'cpsat')

    result = run_from(problem, start, began, 5, misled)
    assert result.status == Status.FEASIBLE and result.schedule is start.greedy
    assert validate(problem, result.schedule) == []
    assert any('infeasible, which the starting schedule disproves' in n for n in result.notes)
