"""The validator accepts a hand-computed schedule and catches each way of breaking it.

The instance is small enough to check on paper; its valid schedule is tight wherever that
is cheap, so each broken row moves one number just past a bound.

    locations P, Q, S; distances P-Q 4, S-P 2, S-Q 6; type 2 is locomote
    A: Arm, speed 1, starts anywhere at 0       travel = distance * 1 / 1
    B: Arm, speed 3, starts at S, released 13/3 travel = distance * 1 / 3; welds in 3 (override)
    C: Crawler, speed 1, starts at Q, released 2 (re-plan: its job F has been running since 0)
                                                travel = distance * 2 / 1
    job  where  plans          robots        time      why
    F    Q      [0]            C hold        [0, 4]    fixed: started before C's release
    J1   P      [0]            A hold        [0, 2]
    W1   P      [0, 1] | [1]   A hold B weld [5, 8]    B arrives 13/3 + 2/3; held from J1
    J2   Q      [1] | [0]      A weld        [12, 16]  after W1; A travels P->Q in 4
    H    P      [0]            C hold        [13, 17]  C travels Q->P in 8, one to spare
"""

import copy
import pickle
from dataclasses import replace
from fractions import Fraction

import pytest

from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate

FIXED_F = FixedJob(plan=0, start=Fraction(0), end=Fraction(4), robots={'C': 0})


def make_problem(**changes) -> Problem:
    fields = dict(
        operation_types={0: 'hold', 1: 'weld', 2: 'locomote'},
        robot_types={'Arm': {0: Fraction(2), 1: Fraction(4), 2: Fraction(1)},
                     'Crawler': {0: Fraction(4), 2: Fraction(2)}},
        robots=(Robot('A', 'Arm'),
                Robot('B', 'Arm', speed=Fraction(3), start_location='S',
                      release_time=Fraction(13, 3)),
                Robot('C', 'Crawler', start_location='Q', release_time=Fraction(2))),
        jobs=(Job('F', 'Q', ((0,),)),
              Job('J1', 'P', ((0,),)),
              Job('W1', 'P', ((0, 1), (1,))),
              Job('J2', 'Q', ((1,), (0,))),
              Job('H', 'P', ((0,),))),
        distances={pair: Fraction(d) for a, b, d in (('P', 'Q', 4), ('S', 'P', 2), ('S', 'Q', 6))
                   for pair in ((a, b), (b, a))},
        precedence=(('J1', 'W1'), ('W1', 'J2')),
        holding=(('J1', 'W1', 0),),
        locomote=2,
        time_overrides={('B', 1): Fraction(3)},
        fixed={'F': FIXED_F},
    )
    fields.update(changes)
    return Problem(**fields)


def assign(job, start, end, robots, plan=0) -> JobAssignment:
    return JobAssignment(job, plan, Fraction(start), Fraction(end), robots)


VALID_JOBS = {
    'F': assign('F', 0, 4, {'C': 0}),
    'J1': assign('J1', 0, 2, {'A': 0}),
    'W1': assign('W1', 5, 8, {'A': 0, 'B': 1}),
    'J2': assign('J2', 12, 16, {'A': 1}),
    'H': assign('H', 13, 17, {'C': 0}),
}
VALID_SEQUENCES = {'A': ('J1', 'W1', 'J2'), 'B': ('W1',), 'C': ('F', 'H')}


def schedule(jobs=None, sequences=None, drop=()) -> Schedule:
    """The valid schedule with some jobs and sequences replaced and some jobs dropped."""
    merged = {**VALID_JOBS, **(jobs or {})}
    return Schedule({k: v for k, v in merged.items() if k not in drop},
                    {**VALID_SEQUENCES, **(sequences or {})})


def test_hand_computed_schedule_is_valid():
    assert validate(make_problem(), schedule()) == []


def test_fixed_job_is_exempt_only_from_the_release_check():
    """Without the exemption C could not start F at 0: it is released at 2."""
    messages = validate(make_problem(fixed={}), schedule())
    assert len(messages) == 1
    assert "first job 'F' starts at 0 but the robot is released at 2" in messages[0]


def test_travel_is_free_without_a_locomote_type():
    """A travels P->Q in 0, so J2 may follow W1 at once; the distances then do not matter."""
    problem = make_problem(locomote=None, distances={})
    early = schedule({'J2': assign('J2', 8, 12, {'A': 1}), 'H': assign('H', 4, 8, {'C': 0})})
    assert validate(problem, early) == []


