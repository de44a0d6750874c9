"""Re-planning after a failure (docs/model.md, "Re-planning"), on an instance small enough
to re-plan on paper.

    locations p, q at distance 4; type 2 is locomote; every robot is an Arm of speed 1
    (hold 2, weld 3, travel = distance) starting at p at time 0
    job  where  plan    after      holding
    J    p      [0]                J -> W, type 0: J's holder goes directly to W
    P    p      [1]
    W    p      [0, 1]  J, P
    F    q      [1]     W

    The plan (optimal, makespan 9: J/P, then W, then F, lasting 3 + 3 + 3):
    J [0, 2] A; P [0, 3] B; W [3, 6] A holds, B welds; F [6, 9] C, who travels p -> q in
    [0, 4] and waits. Each test fails robots at a time `now` of that plan and re-plans; the
    docstrings give the hand-computed optimum of what remains.
"""

from dataclasses import replace
from fractions import Fraction

import pytest

from fjsp_planner.execution.replan import (
    ExecutionState,
    RobotSituation,
    StateError,
    Waypoint,
    frozen,
    improve,
    repair,
    replan,
    residual_problem,
    simulated_state,
)
from fjsp_planner.model.problem import FixedJob, Job, Problem, Robot
from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import JobAssignment, Schedule
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.solve import solve

from replan_checks import check_replan_result
from repo_paths import PAPER


def make_problem() -> Problem:
    return Problem(
        operation_types={0: 'hold', 1: 'weld', 2: 'locomote'},
        robot_types={'Arm': {0: Fraction(2), 1: Fraction(3), 2: Fraction(1)}},
        robots=tuple(Robot(name, 'Arm', start_location='p') for name in 'ABC'),
        jobs=(Job('J', 'p', ((0,),)), Job('P', 'p', ((1,),)), Job('W', 'p', ((0, 1),)),
              Job('F', 'q', ((1,),))),
        distances={('p', 'q'): Fraction(4), ('q', 'p'): Fraction(4)},
        precedence=(('J', 'W'), ('P', 'W'), ('W', 'F')),
        holding=(('J', 'W', 0),),
        locomote=2,
        name='small',
    )


def assign(job, start, end, robots) -> JobAssignment:
    return JobAssignment(job, 0, Fraction(start), Fraction(end), robots)


PLAN = Schedule(
    jobs={'J': assign('J', 0, 2, {'A': 0}), 'P': assign('P', 0, 3, {'B': 1}),
          'W': assign('W', 3, 6, {'A': 0, 'B': 1}), 'F': assign('F', 6, 9, {'C': 1})},
    sequences={'A': ('J', 'W'), 'B': ('P', 'W'), 'C': ('F',)},
)


@pytest.fixture(scope='module')
def small():
    return make_problem()


def at(problem, now, failed=(), schedule=PLAN):
    return simulated_state(problem, schedule, Fraction(now), failed=frozenset(failed))


def test_the_plan_is_valid_and_simulates_as_drawn(small):
    assert validate(small, PLAN) == []
    state = at(small, Fraction(5, 2))
    assert state.done == {'J'}
    assert set(state.running) == {'P'}
    assert state.robots['A'] == RobotSituation('A', True, 'p', Fraction(5, 2))
    assert state.robots['B'] == RobotSituation('B', True, 'p', Fraction(3))
    assert state.robots['C'] == RobotSituation('C', True, 'q', Fraction(4))


def test_failure_while_travelling_keeps_running_jobs(small):
    """C fails on its way to q at 1: J and P go on, F has to wait for A or B to come."""
    residual = residual_problem(small, at(small, 1, {'C'}), PLAN)
    p = residual.problem
    assert residual.failed == ['C']
    assert residual.aborted == residual.voided == residual.blocked == []
    assert [r.name for r in p.robots] == ['A', 'B']
    assert set(p.fixed) == {'J', 'P'}
    assert p.fixed['J'].robots == {'A': 0} and p.fixed['J'].end == 2
    assert p.robot('A').start_location == 'p'
    assert p.robot('B').release_time == 3
    assert set(p.precedence) == {('J', 'W'), ('P', 'W'), ('W', 'F')}


