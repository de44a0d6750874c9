"""The tabu search for single-robot jobs without travel, and the classic solve around it.

Optima worked out by hand in the docstrings; every schedule goes through the validator.
"""

import random
import threading
import time
from fractions import Fraction

import pytest

from fjsp_planner.model.fjs import load_fjs
from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import JobAssignment, Schedule, Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving import tabu
from fjsp_planner.solving.cpsat import SearchHandle, solve_cpsat
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.solve import solve

from repo_paths import DATA, PAPER, REPO

BENCH = REPO / 'bench' / 'data' / 'fjs'


def all_on(problem: Problem, robot: str) -> Schedule:
    """Every job on `robot`, one after another in the file's order (a valid, poor start)."""
    jobs, at = {}, Fraction(0)
    for job in problem.jobs:
        q = job.plans[0][0]
        end = at + problem.duration(robot, q)
        jobs[job.name] = JobAssignment(job.name, 0, at, end, {robot: q})
        at = end
    sequences = {r.name: () for r in problem.robots}
    sequences[robot] = tuple(j.name for j in problem.jobs)
    return Schedule(jobs, sequences)


def random_shop(seed: int) -> Problem:
    """Jobs with one to three able machines each, precedence a random DAG (not chains),
    machines with release times: what the search must handle beyond the classic files."""
    rng = random.Random(seed)
    machines = [f'm{i}' for i in range(4)]
    efficiency = {m: {} for m in machines}
    jobs = []
    for i in range(30):
        for m in rng.sample(machines, rng.randint(1, 3)):
            efficiency[m][i] = Fraction(rng.randint(1, 9))
        jobs.append(Job(f'j{i}', 'here', ((i,),)))
    precedence = [(f'j{a}', f'j{b}') for b in range(30) for a in range(b)
                  if rng.random() < 0.08]
    robots = tuple(Robot(m, m, release_time=Fraction(rng.randint(0, 5))) for m in machines)
    return Problem(operation_types={i: f'op{i}' for i in range(30)}, robot_types=efficiency,
                   robots=robots, jobs=tuple(jobs), precedence=tuple(precedence))


def test_reaches_the_hand_checked_optimum_from_a_poor_start():
    """parallel_3x2: three jobs of 4 on M1 or 6 on M2. All on M1 takes 12; the optimum puts
    two on M1 and one on M2: 8."""
    problem = load_fjs(DATA / 'parallel_3x2.fjs')
    start = all_on(problem, 'M1')
    assert start.makespan == 12 and validate(problem, start) == []
    found, _ = tabu.tabu_search(problem, start, time.monotonic() + 1)
    assert found.makespan == 8
    assert validate(problem, found) == []


@pytest.mark.parametrize('seed', range(5))
def test_schedules_stay_valid_on_random_precedence_and_release_times(seed):
    problem = random_shop(seed)
    assert tabu.applies(problem)
    start = greedy_schedule(problem)
    found, _ = tabu.tabu_search(problem, start, time.monotonic() + 0.5, seed=seed)
    assert validate(problem, found) == []
    assert found.makespan <= start.makespan


def test_improves_a_benchmark_greedy_schedule():
    """Brandimarte mk06: the greedy schedule is far above the best known 57."""
    problem = load_fjs(BENCH / 'brandimarte' / 'mk06.fjs')
    start = greedy_schedule(problem)
    found, found_at = tabu.tabu_search(problem, start, time.monotonic() + 1)
    assert validate(problem, found) == []
    assert 57 <= found.makespan < start.makespan
    assert found_at <= time.monotonic()


def test_stop_ends_the_search_and_nothing_better_returns_the_start():
    """One job, one machine: nothing to improve; a stop that is already true ends it."""
    problem = load_fjs(DATA / 'chain_1x1.fjs')
    start = greedy_schedule(problem)
    began = time.monotonic()
    found, _ = tabu.tabu_search(problem, start, began + 30, stop=lambda: True)
    assert found is start
    assert time.monotonic() - began < 5


def with_fixed(problem: Problem) -> Problem:
    first = problem.jobs[0]
    return Problem(operation_types=problem.operation_types, robot_types=problem.robot_types,
                   robots=problem.robots, jobs=problem.jobs, precedence=problem.precedence,
                   fixed={first.name: FixedJob(0, Fraction(0), Fraction(3),
                                               {'M1': first.plans[0][0]})})


@pytest.mark.parametrize(('problem', 'expected', 'why'), [
    (load_fjs(DATA / 'flex_2x3.fjs'), True, 'a classic file'),
    (random_shop(0), True, 'any precedence, release times'),
    (load_scenario(PAPER), False, 'multi-robot jobs, travel and holding'),
    (with_fixed(load_fjs(DATA / 'tiny_2x2.fjs')), False, 'a running job (a re-plan)'),
    (Problem(operation_types={0: 'w'}, robot_types={'a': {0: Fraction(1, 1009)}},
             robots=(Robot('r', 'a'),), jobs=(Job('j', 'here', ((0,),)),)), False,
     'times on a grid finer than MAX_SCALE'),
], ids=lambda v: v if isinstance(v, str) else '')
def test_applies_only_to_single_robot_jobs_without_travel(problem, expected, why):
    assert tabu.applies(problem) is expected, why


def test_classic_solve_proves_a_small_optimum_and_stops_early():
    """flex_2x3 (hand-checked optimum 5): CP-SAT proves it at once and the search stops with
    it, far before the limit."""
    problem = load_fjs(DATA / 'flex_2x3.fjs')
    result = solve(problem, time_limit=30)
    assert result.status == Status.OPTIMAL and result.makespan == 5
    assert result.solve_seconds < 10
    assert validate(problem, result.schedule) == []


def test_classic_solve_reports_an_honest_bound_on_a_benchmark():
    """mk06's best published lower bound is 57: no bound of ours may claim more."""
    problem = load_fjs(BENCH / 'brandimarte' / 'mk06.fjs')
    result = solve(problem, time_limit=2)
    assert validate(problem, result.schedule) == []
    assert result.lower_bound <= 57 <= result.makespan
    assert result.solve_seconds < 8


def test_a_stopped_cpsat_returns_soon_with_what_it_has():
    problem = load_fjs(BENCH / 'brandimarte' / 'mk10.fjs')
    handle = SearchHandle()
    outcome = {}
    worker = threading.Thread(target=lambda: outcome.update(result=solve_cpsat(
        problem, 60, 1, upper_bound=greedy_schedule(problem), handle=handle)))
    began = time.monotonic()
    worker.start()
    time.sleep(1.5)
    handle.stop()
    worker.join(30)
    assert not worker.is_alive()
    assert time.monotonic() - began < 20
    result = outcome['result']
    assert result.schedule is None or validate(problem, result.schedule) == []
    assert handle.best is None or handle.best >= 193


def test_a_handle_stopped_before_the_search_starts_ends_it_at_once():
    problem = load_fjs(BENCH / 'brandimarte' / 'mk10.fjs')
    handle = SearchHandle()
    handle.stop()
    began = time.monotonic()
    solve_cpsat(problem, 60, 1, upper_bound=greedy_schedule(problem), handle=handle)
    assert time.monotonic() - began < 15
