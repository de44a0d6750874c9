"""Jobs added to a running mission, given as a scenario fragment.

A fragment has the scenario format's `jobs` and, as needed, `locations` (coordinates of its
new locations), `distances` (between its new locations and any of the mission's),
`precedence` and `holding` arcs (among its jobs, or from
and to the mission's). It is checked by building the whole extended scenario, so every rule
of a scenario applies (unknown names, missing distances, cycles, unstaffable jobs) and every
problem is reported at once. An arc into a job that has already started cannot hold any more,
so such arcs are refused too.
"""

from collections.abc import Collection

from fjsp_planner.model.limits import load_yaml, shown
from fjsp_planner.model.problem import Problem, ProblemError
from fjsp_planner.model.scenario import parse_scenario, problem_mapping

SECTIONS = ('jobs', 'locations', 'distances', 'precedence', 'holding')


def extend(problem: Problem, fragment: str, started: Collection[str] = ()
           ) -> tuple[Problem, tuple[str, ...]]:
    """`problem` with the fragment's jobs, and their names; ProblemError lists every reason
    the fragment cannot be added. `started` names the jobs that have started or are done."""
    try:
        data = load_yaml(fragment)
    except ProblemError as error:
        raise ProblemError([f'fragment: {p}' for p in error.problems]) from None
    if not isinstance(data, dict):
        raise ProblemError(['fragment: must be a mapping with a `jobs` section'])
    problems = [f"fragment: unknown section '{key}' (a fragment has {', '.join(SECTIONS)})"
                for key in data if key not in SECTIONS]
    jobs = data.get('jobs')
    if not isinstance(jobs, list) or not jobs:
        problems.append('fragment: `jobs` must list at least one job')
        jobs = []
    added = tuple(str(entry['name']) for entry in jobs
                  if isinstance(entry, dict) and 'name' in entry)
    existing = {j.name for j in problem.jobs}
    for key in ('precedence', 'holding'):
        arcs = data.get(key) or []
        for arc in arcs if isinstance(arcs, list) else ():
            if isinstance(arc, list) and len(arc) >= 2 and str(arc[1]) in existing \
                    and str(arc[1]) in started:
                problems.append(f'{key} arc {shown(arc)}: job {str(arc[1])!r} has already started')
            if key == 'holding' and isinstance(arc, list) and len(arc) >= 2 \
                    and str(arc[0]) in existing and str(arc[0]) in started:
                problems.append(f'holding arc {shown(arc)}: job {str(arc[0])!r} has already '
                                'started, so its robots cannot be told to hold')
    merged = problem_mapping(problem)
    merged['jobs'] = merged['jobs'] + jobs
    section = data.get('distances') or {}
    if isinstance(section, dict):
        merged['distances'] = {**section, 'pairs': merged['distances']['pairs']
                               + list(section.get('pairs') or [])}
    else:
        problems.append("fragment: 'distances' must be a mapping with 'table' and/or 'pairs'")
    places = data.get('locations') or {}
    if isinstance(places, dict):
        problems += [f"fragment: location '{name}' is on the map already"
                     for name in places if str(name) in problem.coordinates]
        merged['locations'] = {**merged.get('locations', {}), **places}
    else:
        problems.append("fragment: 'locations' must be a mapping of location -> [x, y] or "
                        '[x, y, z]')
    for key in ('precedence', 'holding'):
        if data.get(key) is not None:
            merged[key] = merged[key] + (data[key] if isinstance(data[key], list)
                                         else [data[key]])
    try:
        extended = parse_scenario(merged, problem.name)
    except ProblemError as error:
        problems += error.problems
    if problems:
        raise ProblemError(problems)
    return extended, added