def test_failure_while_working_aborts_the_job(small):
    """B fails at 1 in P: P is redone, by C, the only robot not bound to hold for W."""
    residual = residual_problem(small, at(small, 1, {'B'}), PLAN)
    p = residual.problem
    assert residual.aborted == ['P']
    assert set(p.fixed) == {'J'}
    assert {j.name for j in p.jobs} == {'J', 'P', 'W', 'F'}
    assert p.robot('C') == Robot('C', 'Arm', Fraction(1), 'q', Fraction(4))
    assert ('J', 'W', 0) in p.holding


def test_failure_while_holding_voids_the_jig_job(small):
    """A fails at 5/2 while holding since J ended at 2: J is redone, and W after it."""
    residual = residual_problem(small, at(small, Fraction(5, 2), {'A'}), PLAN)
    p = residual.problem
    assert residual.voided == ['J']
    assert residual.aborted == [] and residual.kept == []
    assert p.fixed.keys() == {'P'}
    assert {j.name for j in p.jobs} == {'J', 'P', 'W', 'F'}
    assert ('J', 'W', 0) in p.holding


def test_holder_that_failed_and_came_back_voids_the_jig_job(small):
    """A failed at 9/4 while holding and was back by 5/2: what it held was let go, so J is
    redone as if A were still out, although A may redo it."""
    state = at(small, Fraction(5, 2))
    a = state.robots['A']
    back = replace(state, robots={**state.robots, 'A': replace(a, last_failure=Fraction(9, 4))})
    residual = residual_problem(small, back, PLAN)
    assert residual.voided == ['J'] and residual.kept == [] and residual.failed == []
    assert 'A' in {r.name for r in residual.problem.robots}


@pytest.mark.parametrize(('failed_at', 'started', 'voided'), [
    (Fraction(-1), {}, []),                      # before the planned start of J (0)
    (Fraction(0), {}, ['J']),                    # as J began
    (Fraction(1, 2), {}, ['J']),                 # after J's planned start...
    (Fraction(1, 2), {'J': Fraction(1)}, []),    # ...but before it actually began
])
def test_only_a_failure_since_the_jig_job_began_voids_it(small, failed_at, started, voided):
    state = at(small, Fraction(5, 2))
    robots = {**state.robots, 'A': replace(state.robots['A'], last_failure=failed_at)}
    done_as = {job: replace(PLAN.jobs[job], start=start) for job, start in started.items()}
    residual = residual_problem(small, replace(state, robots=robots, done_as=done_as), PLAN)
    assert residual.voided == voided


def test_a_hold_is_judged_by_who_did_the_jig_job_not_by_the_latest_plan(small):
    """W ran on J's hold under a plan that left the done J out; W's holder A then failed and W
    was aborted. Who held is what J's execution says: J is voided, not an error."""
    state = at(small, Fraction(4), {'A'})
    after_j = Schedule({'W': PLAN.jobs['W'], 'F': PLAN.jobs['F']},
                       {'A': ('W',), 'B': ('W',), 'C': ('F',)})
    aborted = replace(state, running={name: a for name, a in state.running.items()
                                      if name != 'W'})
    residual = residual_problem(small, aborted, after_j)
    assert residual.voided == ['J']
    with pytest.raises(ValueError, match='who holds it'):
        residual_problem(small, replace(aborted, done_as={}), after_j)


def test_healthy_holder_keeps_holding(small):
    """C fails at 5/2 while A holds since J: J stays, fixed with its holder only, so that the
    holding arc still sends A directly to W."""
    residual = residual_problem(small, at(small, Fraction(5, 2), {'C'}), PLAN)
    p = residual.problem
    assert residual.kept == ['J'] and residual.voided == []
    assert p.job('J').plans == ((0,),)
    assert p.fixed['J'].robots == {'A': 0}
    # The hold lasts until now, so W cannot start in the past.
    assert p.fixed['J'].start == 0 and p.fixed['J'].end == Fraction(5, 2)
    assert p.holding == (('J', 'W', 0),)