BROKEN = [
    pytest.param(schedule(drop=('H',), sequences={'C': ('F',)}),
                 ["job 'H' is not scheduled"], id='job missing'),
    pytest.param(schedule({'X': assign('X', 0, 1, {})}),
                 ["unknown job 'X'"], id='unknown job'),
    pytest.param(schedule({'H': assign('J1', 13, 17, {'C': 0})}),
                 ["schedule entry 'H' holds the assignment of job 'J1'"],
                 id='entry filed under another job'),
    pytest.param(schedule({'H': assign('H', 13, 17, {'Z': 0})}, {'C': ('F',)}),
                 ["job 'H' names unknown robot 'Z'"], id='unknown robot on a job'),
    pytest.param(schedule(sequences={'Z': ()}),
                 ["sequence for unknown robot 'Z'"], id='unknown robot in sequences'),
    pytest.param(schedule({'J2': assign('J2', 12, 16, {'A': 1}, plan=2)}),
                 ["job 'J2' uses plan 2 but has only plans 0..1"], id='plan index invalid'),
    pytest.param(schedule({'J2': assign('J2', 12, 16, {'A': 0})}),
                 ['operation types [0] but plan 0 is [1]'], id='operations not the plan'),
    pytest.param(schedule({'J2': assign('J2', 25, 30, {'C': 1})},
                          {'A': ('J1', 'W1'), 'C': ('F', 'H', 'J2')}),
                 ["robot 'C' cannot do operation type 1 (job 'J2')"], id='robot unable'),
    pytest.param(schedule({'J2': assign('J2', 12, 15, {'A': 1})}),
                 ["job 'J2' ends at 15 before robot 'A' finishes its type-1 operation at 16"],
                 id='job shorter than an operation'),
    pytest.param(schedule({'W1': assign('W1', 5, 7, {'A': 0, 'B': 1})}),
                 ["job 'W1' ends at 7 before robot 'B' finishes its type-1 operation at 8"],
                 id='per-robot time override ignored'),
    pytest.param(schedule({'J1': assign('J1', -1, 2, {'A': 0})}),
                 ['starts at negative time -1', 'before its release time 0'],
                 id='negative start, before release'),
    pytest.param(schedule({'J2': assign('J2', 4, 8, {'C': 0}, plan=1),
                           'H': assign('H', 16, 20, {'C': 0})},
                          {'A': ('J1', 'W1'), 'C': ('F', 'J2', 'H')}),
                 ["job 'J2' starts at 4 before its predecessor 'W1' completes at 8"],
                 id='precedence'),
    pytest.param(schedule(sequences={'B': ('W1', 'J2')}),
                 ["robot 'B': sequence lists job 'J2' it has no operation in"],
                 id='sequence lists a job of others'),
    pytest.param(schedule(sequences={'C': ('F',)}),
                 ["robot 'C' has an operation in job 'H' but its sequence omits it"],
                 id='sequence omits a job'),
    pytest.param(schedule(sequences={'C': ('F', 'H', 'H')}),
                 ["sequence lists job 'H' 2 times", "'H' starts at 13, overlapping 'H'"],
                 id='sequence repeats a job'),
    pytest.param(schedule({'H': assign('H', 3, 7, {'C': 0})}),
                 ["robot 'C': job 'H' starts at 3, overlapping 'F' which ends at 4"],
                 id='overlap on a robot'),
    pytest.param(schedule({'J2': assign('J2', 11, 15, {'A': 1})}),
                 ["robot 'A': job 'J2' starts at 11 but the robot ends 'W1' at 8 and travels "
                  "4 from 'P' to 'Q', arriving at 12"], id='travel between jobs'),
    pytest.param(schedule({'W1': assign('W1', Fraction(4999, 1000), 8, {'A': 0, 'B': 1})}),
                 ["robot 'B': first job 'W1' starts at 4.999 but the robot is released at "
                  "4.333 at 'S' and arrives at 'P' at 5"], id='release and travel from start'),
    pytest.param(schedule({'F': assign('F', 0, 5, {'C': 0})}),
                 ["fixed job 'F' has end 5 but is fixed with 4"], id='fixed job moved'),
    pytest.param(schedule({'W1': assign('W1', 5, 8, {'B': 1}, plan=1)}, {'A': ('J1', 'J2')}),
                 ["holding arc ('J1', 'W1', 0): type-0 robots of 'J1' are ['A'] but of 'W1' "
                  'are []'], id='holder does not hold'),
    pytest.param(schedule({'H': assign('H', 3, 5, {'A': 0})},
                          {'A': ('J1', 'H', 'W1', 'J2'), 'C': ('F',)}),
                 ["holding arc ('J1', 'W1', 0): robot 'A' does not go directly from 'J1' to "
                  "'W1'"], id='holder detours'),
]


@pytest.mark.parametrize(('broken', 'expected'), BROKEN)
def test_each_violation_is_reported_alone(broken, expected):
    messages = validate(make_problem(), broken)
    assert len(messages) == len(expected), messages
    for message, fragment in zip(messages, expected, strict=True):
        assert fragment in message


def test_violations_accumulate():
    """Independent faults are all reported, not just the first one found."""
    broken = schedule({'J2': assign('J2', 11, 15, {'A': 1}), 'F': assign('F', 0, 5, {'C': 0})})
    messages = validate(make_problem(), broken)
    assert len(messages) == 2, messages
    assert "robot 'A': job 'J2' starts at 11" in messages[0]
    assert "fixed job 'F' has end 5" in messages[1]


def test_problem_with_changed_release_is_checked_exactly():
    """13/3 + 2/3 is exactly 5; a release 1/1000 later must already be caught."""
    robots = list(make_problem().robots)
    robots[1] = replace(robots[1], release_time=Fraction(13, 3) + Fraction(1, 1000))
    messages = validate(make_problem(robots=tuple(robots)), schedule())
    assert len(messages) == 1
    assert "robot 'B': first job 'W1' starts at 5" in messages[0]


def test_times_read_as_decimals_and_stay_exact_in_the_data():
    """A start 1/10^9 before the arrival it must wait for: written with the places that tell
    the two apart, never as a fraction; the exact values stay with the message."""
    early = Fraction(5) - Fraction(1, 10 ** 9)
    messages = validate(make_problem(), schedule({'W1': assign('W1', early, 8,
                                                                {'A': 0, 'B': 1})}))
    assert messages == ["robot 'B': first job 'W1' starts at 4.999999999 but the robot is "
                        "released at 4.333333333 at 'S' and arrives at 'P' at 5"]
    assert messages[0].exact == ("robot 'B': first job 'W1' starts at 4999999999/1000000000 "
                                 "but the robot is released at 13/3 at 'S' and arrives at "
                                 "'P' at 5")
    assert messages[0].values['start'] == early
    assert messages[0].values['arrival'] == 5
    for copied in (copy.deepcopy(messages[0]), pickle.loads(pickle.dumps(messages[0]))):
        assert copied == messages[0] and copied.exact == messages[0].exact
