"""The local search for multi-robot jobs with travel: valid, never worse than its start, and
it finds the moves a critical path asks for."""

import random
import time
from fractions import Fraction

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.scenario import parse_scenario
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.greedy import greedy_schedule
from fjsp_planner.solving.local import (
    _best_move,
    _from_schedule,
    _Instance,
    _ruined_and_recreated,
    _to_schedule,
    local_search,
)


def _slow_and_fast():
    """A welds in 5, B in 1; the schedule doing x then y on A ends at 10."""
    problem = Problem(operation_types={1: 'weld'},
                      robot_types={'Slow': {1: Fraction(5)}, 'Fast': {1: Fraction(1)}},
                      robots=(Robot('A', 'Slow'), Robot('B', 'Fast')),
                      jobs=(Job('x', 'here', ((1,),)), Job('y', 'here', ((1,),))))
    start = Schedule({'x': JobAssignment('x', 0, Fraction(0), Fraction(5), {'A': 1}),
                      'y': JobAssignment('y', 0, Fraction(5), Fraction(10), {'A': 1})},
                     {'A': ('x', 'y'), 'B': ()})
    assert validate(problem, start) == []
    return problem, start


def test_jobs_move_from_a_slow_robot_to_a_fast_one():
    """Giving y to B ends at 5, then x too at 2 (B welds both, one after the other), the
    optimum."""
    problem, start = _slow_and_fast()
    found, _ = local_search(problem, start, time.monotonic() + 1)
    assert validate(problem, found) == []
    assert found.makespan == 2


def test_two_jobs_of_the_same_robots_change_places():
    """x and y each need both A and B (x 5 long, y 1), z needs C after y. Done x then y, z
    ends at 11; y then x lets z start at 1 and everything ends at 6, the optimum. Swapped
    on A alone, x and y would follow each other in both orders (B still does x first)."""
    problem = Problem(operation_types={1: 'weld', 2: 'bolt', 3: 'inspect'},
                      robot_types={'Arm': {1: Fraction(5), 2: Fraction(1)},
                                   'Eye': {3: Fraction(5)}},
                      robots=(Robot('A', 'Arm'), Robot('B', 'Arm'), Robot('C', 'Eye')),
                      jobs=(Job('x', 'here', ((1, 1),)), Job('y', 'here', ((2, 2),)),
                            Job('z', 'here', ((3,),))),
                      precedence=(('y', 'z'),))
    start = Schedule({'x': JobAssignment('x', 0, Fraction(0), Fraction(5), {'A': 1, 'B': 1}),
                      'y': JobAssignment('y', 0, Fraction(5), Fraction(6), {'A': 2, 'B': 2}),
                      'z': JobAssignment('z', 0, Fraction(6), Fraction(11), {'C': 3})},
                     {'A': ('x', 'y'), 'B': ('x', 'y'), 'C': ('z',)})
    assert validate(problem, start) == []
    found, _ = local_search(problem, start, time.monotonic() + 1)
    assert validate(problem, found) == []
    assert found.makespan == 6


def test_a_job_changes_to_a_faster_plan():
    """x can be welded (5 on A) or bolted (1 on A and B at once); started welded, the search
    bolts it: no other robot can weld, so only the other plan shortens the schedule."""
    problem = Problem(operation_types={1: 'weld', 2: 'bolt'},
                      robot_types={'Arm': {1: Fraction(5), 2: Fraction(1)},
                                   'Driver': {2: Fraction(1)}},
                      robots=(Robot('A', 'Arm'), Robot('B', 'Driver')),
                      jobs=(Job('x', 'here', ((1,), (2, 2))),))
    start = Schedule({'x': JobAssignment('x', 0, Fraction(0), Fraction(5), {'A': 1})},
                     {'A': ('x',), 'B': ()})
    assert validate(problem, start) == []
    found, _ = local_search(problem, start, time.monotonic() + 1)
    assert validate(problem, found) == []
    assert found.makespan == 1 and found.jobs['x'].plan == 1


def test_generated_scenarios_stay_valid_and_no_longer():
    """Holding arcs, travel and multi-robot jobs: every move keeps the holders' direct legs
    and precedence, so the result validates and is no longer than the greedy start."""
    for seed in (1, 2, 3):
        problem = parse_scenario(random_scenario(seed, Shape(jobs=30, robots=5)))
        start = greedy_schedule(problem)
        found, _ = local_search(problem, start, time.monotonic() + 0.5, seed=seed)
        assert validate(problem, found) == []
        assert found.makespan <= start.makespan


