"""The PyJobShop peer's mapping of our scenarios (built without PyJobShop itself, which only
the benches install): every holding arc becomes a mode dependency PyJobShop accepts."""

import importlib.util

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.scenario import parse_scenario

from repo_paths import REPO

_spec = importlib.util.spec_from_file_location('pyjobshop_peer',
                                               REPO / 'bench' / 'pyjobshop_peer.py')
peer = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(peer)


def test_a_holder_staffing_no_held_staffing_matches_is_left_out():
    """Generated seed 10 (12 jobs, 3 robots) holds from Haul-8 into Join-11 with operation 0:
    some staffings of Haul-8 give operation 0 to robots that staff no way of doing Join-11.
    PyJobShop refuses a mode dependency on no modes, so those staffings must go; every other
    one stays, and each staffing kept has a match."""
    problem = parse_scenario(random_scenario(10, Shape(jobs=12)))
    assert any((a, b) == ('Haul-8', 'Join-11') for a, b, _ in problem.holding)
    every = {job.name: [s for plan in job.plans for s in peer._staffings(problem, plan)]
             for job in problem.jobs}
    kept = peer._held_staffings(problem)
    for a, b, q in problem.holding:
        held = {peer._holders(s, q) for s in kept[b]}
        assert kept[a] and all(peer._holders(s, q) in held for s in kept[a])
        assert kept[a] == [s for s in every[a]
                           if peer._holders(s, q) in {peer._holders(t, q) for t in every[b]}]
    assert len(kept['Haul-8']) < len(every['Haul-8'])
    held_jobs = {name for arc in problem.holding for name in arc[:1]}
    assert all(kept[name] == every[name] for name in every if name not in held_jobs)