def test_aborted_held_job_keeps_its_holder(small):
    """B (welding W) fails at 4: W is redone, and A, still holding since J, must be in it."""
    residual = residual_problem(small, at(small, 4, {'B'}), PLAN)
    p = residual.problem
    assert residual.aborted == ['W'] and residual.kept == ['J']
    assert {j.name for j in p.jobs} == {'J', 'W', 'F'}
    assert p.fixed.keys() == {'J'}
    # P is done and gone, so is its arc; J's arc stays, harmless since J ended by now.
    assert set(p.precedence) == {('J', 'W'), ('W', 'F')}
    assert p.robot('A').release_time == 4 and p.robot('A').start_location == 'p'


def test_holder_known_from_the_running_held_job(small):
    """A plan made while W ran no longer has J, and J's execution is not given: when W is
    aborted, W's holder is J's."""
    later_plan = Schedule({name: a for name, a in PLAN.jobs.items() if name != 'J'},
                          {**PLAN.sequences, 'A': ('W',)})
    residual = residual_problem(small, replace(at(small, 4, {'B'}), done_as={}), later_plan)
    assert residual.kept == ['J']
    # J is known to have ended by W's start at 3, after A's hold of 2.
    assert residual.problem.fixed['J'] == FixedJob(0, Fraction(1), Fraction(4), {'A': 0})


def test_jig_job_holding_for_a_running_job_is_gone(small):
    """At 4, W runs on healthy A and B: the hold is inside W now, J is simply done."""
    residual = residual_problem(small, at(small, 4, {'C'}), PLAN)
    assert residual.kept == []
    assert {j.name for j in residual.problem.jobs} == {'W', 'F'}
    assert residual.problem.holding == ()


def test_late_running_job_ends_no_earlier_than_now(small):
    """P was expected to end at 3 but still runs at 7/2: nothing may follow it before 7/2."""
    state = replace(at(small, Fraction(5, 2), {'C'}), now=Fraction(7, 2))
    fixed = residual_problem(small, state, PLAN).problem.fixed['P']
    assert (fixed.start, fixed.end) == (0, Fraction(7, 2))


def test_failure_after_the_robots_last_job(small):
    """A fails at 7, after W: only F, running on C, remains."""
    residual = residual_problem(small, at(small, 7, {'A'}), PLAN)
    p = residual.problem
    assert [j.name for j in p.jobs] == ['F'] and p.fixed.keys() == {'F'}
    assert p.precedence == () and not residual.complete


def test_two_failures_block_with_the_reason(small):
    residual = residual_problem(small, at(small, 1, {'A', 'B'}), PLAN)
    assert residual.problem is None and not residual.complete
    assert residual.aborted == ['J', 'P']
    assert residual.blocked == [
        "job 'W' cannot be staffed: plan 0 ['hold' (0), 'weld' (1)] needs 2 distinct robots "
        "able to do ['hold' (0), 'weld' (1)]; 1 healthy can (failed: A, B)"]


def test_recovered_robot_unblocks(small):
    state = at(small, 1, {'A', 'B'})
    later = ExecutionState(Fraction(5), state.done, {}, {
        **state.robots,
        'B': RobotSituation('B', True, 'p', Fraction(5)),
        'C': RobotSituation('C', True, 'q', Fraction(5))})
    residual = residual_problem(small, later, PLAN)
    assert residual.blocked == []
    assert [r.name for r in residual.problem.robots] == ['B', 'C']
    assert residual.problem.fixed == {}


def test_everything_done_is_complete(small):
    residual = residual_problem(small, at(small, 9), PLAN)
    assert residual.complete and residual.problem is None


def test_kept_jig_job_needs_the_executed_schedule(small):
    with pytest.raises(ValueError, match="job 'J' is done and holds for 'W'"):
        residual_problem(small, replace(at(small, Fraction(5, 2), {'C'}), done_as={}))


def check_replan(problem, previous, state, **limits):
    """Re-plan, and check what every re-plan must satisfy whatever the solver's choices."""
    return check_replan_result(state, replan(problem, previous, state, **limits))


