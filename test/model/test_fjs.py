"""The FJSP benchmark reader: structure of what it builds, optima of tiny files, bad files."""

import re
from fractions import Fraction

import pytest

from fjsp_planner.model.fjs import load_fjs, parse_fjs
from fjsp_planner.model.problem import ProblemError
from fjsp_planner.model.schedule import Status
from fjsp_planner.model.validate import validate
from fjsp_planner.solving.mip import solve_mip

from repo_paths import DATA


def test_structure_of_a_small_file():
    problem = load_fjs(DATA / 'tiny_2x2.fjs')
    assert problem.name == 'tiny_2x2'
    assert [r.name for r in problem.robots] == ['M1', 'M2']
    assert [j.name for j in problem.jobs] == ['J1.O1', 'J1.O2', 'J2.O1', 'J2.O2']
    # One operation type per benchmark operation, one single-operation plan per job.
    assert [j.plans for j in problem.jobs] == [((0,),), ((1,),), ((2,),), ((3,),)]
    assert problem.precedence == (('J1.O1', 'J1.O2'), ('J2.O1', 'J2.O2'))
    assert problem.duration('M1', 0) == 3
    assert problem.duration('M2', 0) == 5
    assert problem.duration('M1', 1) is None
    assert problem.duration('M2', 1) == 4
    assert problem.locomote is None
    assert problem.travel('M1', 'shop', 'shop') == 0


def test_decimal_times_stay_exact():
    problem = parse_fjs('1 1\n1 1 1 2.5\n')
    assert problem.duration('M1', 0) == Fraction(5, 2)


# Optima by hand:
# tiny_2x2: job 1 alone needs 3 + 4 = 7 (O1 on M1, O2 only on M2); job 2 fits beside it.
# parallel_3x2: three 4|6 jobs; M1 takes two (8), M2 one (6); any other split is >= 12.
# chain_1x1: one machine, 2 + 3 + 4 = 9.
# flex_2x3: job 2 needs 3 + 2 = 5 (O2 only on M1); J1 = M1 [0,2], M3 [3,4] fits around it.
@pytest.mark.parametrize(('name', 'optimum'), [
    ('tiny_2x2', 7), ('parallel_3x2', 8), ('chain_1x1', 9), ('flex_2x3', 5)])
def test_tiny_files_solve_to_their_hand_checked_optimum(name, optimum):
    problem = load_fjs(DATA / f'{name}.fjs')
    result = solve_mip(problem, time_limit=5.0)
    assert result.status == Status.OPTIMAL
    assert result.makespan == optimum
    assert validate(problem, result.schedule) == []


@pytest.mark.parametrize(('text', 'message'), [
    ('', 'empty file'),
    ('2\n', 'line 1: header must be'),
    ('x 2\n1 1 1 3\n', "number of jobs must be an integer, got 'x'"),
    ('2 2\n1 1 1 3\n', 'announces 2 jobs but 1 job lines follow'),
    ('1 2\n1 1 3 4\n', 'line 2 (job 1), operation 1: machine 3 is outside 1..2'),
    ('1 2\n1 0\n', 'operation 1: no machine can perform it'),
    ('1 2\n2 1 1 4\n', 'operation 2: line ends early; it announces 2 operations'),
    ('1 2\n1 2 1 4 2\n', 'announces 2 machine/time pairs, line has only 3 numbers left'),
    ('1 2\n1 1 1 4 7\n', 'line 2 (job 1): 1 numbers left over after its 1 operations'),
    ('1 2\n1 1 1 -4\n', "time on machine 1: '-4' is outside [0, 1e+06]"),
    ('1 2\n1 1 1 four\n', "time on machine 1: expected a finite number, got 'four'"),
    ('1 2\n1 1 1 1e-999999999\n', 'time on machine 1: expected a finite number'),
    ('1 2\n1 2 1 4 1 5\n', 'machine 1 is listed twice'),
    ('1 2\n-1\n', 'number of operations must not be negative'),
    # Beyond the limits of docs/scenario-format.md: CP-SAT overflowed on 1e23.
    ('1 2\n1 1 1 1e23\n', "time on machine 1: '1e23' is outside [0, 1e+06]"),
    ('1 2\n1 1 1 nan\n', "time on machine 1: expected a finite number, got 'nan'"),
    ('1 2\n1 1 1 0.0000001\n', "time on machine 1: '0.0000001' is too precise"),
    ('1 101\n1 1 1 3\n', 'number of machines: 101 is more than the limit of 100'),
    ('1 1000000000\n1 1 1 3\n', 'number of machines: 1000000000 is more than the limit'),
    ('1 1\n1001' + ' 1 1 1' * 1001 + '\n',
     'operations (each one a job): 1001 is more than the limit'),
    ('1 1\n' + '9' * 5000 + '\n', "number of operations must be an integer, got '999999"),
])
def test_malformed_files_name_line_and_fault(text, message):
    with pytest.raises(ProblemError, match=re.escape(message)):
        parse_fjs(text)


def test_missing_file_is_a_problem_error(tmp_path):
    with pytest.raises(ProblemError, match='absent.fjs: no such file'):
        load_fjs(tmp_path / 'absent.fjs')


def test_bad_files_are_named(tmp_path):
    with pytest.raises(ProblemError, match='is a directory, not a .fjs file'):
        load_fjs(tmp_path)
    latin = tmp_path / 'latin.fjs'
    latin.write_bytes(b'1 1\n1 1 1 3 \xe9\n')
    with pytest.raises(ProblemError, match=r'not UTF-8 text \(byte 0xe9 at offset 12\)'):
        load_fjs(latin)


def test_messages_stay_short():
    with pytest.raises(ProblemError) as caught:
        parse_fjs('1 1\n1 1 1 ' + 'x' * 10**6 + '\n')
    assert len(str(caught.value)) < 300
