"""The MIP beside CP-SAT on small random instances (`solver_instances.random_problem`): both
prove the same optimum on each of 20 seeds (the table of `known_optima`, proven again by the
slow test of `test_known_optima.py`); here, the MIP's backends agree and the instances cover
the features the comparison is meant to exercise.
"""

import pytest

from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.mip import solve_mip

from solver_instances import LOCATIONS, random_problem

SEEDS = range(20)


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