# (now, failed robots, hand-computed optimum of what remains, why)
HAND_CHECKED = [
    (1, {'C'}, 13, 'travelling: W [3, 6] by A and B, then one of them travels to q in 4, F 3'),
    (1, {'B'}, 21, 'working: A must hold from J into W, so C comes back (8) for P [8, 11], '
                   'W [11, 14], travels (18), F [18, 21]'),
    (Fraction(5, 2), {'A'}, 18, 'holding: B redoes J [3, 5] after P, C comes back (8) for W '
                                '[8, 11], travels (15), F [15, 18]'),
    (Fraction(5, 2), {'C'}, 13, 'a healthy holder: A goes on to W [3, 6] with B, then as '
                                'when travelling'),
    (4, {'B'}, 18, 'W aborted: A still holds, C comes back (8) for W [8, 11], F [15, 18]'),
    (7, {'A'}, 9, "after A's last job: F goes on as planned"),
]


@pytest.mark.parametrize(('now', 'failed', 'makespan', 'why'), HAND_CHECKED,
                         ids=[row[3].split(':')[0] for row in HAND_CHECKED])
def test_replan_finds_the_hand_computed_makespan(small, now, failed, makespan, why):
    result = check_replan(small, PLAN, at(small, now, failed), time_limit=5.0)
    assert result.result.makespan == makespan


def test_replan_sends_a_kept_holder_directly_to_the_held_job(small):
    result = check_replan(small, PLAN, at(small, Fraction(5, 2), {'C'}), time_limit=5.0)
    assert result.schedule.sequences['A'][:2] == ('J', 'W')
    assert result.schedule.jobs['W'].robots['A'] == 0


def test_replan_after_recovery(small):
    """B back at p at 5 with C at q: B does P [5, 8] and J [8, 10], holds in W [10, 13]
    with C (at p since 9); one travels (17), F [17, 20]."""
    state = at(small, 1, {'A', 'B'})
    assert replan(small, PLAN, state).residual.blocked
    later = ExecutionState(Fraction(5), state.done, {}, {
        **state.robots,
        'B': RobotSituation('B', True, 'p', Fraction(5)),
        'C': RobotSituation('C', True, 'q', Fraction(5))})
    assert check_replan(small, PLAN, later, time_limit=5.0).result.makespan == 20


def test_replan_when_everything_is_done(small):
    result = replan(small, PLAN, at(small, 10))
    assert result.residual.complete and result.result is None and result.schedule is None


def test_deadlocked_holds_are_given_up():
    """A holds from J1 for W1, B from J2 for W2, and D welds both; D fails at 3 in W1.
    Each held job now needs the other holder as welder: no schedule keeps both holds. Given
    up, A and B redo everything in turn from 3: J, W, J, W = 2 + 3 + 2 + 3, ending at 13."""
    problem = Problem(
        operation_types={0: 'hold', 1: 'weld'},
        robot_types={'Arm': {0: Fraction(2), 1: Fraction(3)}},
        robots=tuple(Robot(name, 'Arm') for name in 'ABD'),
        jobs=tuple(Job(name, 'p', (plan,)) for name, plan in (
            ('J1', (0,)), ('W1', (0, 1)), ('J2', (0,)), ('W2', (0, 1)))),
        precedence=(('J1', 'W1'), ('J2', 'W2')),
        holding=(('J1', 'W1', 0), ('J2', 'W2', 0)),
    )
    plan = Schedule(
        jobs={'J1': assign('J1', 0, 2, {'A': 0}), 'J2': assign('J2', 0, 2, {'B': 0}),
              'W1': assign('W1', 2, 5, {'A': 0, 'D': 1}),
              'W2': assign('W2', 5, 8, {'B': 0, 'D': 1})},
        sequences={'A': ('J1', 'W1'), 'B': ('J2', 'W2'), 'D': ('W1', 'W2')})
    assert validate(problem, plan) == []
    state = at(problem, 3, {'D'}, plan)
    assert residual_problem(problem, state, plan).kept == ['J1', 'J2']
    result = check_replan(problem, plan, state, time_limit=5.0)
    assert result.residual.released == result.residual.voided == ['J1', 'J2']
    assert result.residual.aborted == ['W1']
    assert result.result.makespan == 13


