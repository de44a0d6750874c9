"""Small problems whose optima are proven independently (`known_optima`), built here once
for the bound tests, the MIP comparison and the slow test that re-proves the table."""

import dataclasses
import random
from fractions import Fraction

from fjsp_planner.model.problem import FixedJob, Job, Problem, ProblemError, Robot
from fjsp_planner.model.scenario import repeat_panels


def tiny(panels: int) -> Problem:
    """Per panel (repeated 1 apart): x at a, then y at b needs [hold, weld], then z at b
    [weld]. S holds in 1, welds in 4 and travels 100 per unit of distance, so crossing to
    another panel costs it 100: in any schedule shorter than 100 it stays in one panel. The
    arms A1, A2 hold in 3, weld in 1, travel 1 per unit."""
    base = Problem(
        operation_types={0: 'hold', 1: 'weld', 2: 'move'},
        robot_types={'Slow': {0: Fraction(1), 1: Fraction(4), 2: Fraction(100)},
                     'Arm': {0: Fraction(3), 1: Fraction(1), 2: Fraction(1)}},
        robots=(Robot('S', 'Slow'), Robot('A1', 'Arm'), Robot('A2', 'Arm')),
        jobs=(Job('x', 'a', ((0,),)), Job('y', 'b', ((0, 1),)), Job('z', 'b', ((1,),))),
        distances={('a', 'b'): Fraction(2), ('b', 'a'): Fraction(2)},
        precedence=(('x', 'y'), ('y', 'z')), locomote=2, name='tiny')
    return repeat_panels(base, panels, 1)


def detour(panels: int) -> Problem:
    """One robot A, jobs x at a, y at b, z at c (1 each), x before z; a and c are 10 apart,
    but 1 each from b: the distance table breaks the triangle inequality, as the paper's
    does."""
    base = Problem(
        operation_types={0: 'work', 1: 'move'},
        robot_types={'Arm': {0: Fraction(1), 1: Fraction(1)}},
        robots=(Robot('A', 'Arm'),),
        jobs=(Job('x', 'a', ((0,),)), Job('y', 'b', ((0,),)), Job('z', 'c', ((0,),))),
        distances={('a', 'b'): Fraction(1), ('b', 'a'): Fraction(1), ('b', 'c'): Fraction(1),
                   ('c', 'b'): Fraction(1), ('a', 'c'): Fraction(10), ('c', 'a'): Fraction(10)},
        precedence=(('x', 'z'),), locomote=1, name='detour')
    return repeat_panels(base, panels, 1)


def random_panel(seed: int) -> Problem:
    """One panel of three jobs at two places for a slow crosser S (200 per unit of
    distance) and two arms, plans of one to three operations, a precedence chain with gaps,
    sometimes a holding arc."""
    rng = random.Random(seed)
    types = {'Slow': {0: Fraction(1), 1: Fraction(rng.randint(2, 5)), 2: Fraction(200)},
             'Arm': {0: Fraction(rng.randint(2, 4)), 1: Fraction(1), 2: Fraction(1)}}
    robots = (Robot('S', 'Slow'), Robot('A1', 'Arm'),
              Robot('A2', 'Arm', Fraction(rng.choice([1, 2]))))
    plans = [((0,),), ((0, 1),), ((0, 0, 1),), ((1,),), ((0, 1), (0, 0))]
    jobs = tuple(Job(f'j{i}', rng.choice('ab'), rng.choice(plans)) for i in range(3))
    precedence = tuple((f'j{i}', f'j{i + 1}') for i in range(2) if rng.random() < 0.8)
    distance = Fraction(rng.randint(1, 3))
    holding = ()
    if ('j0', 'j1') in precedence and all(
            0 in p for p in jobs[0].plans + jobs[1].plans) and rng.random() < 0.6:
        holding = (('j0', 'j1', 0),)
    return Problem(operation_types={0: 'hold', 1: 'weld', 2: 'move'}, robot_types=types,
                   robots=robots, jobs=jobs,
                   distances={('a', 'b'): distance, ('b', 'a'): distance},
                   precedence=precedence, holding=holding, locomote=2, name=f'random {seed}')


def places_panel(seed: int) -> Problem:
    """One panel of four jobs at three places a, b, c, some at distance 0 of each other
    (one place for the load bound), for a crosser S that is slow or not, and two arms (one
    slower, maybe released later); plans of one or two operations, moves among them."""
    rng = random.Random(seed)
    types = {'Slow': {0: Fraction(1), 1: Fraction(rng.randint(2, 5)),
                      2: Fraction(rng.choice([1, 30]))},
             'Arm': {0: Fraction(rng.randint(2, 4)), 1: Fraction(1), 2: Fraction(1)}}
    robots = (Robot('S', 'Slow'), Robot('A1', 'Arm'),
              Robot('A2', 'Arm', Fraction(rng.choice([1, 2])),
                    release_time=Fraction(rng.choice([0, 0, 1]))))
    plans = [((0,),), ((0, 1),), ((1,),), ((0, 1), (0, 0)), ((2,),)]
    jobs = tuple(Job(f'j{i}', rng.choice('abc'), rng.choice(plans)) for i in range(4))
    precedence = tuple((f'j{i}', f'j{i + 1}') for i in range(3) if rng.random() < 0.6)
    distances = {}
    for a, b in (('a', 'b'), ('a', 'c'), ('b', 'c')):
        distances[a, b] = distances[b, a] = Fraction(rng.choice([0, 1, 2, 4]))
    return Problem(operation_types={0: 'hold', 1: 'weld', 2: 'move'}, robot_types=types,
                   robots=robots, jobs=jobs, distances=distances, precedence=precedence,
                   locomote=2, name=f'places {seed}')


