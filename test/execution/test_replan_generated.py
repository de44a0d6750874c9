"""Property tests on generated scenarios (`fjsp_planner.model.generator`): the schedule
`solve` returns is valid, and so is a re-plan from a random moment of it, with a random robot
failed or not — or the re-plan is blocked naming each job no healthy robot can staff.
Seeds: a fixed range and this run's own (`generated_seeds`, printed in pytest's header)."""

import random
from fractions import Fraction

import pytest

from fjsp_planner.execution.replan import ExecutionState, RobotSituation, replan
from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve

from generated_seeds import fresh
from replan_checks import check_replan_result

SEEDS = [*range(40), *fresh(40, salt=9)]


def mid_mission(problem, schedule, now: Fraction, failed: str | None) -> ExecutionState:
    """The state of `schedule` executed as planned until `now`: jobs ended are done, jobs
    begun are running, each robot at its job, on its way to the next, or where it stopped."""
    done = frozenset(name for name, a in schedule.jobs.items() if a.end <= now)
    running = {name: a for name, a in schedule.jobs.items() if a.start <= now < a.end}
    robots = {}
    for robot in problem.robots:
        location, free_at = robot.start_location, max(now, robot.release_time)
        for visit in schedule.visits(problem, robot.name):
            here = problem.job(visit.job).location
            if visit.job in running:
                location, free_at = here, visit.end
                break
            if visit.travel_start <= now < visit.arrival:
                location, free_at = here, visit.arrival
                break
            if visit.end <= now:
                location, free_at = here, now
        robots[robot.name] = RobotSituation(robot.name, robot.name != failed, location, free_at,
                                            now if robot.name == failed else None)
    return ExecutionState(now, done, running, robots,
                          {name: schedule.jobs[name] for name in done})


@pytest.mark.slow
@pytest.mark.parametrize('seed', SEEDS)
def test_a_solved_generated_scenario_and_its_re_plan_are_valid(seed):
    rng = random.Random(seed)
    problem = parse_scenario(random_scenario(
        seed, Shape(jobs=rng.randint(4, 14), robots=rng.randint(3, 6))))
    result = solve(problem, time_limit=0.5, workers=1)
    assert result.schedule is not None, (seed, result.status, result.notes)
    assert validate(problem, result.schedule) == [], seed
    schedule = result.schedule
    now = Fraction(rng.randint(0, int(schedule.makespan * 10)), 10)
    failed = rng.choice([None, *(r.name for r in problem.robots)])
    state = mid_mission(problem, schedule, now, failed)
    outcome = replan(problem, schedule, state, time_limit=0.5, workers=1)
    if outcome.residual.blocked:
        assert failed is not None, (seed, outcome.residual.blocked)
        assert all('cannot be staffed' in why for why in outcome.residual.blocked), seed
        return
    if outcome.residual.complete:
        assert state.done | set(outcome.residual.voided) >= set(schedule.jobs), seed
        return
    check_replan_result(state, outcome)
    assert validate(outcome.residual.problem, outcome.schedule) == [], seed