def carried():
    """A and B lift a part at p (2 units) and carry it, still holding, 4 units to q, to
    place it there (2 units) once D has scanned the spot (7 units); C, a spare drone at q,
    has nothing to do. Planned: Lift [0, 2], the leg [2, 6], holding at q until Scan ends,
    Place [7, 9]."""
    problem = Problem(
        operation_types={0: 'lift', 1: 'scan', 2: 'drive'},
        robot_types={'Rover': {0: Fraction(2), 2: Fraction(1)},
                     'Drone': {1: Fraction(7), 2: Fraction(1)}},
        robots=(Robot('A', 'Rover', start_location='p'), Robot('B', 'Rover', start_location='p'),
                Robot('C', 'Drone', start_location='q'), Robot('D', 'Drone', start_location='q')),
        jobs=(Job('Lift', 'p', ((0, 0),)), Job('Place', 'q', ((0, 0),)),
              Job('Scan', 'q', ((1,),))),
        distances={('p', 'q'): Fraction(4), ('q', 'p'): Fraction(4)},
        precedence=(('Lift', 'Place'), ('Scan', 'Place')),
        holding=(('Lift', 'Place', 0),),
        locomote=2,
        name='carried',
    )
    plan = Schedule(
        jobs={'Lift': JobAssignment('Lift', 0, Fraction(0), Fraction(2), {'A': 0, 'B': 0}),
              'Place': JobAssignment('Place', 0, Fraction(7), Fraction(9), {'A': 0, 'B': 0}),
              'Scan': assign('Scan', 0, 7, {'D': 1})},
        sequences={'A': ('Lift', 'Place'), 'B': ('Lift', 'Place'), 'C': (), 'D': ('Scan',)})
    assert validate(problem, plan) == []
    return problem, plan


@pytest.mark.parametrize('now', [1, 4, Fraction(13, 2)],
                         ids=['lifting', 'carrying', 'holding at q'])
def test_holders_carrying_a_part_are_replanned_from_where_they_are(now):
    """C fails at `now`, which nothing needs: the re-plan has the holders go on from where
    they are, so Place still starts at 7 once Scan is done, not a whole leg after `now`."""
    problem, plan = carried()
    result = check_replan(problem, plan, at(problem, now, {'C'}, plan), time_limit=5.0)
    assert result.schedule.jobs['Place'].start == 7
    assert result.result.makespan == 9


def crossroads() -> Problem:
    """Places a, b, c: b is 10 from a and from c, c is 2 from a. R (speed 1, travel =
    distance) starts at a; X is at b, Y at c, each takes 1."""
    distances = {('a', 'b'): 10, ('a', 'c'): 2, ('b', 'c'): 10}
    return Problem(
        operation_types={0: 'grip', 1: 'locomote'},
        robot_types={'Rover': {0: Fraction(1), 1: Fraction(1)}},
        robots=(Robot('R', 'Rover', start_location='a'),),
        jobs=(Job('X', 'b', ((0,),)), Job('Y', 'c', ((0,),))),
        distances={**{k: Fraction(v) for k, v in distances.items()},
                   **{(b, a): Fraction(v) for (a, b), v in distances.items()}},
        locomote=1, name='crossroads')


def test_a_robot_on_a_leg_is_replanned_from_the_point_it_reached():
    """R left a at 0 for X at b (arrival 10) and is a fifth of the way at 2. From there, c
    is 4 away (back through a: 2 + 2; on through b: 8 + 10), b is 8: Y at c [6, 7], then X
    at b [17, 18], makespan 18. Planned from b, where the leg ends, it would be X [10, 11],
    Y [21, 22]: 22."""
    problem = crossroads()
    way = Waypoint('a', 'b', Fraction(1, 5))
    state = ExecutionState(Fraction(2), frozenset(), {}, {
        'R': RobotSituation('R', True, 'b', Fraction(10), on_way=way)})
    result = check_replan_result(state, replan(problem, PLAN_XY, state, time_limit=5.0))
    posed = result.residual.problem
    assert (posed.robot('R').start_location, posed.robot('R').release_time) == ('a->b@0.20', 2)
    assert (posed.distance('a->b@0.20', 'c'), posed.distance('a->b@0.20', 'b')) == (4, 8)
    assert result.schedule.sequences['R'] == ('Y', 'X')
    assert result.result.makespan == 18
    # Without the point reached, the same state is planned from the end of the leg.
    at_b = ExecutionState(Fraction(2), frozenset(), {}, {
        'R': RobotSituation('R', True, 'b', Fraction(10))})
    assert replan(problem, PLAN_XY, at_b, time_limit=5.0).result.makespan == 22