def jig_panel(seed: int) -> Problem:
    """One panel like the paper's in small: jig job J held into A (two holds and a weld), up
    to three more jobs at three places; a big robot B that holds in 1 but takes 200 to
    cross, two arms and a mover, so G has three robots and a heavy job two of them."""
    rng = random.Random(seed)
    types = {'Big': {0: Fraction(1), 1: Fraction(rng.choice([1, 5])), 2: Fraction(200)},
             'Arm': {0: Fraction(rng.choice([3, 5])), 1: Fraction(1),
                     2: Fraction(rng.choice([1, 5]))},
             'Mover': {0: Fraction(rng.choice([5, 10])), 1: Fraction(10), 2: Fraction(1)}}
    robots = (Robot('B', 'Big'), Robot('A1', 'Arm'),
              Robot('A2', 'Arm', Fraction(rng.choice([1, 2]))), Robot('L', 'Mover'))
    jobs = [Job('J', 'x', ((0, 0),)), Job('A', 'x', ((0, 0, 1),))]
    extra = [((2,),), ((0,),), ((0, 1),), ((1,),), ((0, 0),)]
    for i in range(rng.randint(1, 3)):
        jobs.append(Job(f'k{i}', rng.choice('xyz'), rng.choice(extra)))
    names = [j.name for j in jobs]
    precedence = [('J', 'A')]
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            if a != 'J' and rng.random() < 0.35:
                precedence.append((a, b))
    if rng.random() < 0.5:
        precedence.append(('k0', 'J'))
    distances = {}
    for x, y in (('x', 'y'), ('x', 'z'), ('y', 'z')):
        distances[x, y] = distances[y, x] = Fraction(rng.choice([0, 1, 3]))
    return Problem(operation_types={0: 'hold', 1: 'weld', 2: 'move'}, robot_types=types,
                   robots=robots, jobs=tuple(jobs), distances=distances,
                   precedence=tuple(precedence), holding=(('J', 'A', 0),), locomote=2,
                   name=f'jig {seed}')


def slow_crossers(seed: int, crossing: Fraction, panels: int, shift: int, mover_too: bool
                  ) -> Problem:
    """`jig_panel(seed)` with B crossing at `crossing` per unit of distance, and L at
    twice that if `mover_too`, repeated."""
    panel = jig_panel(seed)
    types = dict(panel.robot_types)
    types['Big'] = {**types['Big'], 2: crossing}
    if mover_too:
        types['Mover'] = {**types['Mover'], 2: 2 * crossing}
    return repeat_panels(dataclasses.replace(panel, robot_types=types), panels, shift)


def waiting_chain(shift: int) -> Problem:
    """Two panels `shift` apart of x -> y -> z -> w, all at one spot. x and z need both A and
    B (1 each), only A does y (5), only B does w (6); both travel 1 per unit of distance."""
    base = Problem(
        operation_types={0: 'hold', 1: 'weld', 2: 'move', 3: 'locomote'},
        robot_types={'A': {0: Fraction(1), 2: Fraction(5), 3: Fraction(1)},
                     'B': {0: Fraction(1), 1: Fraction(6), 3: Fraction(1)}},
        robots=(Robot('A', 'A'), Robot('B', 'B')),
        jobs=(Job('x', 'a', ((0, 0),)), Job('y', 'a', ((2,),)), Job('z', 'a', ((0, 0),)),
              Job('w', 'a', ((1,),))),
        distances={}, precedence=(('x', 'y'), ('y', 'z'), ('z', 'w')), locomote=3,
        name='waiting chain')
    return repeat_panels(base, 2, shift)


def unrelated(slow_hold: int) -> Problem:
    """Per panel X (hold and weld) and Y (two welds), unrelated; S holds in `slow_hold` but
    takes 200 to cross, arms hold in 3 and weld in 1; two panels 1 apart."""
    types = {'Slow': {0: Fraction(slow_hold), 1: Fraction(100), 2: Fraction(200)},
             'Arm': {0: Fraction(3), 1: Fraction(1), 2: Fraction(1)}}
    robots = (Robot('S', 'Slow'), Robot('A1', 'Arm'), Robot('A2', 'Arm'), Robot('A3', 'Arm'))
    panel = Problem(operation_types={0: 'hold', 1: 'weld', 2: 'move'}, robot_types=types,
                    robots=robots, jobs=(Job('X', 'a', ((0, 1),)), Job('Y', 'a', ((1, 1),))),
                    distances={}, locomote=2, name='unrelated')
    return repeat_panels(panel, 2, 1)


