"""The table of known optima (`known_optima`): every bound stays at or below each entry,
checked without solving, and one slow test proves the entries again with each of their
provers (the costly ones one a run, in turn). Also: the scenarios shipped in config/scenarios/
besides the paper's carry the features the integration tests rely on."""

import os
from fractions import Fraction

import pytest

from fjsp_planner.model.scenario import load_scenario
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.bounds import panel
from fjsp_planner.solving.bounds.assignment import fleet_load_bound
from fjsp_planner.solving.bounds.chains import chain_bound
from fjsp_planner.solving.bounds.fleet import static_bound
from fjsp_planner.solving.bounds.load import panel_load_bound
from fjsp_planner.solving.bounds.machine import panel_machine_bound
from fjsp_planner.solving.bounds.operations import operation_bound
from fjsp_planner.solving.bounds.sequence import panel_sequence_bound
from fjsp_planner.solving.solve import solve

import generated_seeds
from known_optima import KNOWN
from repo_paths import SCENARIOS

REPROVE_ALL = 'FJSP_REPROVE_ALL'
"""Set (to anything) to re-prove every costly entry too, not only this run's turn."""

PATIENCE = 4
"""The re-proof waits this many times an entry's limit: a proof ends the solve at once, and
the suite runs it beside fleets of other tests on 2 cores."""


def reproofs():
    """Every entry; of the costly ones, all but this run's turn (picked by the run's seed)
    skipped unless REPROVE_ALL is set: each takes most of a minute."""
    costly = sorted(name for name, entry in KNOWN.items() if entry.costly)
    turn = costly[generated_seeds.base() % len(costly)]
    for name, entry in KNOWN.items():
        skipped = entry.costly and name != turn and not os.environ.get(REPROVE_ALL)
        yield pytest.param(name, marks=[pytest.mark.skip(
            reason=f"costly: re-proved in turn, '{turn}' this run; {REPROVE_ALL}=1 "
                   'proves every entry')] if skipped else [])


@pytest.mark.slow
@pytest.mark.parametrize('name', list(reproofs()))
def test_every_known_optimum_is_proven_again_by_each_of_its_provers(name):
    """The MIP has none of the CP-SAT cuts: where both prove the entry, no cut removed an
    optimal schedule."""
    entry = KNOWN[name]
    problem = entry.problem()
    for prover in entry.provers:
        if prover == 'mip':
            result = solve(problem, solver='mip', mip_backend='SCIP',
                           time_limit=PATIENCE * entry.time_limit, workers=1)
        else:
            result = solve(problem, time_limit=PATIENCE * entry.time_limit, workers=2)
        assert result.status == Status.OPTIMAL, (prover, result)
        assert result.makespan == result.lower_bound == entry.optimum, prover
        assert validate(problem, result.schedule) == [], prover


SEARCHED_PANELS = 3
"""From this many panels the panel bounds search for seconds: those entries' checks are slow."""


def bound_checks():
    for name, entry in KNOWN.items():
        slow = len(entry.problem().panels) >= SEARCHED_PANELS
        yield pytest.param(name, marks=[pytest.mark.slow] if slow else [])


@pytest.mark.parametrize('name', list(bound_checks()))
def test_every_bound_stays_at_or_below_the_known_optimum(name):
    """The static, fleet load (with chained ways), chain and operation set bounds on every
    entry; on panels, the panel bounds too, given a schedule just above the optimum (as the
    search would report one)."""
    entry = KNOWN[name]
    problem = entry.problem()
    assert static_bound(problem) <= entry.optimum
    load = fleet_load_bound(problem, 10, chains=True)
    assert load is None or load <= entry.optimum, 'fleet load'
    chains = chain_bound(problem, 10)
    assert chains is None or chains <= entry.optimum, 'chains'
    operations = operation_bound(problem, 10)
    assert operations is None or operations <= entry.optimum, 'operation sets'
    if not problem.panels:
        return
    incumbent = entry.optimum + 1
    for bound, found in [
            ('machine', panel_machine_bound(problem, incumbent, 30)),
            ('load', panel_load_bound(problem, incumbent, 30)),
            ('sequence', panel_sequence_bound(problem, incumbent, 30)),
            ('energy', panel.panel_energy_bound(problem, incumbent)),
            ('clique', panel.panel_clique_bound(problem, incumbent))]:
        assert found is None or found <= entry.optimum, bound


def test_the_shipped_scenarios_carry_start_locations_releases_plans_and_holding():
    for scenario in ('truss', 'antenna', 'habitat'):
        problem = load_scenario(SCENARIOS / f'{scenario}.yaml')
        assert any(r.start_location for r in problem.robots), scenario
        assert any(r.release_time > 0 for r in problem.robots), scenario
        assert any(len(j.plans) > 1 for j in problem.jobs) and problem.holding, scenario


def test_the_yard_map_is_planned_to_its_optimum_on_the_solver_grid():
    """Its distances from coordinates are millionths, so CP-SAT rounds travel up onto its
    1/1000 grid: it proves 46.175 optimal there, which bounds the exact optimum above."""
    problem = load_scenario(SCENARIOS / 'yard.yaml')
    result = solve(problem, time_limit=60, workers=2)
    assert validate(problem, result.schedule) == []
    assert result.makespan <= Fraction('46.175'), result


def test_a_shipped_scenario_carries_a_held_part_between_two_places():
    problem = load_scenario(SCENARIOS / 'habitat.yaml')
    assert any(problem.job(a).location != problem.job(b).location
               for a, b, _ in problem.holding)
    assert problem.operation_types[problem.locomote] != 'locomote'