PLAN_XY = Schedule(jobs={'X': assign('X', 10, 11, {'R': 0}), 'Y': assign('Y', 21, 22, {'R': 0})},
                   sequences={'R': ('X', 'Y')})


def test_a_slow_leg_releases_the_robot_no_earlier_than_its_reported_arrival_allows():
    """R reports arriving at b at 14, not 10: from its point a fifth of the way, 8 from b,
    it is free to turn at 6, not at 2."""
    problem = crossroads()
    state = ExecutionState(Fraction(2), frozenset(), {}, {
        'R': RobotSituation('R', True, 'b', Fraction(14),
                            on_way=Waypoint('a', 'b', Fraction(1, 5)))})
    posed = residual_problem(problem, state, PLAN_XY).problem
    assert posed.robot('R').release_time == 6


def test_a_robot_not_yet_released_stays_unreleased_on_its_leg():
    """R is released at 10 at a; at 3 it stands at the start of its first leg, toward X at b
    (10 away), which the tracker reckons it could end at 13. It still cannot leave before
    10. Found by a generated fleet whose robot failed and recovered before its release: the
    re-plan let it leave at once, and its first job started before it could have arrived."""
    problem = crossroads()
    problem = replace(problem, robots=(replace(problem.robot('R'), release_time=Fraction(10)),))
    state = ExecutionState(Fraction(3), frozenset(), {}, {
        'R': RobotSituation('R', True, 'b', Fraction(13), on_way=Waypoint('a', 'b', Fraction(0)))})
    posed = residual_problem(problem, state, PLAN_XY).problem
    assert (posed.robot('R').start_location, posed.robot('R').release_time) == ('a', 10)


@pytest.fixture(scope='module')
def paper():
    problem = load_scenario(PAPER)
    result = solve(problem, time_limit=30.0)
    assert result.makespan == 32
    return problem, result.schedule


def test_paper_failure_after_a_robots_last_job_keeps_the_optimum(paper):
    """The rest of the optimal plan still works without that robot, and nothing shorter
    exists: with the part already executed it would beat the optimum 32."""
    problem, plan = paper
    last = {r: plan.jobs[seq[-1]].end for r, seq in plan.sequences.items() if seq}
    robot = min(last, key=last.get)
    now = last[robot] + Fraction(1, 2)
    assert now < 32
    result = check_replan(problem, plan, simulated_state(problem, plan, now, {robot}))
    assert result.result.makespan == 32


@pytest.mark.parametrize(('now', 'robot'), [
    (Fraction(1, 2), 'Assembler'), (3, 'MARC1'), (9, 'MARC2'), (Fraction(29, 2), 'LSMS'),
    (20, 'Assembler'), (Fraction(243, 10), 'MARC1'), (28, 'MARC1')])
def test_paper_single_failures_give_valid_replans(paper, now, robot):
    """Whatever the plan, its executed part plus the re-plan is a schedule of the paper's
    instance, so it cannot beat 32."""
    problem, plan = paper
    state = simulated_state(problem, plan, Fraction(now), {robot})
    result = check_replan(problem, plan, state)
    assert result.result.makespan >= 32


def test_paper_two_failures_block_then_recovery_unblocks(paper):
    problem, plan = paper
    state = simulated_state(problem, plan, Fraction(1), {'MARC1', 'MARC2'})
    result = replan(problem, plan, state)
    assert result.result is None
    needs = "['hold frame link' (0) x2, 'weld connection point' (2)]"
    assert result.residual.blocked == [
        f"job '{job}' cannot be staffed: plan 0 {needs} needs 3 distinct robots able to "
        f'do {needs}; 2 healthy can (failed: MARC1, MARC2)' for job in ('Aa', 'Ab')]
    marc1 = state.robots['MARC1']
    back = replace(state, robots={**state.robots, 'MARC1': replace(marc1, healthy=True)})
    check_replan(problem, plan, back)