LOCOMOTE = 3
LOCATIONS = ('A', 'B', 'C')


def random_problem(seed: int) -> Problem:
    """3-5 jobs, 2-3 robots with rational speeds, multi-robot jobs, alternative plans, one
    holding arc and travel between three locations; some add a robot with a start location
    and release time, or a job already running (fixed), maybe with one of its robots
    released only after it ends: the first well-formed instance drawn from `seed` (some
    draws cannot be staffed)."""
    rng = random.Random(seed)
    while True:
        try:
            return _draw(rng, seed)
        except ProblemError:
            continue


def _draw(rng: random.Random, seed: int) -> Problem:
    n_robots = rng.randint(2, 3)
    robot_types = {}
    for i in range(n_robots):
        efficiency = {q: Fraction(rng.randint(1, 6)) for q in (0, 1, 2) if rng.random() < 0.85}
        efficiency[LOCOMOTE] = Fraction(rng.randint(1, 3))
        robot_types[f'T{i}'] = efficiency
    robots = [Robot(f'R{i}', f'T{i}', speed=Fraction(rng.choice((1, 2, 3)))) for i in
              range(n_robots)]
    if rng.random() < 0.3:
        robots[0] = Robot('R0', 'T0', robots[0].speed, rng.choice(LOCATIONS),
                          Fraction(rng.randint(0, 3)))

    n_jobs = rng.randint(3, 5)
    names = [f'j{i}' for i in range(n_jobs)]
    plans = []
    for _ in names:
        count = 2 if rng.random() < 0.4 else 1
        plans.append([[rng.randint(0, 2) for _ in range(rng.randint(1, min(2, n_robots)))]
                      for _ in range(count)])
    # One holding arc between two jobs, with exactly one type-q operation in every plan of
    # both, so the holder set can match whatever plans are chosen.
    a, b = sorted(rng.sample(range(n_jobs), 2))
    q = rng.randint(0, 2)
    for index in (a, b):
        for plan in plans[index]:
            plan[:] = [q] + [t for t in plan[1:] if t != q]
    precedence = [(names[i], names[k]) for i in range(n_jobs) for k in range(i + 1, n_jobs)
                  if (i, k) != (a, b) and rng.random() < 0.3]
    jobs = [Job(name, rng.choice(LOCATIONS), tuple(tuple(p) for p in plan))
            for name, plan in zip(names, plans, strict=True)]
    distances = {}
    for i, x in enumerate(LOCATIONS):
        for y in LOCATIONS[i + 1:]:
            distances[x, y] = distances[y, x] = Fraction(rng.randint(0, 4))

    fixed = {}
    roots = [n for n in names if not any(after == n for _, after in precedence)
             and n not in (names[a], names[b])]
    if roots and rng.random() < 0.3:
        fixed = _running(rng, roots[0], jobs, robots, robot_types)
        if fixed and rng.random() < 0.5:
            robots = _late_release(rng, robots, fixed)

    return Problem(
        operation_types={0: 'hold', 1: 'carry', 2: 'weld', LOCOMOTE: 'locomote'},
        robot_types=robot_types, robots=tuple(robots), jobs=tuple(jobs),
        distances=distances, precedence=tuple(precedence),
        holding=((names[a], names[b], q),), locomote=LOCOMOTE,
        fixed=fixed, name=f'random-{seed}')


def _running(rng, name, jobs, robots, robot_types):
    """Fix `name` as started at 0 with plan 0, staffed greedily, if its robots allow."""
    plan = next(j for j in jobs if j.name == name).plans[0]
    free = [r for r in robots if r.start_location is None]
    rng.shuffle(free)
    staff, longest = {}, Fraction(0)
    for q in plan:
        robot = next((r for r in free if q in robot_types[r.type] and r.name not in staff),
                     None)
        if robot is None:
            return {}
        staff[robot.name] = q
        longest = max(longest, robot_types[robot.type][q])
    return {name: FixedJob(0, Fraction(0), longest + 1, staff)}


def _late_release(rng, robots, fixed):
    """Release one robot of the running job after it ends (it reports back late)."""
    (job,) = fixed.values()
    late = rng.choice(sorted(job.robots))
    return [Robot(r.name, r.type, r.speed, r.start_location, job.end + rng.randint(1, 3))
            if r.name == late else r for r in robots]


def places(panels: int, seed: int) -> Problem:
    """`places_panel(seed)` repeated, the panels 1 to 3 apart as the seed draws."""
    return repeat_panels(places_panel(seed), panels, random.Random(seed).choice([1, 2, 3]))
