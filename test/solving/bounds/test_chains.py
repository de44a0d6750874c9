"""The chain bound (`bounds.chains`), by hand on small cases; against optima proven
independently: `test_known_optima.py`."""

import dataclasses
from fractions import Fraction

from fjsp_planner.model.problem import Job, Problem, Robot
from fjsp_planner.solving.bounds import chains
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.chains import chain_bound
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.solve import solve


def sites(robots, jobs, precedence, distances) -> Problem:
    """Welding (operation 1) and moving (operation 2, 1 per unit of distance); a fast welder
    (1) and a slow one (13/2)."""
    table = {}
    for x, y, d in distances:
        table[x, y] = table[y, x] = Fraction(d)
    return Problem(operation_types={1: 'weld', 2: 'move'},
                   robot_types={'Fast': {1: Fraction(1), 2: Fraction(1)},
                                'Slow': {1: Fraction(13, 2), 2: Fraction(1)}},
                   robots=tuple(robots), jobs=tuple(Job(n, at, ((1,),)) for n, at in jobs),
                   precedence=tuple(precedence), distances=table, locomote=2)


def fast_or_near():
    """x at a, then y at b, 5 away. F at a welds x (0-1): it crosses to weld y (6-7), or S
    at b welds y from 1 to 15/2. The optimum is 7."""
    return sites([Robot('F', 'Fast', start_location='a'),
                  Robot('S', 'Slow', start_location='b')],
                 [('x', 'a'), ('y', 'b')], [('x', 'y')], [('a', 'b', 5)])


def test_a_chain_is_slow_unless_its_fast_robot_travels():
    """The chain bound weighs crossing against the slow welder: 7, the optimum. The fleet
    load bound, blind to the order, lets F weld x and S weld y side by side (13/2); the
    critical path takes both welds at their fastest."""
    problem = fast_or_near()
    assert chain_bound(problem, 5) == 7 == solve(problem).makespan
    assert fleet_load_bound(problem, 5) == Fraction(13, 2)
    assert static_bound(problem) < 7


def test_a_robot_between_two_chain_jobs_goes_the_least_way_along_the_table(monkeypatch):
    """a to b is 20 direct, 10 through c, where z (outside the chain) waits: F welds x, z
    on its way and y by 13. Taking the direct leg, the chain x -> y alone would be
    1 + 20 + 1; the least way gives 12, below the optimum."""
    monkeypatch.setattr(chains, 'PAIRED_CHAINS', 0)
    problem = sites([Robot('F', 'Fast', start_location='a')],
                    [('x', 'a'), ('y', 'b'), ('z', 'c')], [('x', 'y')],
                    [('a', 'b', 20), ('a', 'c', 5), ('c', 'b', 5)])
    assert solve(problem).makespan == 13
    assert chain_bound(problem, 5) == 12


def test_two_chains_together_share_their_fast_robot(monkeypatch):
    """Two chains x1 -> y1 and x2 -> y2 from a to b: each alone takes 7 (F crosses), but F
    cannot cross for both at once: F welds x1, x2, crosses and welds y2 by 8 while S welds
    y1 from 1 to 15/2; the optimum is 8, which the two chains taken together prove."""
    problem = sites([Robot('F', 'Fast', start_location='a'),
                     Robot('S', 'Slow', start_location='b')],
                    [('x1', 'a'), ('y1', 'b'), ('x2', 'a'), ('y2', 'b')],
                    [('x1', 'y1'), ('x2', 'y2')], [('a', 'b', 5)])
    assert chain_bound(problem, 5) == 8 == solve(problem).makespan
    monkeypatch.setattr(chains, 'PAIRED_CHAINS', 0)
    assert chain_bound(problem, 5) == 7


def test_no_precedence_gets_none():
    """(Running jobs get no bound from any set of jobs: `test_operations.py`.)"""
    assert chain_bound(dataclasses.replace(fast_or_near(), precedence=()), 5) is None
