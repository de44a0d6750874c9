"""Schedules handed to the fleet are left-shifted: no job starts later than its robots,
predecessors and travel allow, or robots would stand idle before it for nothing."""

from fractions import Fraction

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve


def earliest_start(problem, schedule, job):
    """The latest of: each predecessor's end; for each of the job's robots, its release time
    and, after its previous job (or from its start location), the end of that job plus the
    leg over."""
    times = [schedule.jobs[a].end for a, b in problem.precedence if b == job]
    here = problem.job(job).location
    for name in schedule.jobs[job].robots:
        robot = problem.robot(name)
        sequence = schedule.sequences[name]
        k = sequence.index(job)
        times.append(robot.release_time)
        if k:
            before = sequence[k - 1]
            times.append(schedule.jobs[before].end
                         + problem.travel(name, problem.job(before).location, here))
        elif robot.start_location is not None:
            times.append(robot.release_time + problem.travel(name, robot.start_location, here))
    return max(times, default=Fraction(0))


def test_a_solved_schedule_starts_every_job_as_early_as_its_robots_allow():
    """20 jobs on a time grid of 1/600: CP-SAT's schedule started a first job at 1/600 and
    another 4 units late, every robot on it idle."""
    problem = parse_scenario(random_scenario(1, Shape(jobs=20, robots=5, robot_types=3)))
    result = solve(problem, time_limit=3)
    assert validate(problem, result.schedule) == []
    late = {job: (a.start, earliest_start(problem, result.schedule, job))
            for job, a in result.schedule.jobs.items()
            if a.start != earliest_start(problem, result.schedule, job)}
    assert late == {}
