"""Routed scenarios past the sizes CP-SAT proves at once: CP-SAT alone up to
`MAX_PAIRWISE_JOBS` jobs, two runs of the local search beyond, the search-free bounds in a
thread of their own; whoever wins, the schedule is valid and no longer than the start."""

import pytest

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.routed import MAX_PAIRWISE_JOBS, MIN_JOBS
from fjsp_planner.solving.solve import solve


def solved(jobs: int, workers: int = 2):
    problem = parse_scenario(random_scenario(21, Shape(jobs=jobs, robots=5, robot_types=3)))
    assert problem.locomote is not None and len(problem.jobs) > MIN_JOBS
    return problem, solve(problem, time_limit=6, workers=workers)


@pytest.mark.slow
def test_up_to_forty_jobs_the_schedule_is_cpsats_or_the_start():
    """CP-SAT has both cores there: no local search schedule comes back."""
    problem, result = solved(MAX_PAIRWISE_JOBS - 5)
    assert result.solver in ('cpsat', 'greedy')
    assert validate(problem, result.schedule) == []
    assert result.lower_bound <= result.makespan <= greedy_schedule(problem).makespan


@pytest.mark.slow
@pytest.mark.parametrize('workers', [1, 2, 3])
def test_beyond_forty_jobs_the_local_search_shortens_the_start(workers):
    """Past MAX_PAIRWISE_JOBS the local search (one run on one core; two, one in a process of
    its own, on two; CP-SAT beside them on a third) shortens the start within seconds."""
    problem, result = solved(MAX_PAIRWISE_JOBS + 20, workers)
    assert result.solver in (('local search', 'cpsat') if workers > 2 else ('local search',))
    assert not [note for note in result.notes if 'second process' in note]
    assert validate(problem, result.schedule) == []
    assert result.lower_bound <= result.makespan < greedy_schedule(problem).makespan
