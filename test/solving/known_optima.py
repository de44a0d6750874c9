"""Optima proven once, written down with how: the bound tests check their bounds against
this table without solving, and one slow test (`test_known_optima.py`) proves the entries
again with each prover named: every entry on every run but the costly ones, one of which a
run picks in turn.

Provers: 'mip' is the paper's MIP through SCIP (`solving/mip.py`), which shares nothing with
the CP-SAT model and has none of its cuts or panel bounds; 'cpsat' is `solve` proving
optimality. Two provers agreeing also says no CP-SAT cut removed an optimal schedule.
"""

from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from functools import partial

from fjsp_planner.model.generator import Shape, random_scenario
from fjsp_planner.model.problem import Problem
from fjsp_planner.model.scenario import load_scenario, parse_scenario, repeat_panels

import solver_instances as inst
from repo_paths import PAPER, SCENARIOS


@dataclass(frozen=True)
class KnownOptimum:
    name: str
    build: Callable[[], Problem]
    optimum: Fraction
    provers: tuple[str, ...]
    time_limit: float  # per prover, on a loaded 2-core machine
    costly: bool = False
    """Most of a minute to prove: the slow test re-proves such entries one a run, in turn."""

    def problem(self) -> Problem:
        return self.build()


def _generated(seed: int, jobs: int, robots: int, robot_types: int | None) -> Problem:
    return parse_scenario(random_scenario(seed, Shape(jobs=jobs, robots=robots,
                                                      robot_types=robot_types)))


def _repeated(panel: Callable[[int], Problem], seed: int, panels: int, shift: int
              ) -> Problem:
    return repeat_panels(panel(seed), panels, shift)


def _entries():
    yield KnownOptimum('paper', partial(load_scenario, PAPER), Fraction(32), ('cpsat',), 30)
    for scenario, optimum in (('truss', '23'), ('antenna', '88/5'), ('habitat', '58')):
        yield KnownOptimum(scenario, partial(load_scenario, SCENARIOS / f'{scenario}.yaml'),
                           Fraction(optimum), ('cpsat',), 60)
    yield KnownOptimum('tiny x2', partial(inst.tiny, 2), Fraction(11), ('mip', 'cpsat'), 120)
    yield KnownOptimum('detour x2', partial(inst.detour, 2), Fraction(11), ('mip', 'cpsat'),
                       60)
    for seed, optimum in ((2, 409), (8, 10), (9, 22), (13, 11)):
        yield KnownOptimum(f'random panel {seed} x2', partial(_repeated, inst.random_panel,
                                                             seed, 2, 2),
                           Fraction(optimum), ('mip', 'cpsat'), 120)
    for panels, seed, optimum in ((2, 0, 11), (2, 3, 6), (2, 12, 14), (2, 22, 5), (3, 0, 18),
                                  (3, 3, 9), (3, 4, 10)):
        yield KnownOptimum(f'places {seed} x{panels}', partial(inst.places, panels, seed),
                           Fraction(optimum), ('cpsat',), 30)
    for seed, panels, shift, optimum in ((4, 2, 2, '27'), (20, 3, 1, '43'), (46, 2, 2, '24'),
                                         (74, 3, 1, '43'), (78, 2, 1, '49/2')):
        yield KnownOptimum(f'jig {seed} x{panels}',
                           partial(_repeated, inst.jig_panel, seed, panels, shift),
                           Fraction(optimum), ('cpsat',), 20)
    for seed, crossing, shift, mover_too, optimum, costly in (
            (78, '119/4', 1, False, '41', False), (150, '91/4', 1, False, '65/2', True),
            (0, '749/20', 1, False, '107/2', True), (19, '561/20', 1, False, '47', True),
            (6, '671/40', 2, False, '56', True), (39, '259/10', 2, True, '584/5', False)):
        yield KnownOptimum(f'slow crossers {seed} x3',
                           partial(inst.slow_crossers, seed, Fraction(crossing), 3, shift,
                                   mover_too),
                           Fraction(optimum), ('cpsat',), 120, costly=costly)
    for slow_hold in (1, 6):
        yield KnownOptimum(f'unrelated {slow_hold}', partial(inst.unrelated, slow_hold),
                           Fraction(6), ('cpsat',), 20)
    for shift, optimum in ((1, 23), (3, 27), (10, 36)):
        yield KnownOptimum(f'waiting chain {shift}', partial(inst.waiting_chain, shift),
                           Fraction(optimum), ('cpsat',), 20)
    for seed, optimum in enumerate(
            '11 11/3 26 47/3 14 3 7 5 13 13 16 11 17 20 22 10 15 22 16 6'.split()):
        yield KnownOptimum(f'random problem {seed}', partial(inst.random_problem, seed),
                           Fraction(optimum), ('mip', 'cpsat'), 10)
    for seed, optimum in zip(range(400, 408), (
            '112 227/2 339/10 633/5 219/4 584/15 233/10 551/15'.split()), strict=True):
        yield KnownOptimum(f'generated {seed} (5 jobs)', partial(_generated, seed, 5, 3, 2),
                           Fraction(optimum), ('mip', 'cpsat'), 60)
    for seed, optimum in zip(range(300, 330), (
            '439/20 301/5 831/40 269/4 403/20 138/5 2893/75 643/30 1433/10 1288/15 411/10 '
            '1298/25 1197/20 172/5 186/5 269/5 1049/20 199/3 329/10 195/8 1202/15 1667/25 '
            '127/10 13 292/5 371/5 38 166/3 133/4 93/5').split(), strict=True):
        yield KnownOptimum(f'generated {seed} (7 jobs)', partial(_generated, seed, 7, 4, 3),
                           Fraction(optimum), ('cpsat',), 20)
    # The shape users reported (bench/solve_general.py): 30 jobs, 7 robots of 4 types, travel,
    # holding, alternative plans; the operation set bound comes within 9 % of it (131.83).
    yield KnownOptimum('generated 12 (30 jobs)', partial(_generated, 12, 30, 7, 4),
                       Fraction(4321, 30), ('cpsat',), 60)
    # A holder crossing places; the fleet load bound's exact optimum here, 6048 ticks, comes
    # back from CP-SAT as 6048.000000000001: its ceiling once made the bound unreachable.
    yield KnownOptimum('generated 13012918 (14 jobs)', partial(_generated, 13012918, 14, 4, None),
                       Fraction(756, 5), ('cpsat',), 20)


KNOWN = {entry.name: entry for entry in _entries()}