def _with_robot(state, robot_state):
    return replace(state, robots={**state.robots, robot_state.name: robot_state})


BAD_STATES = [
    ('done names an unknown job', lambda s: replace(s, done=frozenset({'J', 'X'})),
     "done job 'X' is not a job"),
    ('running names an unknown job',
     lambda s: replace(s, running={'X': assign('X', 0, 3, {'B': 1})}),
     "running job 'X' is not a job"),
    ('a job both done and running', lambda s: replace(s, done=frozenset({'J', 'P'})),
     "job 'P' is both done and running"),
    ('a running job with an unknown robot',
     lambda s: replace(s, running={'P': assign('P', 0, 3, {'Z': 1})}),
     "running job 'P' names unknown robot 'Z'"),
    ('robots that do not match the plan',
     lambda s: replace(s, running={'P': assign('P', 0, 3, {'B': 0})}),
     r"running job 'P': robots do \[0\], but plan 0 is \[1\]"),
    ('a state for an unknown robot',
     lambda s: _with_robot(s, RobotSituation('Z', True, None, Fraction(0))),
     "robot state for unknown robot 'Z'"),
    ('a robot without a state',
     lambda s: replace(s, robots={k: v for k, v in s.robots.items() if k != 'C'}),
     "no state for robot 'C'"),
    ('a holder at work elsewhere',
     lambda s: replace(s, running={'P': assign('P', 0, 3, {'A': 1})}),
     "robot 'A' is running 'P' while it should still hold since 'J'"),
    ('an unknown location',
     lambda s: _with_robot(s, RobotSituation('C', True, 'moon', Fraction(4))),
     "robot 'C' is at unknown location 'moon'"),
]


@pytest.mark.parametrize(('why', 'change', 'message'), BAD_STATES,
                         ids=[row[0] for row in BAD_STATES])
def test_bad_state_is_named(small, why, change, message):
    with pytest.raises(StateError, match=message):
        residual_problem(small, change(at(small, Fraction(5, 2))), PLAN)


@pytest.mark.parametrize(('now', 'failed', 'makespan', 'why'), HAND_CHECKED,
                         ids=[row[3].split(':')[0] for row in HAND_CHECKED])
def test_repair_then_improve_reaches_the_hand_computed_makespan(small, now, failed, makespan,
                                                                 why):
    """Anytime re-planning: `repair` publishes a valid plan without search, `improve` then
    reaches the optimum and says whether it is worth a new revision."""
    state = at(small, now, failed)
    repaired = repair(small, PLAN, state)
    assert repaired.problems == []
    assert repaired.schedule.makespan >= makespan
    better = improve(repaired, time_limit=5.0)
    assert better.replan.problems == []
    assert validate(better.replan.residual.problem, better.replan.schedule) == []
    assert better.replan.schedule.makespan == makespan
    assert better.improved == (makespan < repaired.schedule.makespan * Fraction(98, 100))


def test_improve_keeps_the_published_plan_for_a_small_gain(small):
    """A margin of 100 % can never be beaten: the published plan stays, unchanged."""
    repaired = repair(small, PLAN, at(small, 1, {'B'}))
    kept = improve(repaired, time_limit=2.0, margin=1.0)
    assert not kept.improved
    assert kept.replan.schedule == repaired.schedule


def test_repair_keeps_the_previous_plan_when_it_still_works(paper):
    """A robot failing after its last job leaves the rest of the optimal plan valid."""
    problem, plan = paper
    last = {r: plan.jobs[seq[-1]].end for r, seq in plan.sequences.items() if seq}
    robot = min(last, key=last.get)
    repaired = repair(problem, plan, simulated_state(problem, plan, last[robot] + 1, {robot}))
    assert repaired.problems == []
    assert repaired.schedule.makespan == 32


@pytest.fixture(scope='module')
def repaired_paper(paper):
    """The paper's optimal plan repaired after MARC1 fails at 3, and when a search started
    then would reach the robots (6 later)."""
    problem, plan = paper
    now = Fraction(3)
    repaired = repair(problem, plan, simulated_state(problem, plan, now, {'MARC1'}))
    assert repaired.problems == []
    return repaired, now + 6