def test_no_job_is_put_before_a_running_one():
    """A (welds in 1) runs f at a from 0 to 5; B (welds in 5) does x then y at b, 1 away:
    the schedule ends at 10. Put before f on A, y would seem to end at 2 but overlap f; after
    f it ends at 7 (x stays on B), the optimum."""
    problem = Problem(operation_types={1: 'weld', 2: 'move'},
                      robot_types={'Fast': {1: Fraction(1), 2: Fraction(1)},
                                   'Slow': {1: Fraction(5), 2: Fraction(1)}},
                      robots=(Robot('A', 'Fast', start_location='a'),
                              Robot('B', 'Slow', start_location='b')),
                      jobs=(Job('f', 'a', ((1,),)), Job('x', 'b', ((1,),)),
                            Job('y', 'b', ((1,),))),
                      distances={('a', 'b'): Fraction(1), ('b', 'a'): Fraction(1)},
                      locomote=2, fixed={'f': FixedJob(0, Fraction(0), Fraction(5), {'A': 1})})
    start = Schedule({'f': JobAssignment('f', 0, Fraction(0), Fraction(5), {'A': 1}),
                      'x': JobAssignment('x', 0, Fraction(0), Fraction(5), {'B': 1}),
                      'y': JobAssignment('y', 0, Fraction(5), Fraction(10), {'B': 1})},
                     {'A': ('f',), 'B': ('x', 'y')})
    assert validate(problem, start) == []
    found, _ = local_search(problem, start, time.monotonic() + 1)
    assert validate(problem, found) == []
    assert found.makespan == 7


def test_a_tabu_job_moves_only_to_beat_the_best_schedule():
    """With x and y both tabu, giving one to B (ends at 5) is still made while the best
    schedule found ends at 10, and no move is made once one ending at 2 was found."""
    problem, start = _slow_and_fast()
    inst = _Instance(problem)
    current = _from_schedule(inst, start)
    assert current.evaluate(inst)
    x, y = inst.index['x'], inst.index['y']
    tabu = {x: 5, y: 5}
    moved, job = _best_move(inst, current, random.Random(0), tabu, 1, current)
    assert moved.makespan == 5 and job in (x, y)
    both_fast = _from_schedule(inst, Schedule(
        {'x': JobAssignment('x', 0, Fraction(0), Fraction(1), {'B': 1}),
         'y': JobAssignment('y', 0, Fraction(1), Fraction(2), {'B': 1})},
        {'A': (), 'B': ('x', 'y')}))
    assert both_fast.evaluate(inst) and both_fast.makespan == 2
    assert _best_move(inst, current, random.Random(0), tabu, 1, both_fast) == (None, None)
    moved, _ = _best_move(inst, current, random.Random(0), {}, 1, both_fast)
    assert moved.makespan == 5


def test_jobs_put_back_gather_by_place():
    """One robot works 1 on each of w, y at a and x, z at b, 10 apart. Done w, x, y, z it
    crosses three times (ends at 34); taken out and put back, each job goes next to one at
    its place: one crossing, the schedule ends at 14."""
    problem = Problem(operation_types={0: 'work', 1: 'move'},
                      robot_types={'Arm': {0: Fraction(1), 1: Fraction(1)}},
                      robots=(Robot('A', 'Arm'),),
                      jobs=(Job('w', 'a', ((0,),)), Job('x', 'b', ((0,),)),
                            Job('y', 'a', ((0,),)), Job('z', 'b', ((0,),))),
                      distances={('a', 'b'): Fraction(10), ('b', 'a'): Fraction(10)},
                      locomote=1)
    inst = _Instance(problem)
    alternating = _from_schedule(inst, greedy_schedule(problem))
    alternating.orders['A'] = [inst.index[j] for j in 'wxyz']
    assert alternating.evaluate(inst) and alternating.makespan == 34
    gathered = _ruined_and_recreated(inst, alternating, random.Random(0))
    assert gathered.evaluate(inst) and gathered.makespan == 14


def test_ruined_and_recreated_schedules_stay_valid():
    """Jobs taken out of generated schedules (holding arcs, travel, multi-robot jobs, several
    plans) and put back: every job is staffed by one of its plans and the schedule
    validates, however often it is done."""
    for seed in (1, 2, 3):
        problem = parse_scenario(random_scenario(seed, Shape(jobs=30, robots=5)))
        inst = _Instance(problem)
        current = _from_schedule(inst, greedy_schedule(problem))
        assert current.evaluate(inst)
        rng = random.Random(seed)
        for _ in range(20):
            current = _ruined_and_recreated(inst, current, rng)
            assert current.evaluate(inst)
            assert validate(problem, _to_schedule(inst, current)) == []