def test_frozen_keeps_what_the_robots_do_until_a_new_plan_reaches_them(repaired_paper):
    repaired, until = repaired_paper
    schedule = repaired.schedule
    posed = frozen(repaired.residual, schedule, until).problem
    begun = {name for name, a in schedule.jobs.items() if a.start < until}
    assert begun and begun <= set(posed.fixed)
    assert set(posed.fixed) < set(schedule.jobs), 'everything frozen: nothing to search'
    for name, kept in posed.fixed.items():
        a = schedule.jobs[name]
        assert (kept.plan, kept.start, kept.end, dict(kept.robots)) == (
            a.plan, a.start, a.end, dict(a.robots))
    for sequence in schedule.sequences.values():
        # A robot's kept jobs come first: nothing new can be planned before them.
        flags = [name in posed.fixed for name in sequence]
        assert flags == sorted(flags, reverse=True)
    for robot in posed.robots:
        assert robot.release_time >= until
        for visit in schedule.visits(posed, robot.name):
            if visit.travel_start < until:  # on its way there when the plan arrives
                assert visit.job in posed.fixed
        # A kept job the robot has not reached yet keeps its leg: the agent travels it.
        legs = [v.arrival - v.travel_start for v in schedule.visits(posed, robot.name)]
        assert legs == [v.arrival - v.travel_start for v in schedule.visits(
            repaired.residual.problem, robot.name)]
    assert validate(posed, schedule) == []


def test_frozen_keeps_the_jobs_robots_started_ahead_of_the_plan(repaired_paper):
    """Robots start a job as soon as its robots and predecessors are ready, which can be
    before the plan's time: what they started stays as it is, with what comes before it."""
    repaired, until = repaired_paper
    schedule = repaired.schedule
    by_time = frozen(repaired.residual, schedule, until).problem
    ahead = min((name for name in schedule.jobs if name not in by_time.fixed),
                key=lambda name: schedule.jobs[name].start)
    posed = frozen(repaired.residual, schedule, until, started={ahead}).problem
    assert set(by_time.fixed) | {ahead} <= set(posed.fixed)
    for robot in schedule.jobs[ahead].robots:
        sequence = schedule.sequences[robot]
        assert set(sequence[:sequence.index(ahead)]) <= set(posed.fixed)
    assert validate(posed, schedule) == []


def test_improve_from_a_frozen_plan_starts_nothing_new_before_it_reaches_the_robots(
        repaired_paper):
    """The better plan keeps the jobs the robots do meanwhile as they are, so the planner
    can publish it after they moved on; with the part executed before the failure it is a
    schedule of the paper's instance, so it cannot beat 32."""
    repaired, until = repaired_paper
    better = improve(repaired, time_limit=3.0, margin=0, frozen_until=until)
    posed, schedule = better.replan.residual.problem, better.replan.schedule
    assert validate(posed, schedule) == []
    for name, a in repaired.schedule.jobs.items():
        if name in posed.fixed:
            assert schedule.jobs[name] == a
        else:
            assert schedule.jobs[name].start >= until
    assert 32 <= schedule.makespan <= repaired.schedule.makespan


def test_a_kept_jig_job_keeps_the_index_of_the_plan_it_ran():
    """J ran its second plan (A holds alone) when C fails: the kept J is pinned under that
    plan's index, as the published plan and the robots name it, not under a new one."""
    problem = replace(make_problem(), jobs=(Job('J', 'p', ((0, 0), (0,))),
                                            *make_problem().jobs[1:]))
    plan = replace(PLAN, jobs={**PLAN.jobs, 'J': replace(PLAN.jobs['J'], plan=1)})
    residual = residual_problem(problem, at(problem, Fraction(5, 2), {'C'}, plan), plan)
    p = residual.problem
    assert residual.kept == ['J']
    assert p.fixed['J'].plan == 1 and p.job('J').plans[1] == (0,)
    outcome = replan(problem, plan, at(problem, Fraction(5, 2), {'C'}, plan), time_limit=2)
    assert outcome.schedule.jobs['J'].plan == 1
    assert validate(outcome.residual.problem, outcome.schedule) == []
