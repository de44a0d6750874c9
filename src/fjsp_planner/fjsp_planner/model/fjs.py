"""Read the standard FJSP benchmark text format (Brandimarte, Hurink, ...) into a `Problem`.

Format: the first line is `n m [average machines per operation]`; then one line per job:
the number of operations, then for each operation `k` followed by `k` pairs
`machine time` (machines numbered from 1).

The classic FJSP is the special case of our model (docs/model.md) where every job of the
benchmark is a chain of single-robot operations. Each benchmark operation therefore becomes
one job of ours (`J2.O3` is operation 3 of job 2, both 1-indexed) with a single
one-operation plan whose operation type belongs to that operation alone; each machine
becomes a robot `M<i>` of its own robot type, whose efficiency for an operation type is the
machine's processing time. The operations of a benchmark job are chained by precedence
arcs. Everything happens at one location and travel is free (`locomote=None`).
"""

from fractions import Fraction
from pathlib import Path

from fjsp_planner.model import limits
from fjsp_planner.model.limits import shown
from fjsp_planner.model.problem import Job, Problem, ProblemError, Robot

LOCATION = 'shop'


def load_fjs(path) -> Problem:
    """Parse an `.fjs` file; a malformed file raises `ProblemError` naming the line."""
    path = Path(path)
    text = limits.read_input_file(path, '.fjs')
    return parse_fjs(text, name=path.stem, source=str(path))


def parse_fjs(text: str, name: str = 'fjs', source: str = '<text>') -> Problem:
    lines = [(number, line.split()) for number, line in enumerate(text.splitlines(), 1)]
    lines = [(number, tokens) for number, tokens in lines if tokens]
    if not lines:
        raise ProblemError([f'{source}: empty file, expected a header line "jobs machines"'])
    header_line, header = lines[0]
    if len(header) not in (2, 3):
        raise ProblemError([f'{source} line {header_line}: header must be "jobs machines '
                            f'[average]", got {len(header)} fields'])
    n_jobs = _count(header[0], 'number of jobs', source, header_line)
    n_machines = _count(header[1], 'number of machines', source, header_line)
    # Each machine is a robot, and each operation a job: bounded before anything is built.
    too_many = limits.count_problem(f'{source} line {header_line}: number of machines',
                                    n_machines, limits.MAX_ROBOTS)
    if too_many:
        raise ProblemError(too_many)
    job_lines = lines[1:]
    if len(job_lines) != n_jobs:
        raise ProblemError([f'{source}: header (line {header_line}) announces {n_jobs} jobs '
                            f'but {len(job_lines)} job lines follow'])

    machines = [f'M{i}' for i in range(1, n_machines + 1)]
    efficiency = {machine: {} for machine in machines}
    operation_types, jobs, precedence = {}, [], []
    for job_index, (number, tokens) in enumerate(job_lines, 1):
        where = f'{source} line {number} (job {job_index})'
        names = []
        for op_index, options in enumerate(_operations(tokens, n_machines, where), 1):
            q = len(operation_types)
            op_name = f'J{job_index}.O{op_index}'
            operation_types[q] = op_name
            for machine, time in options.items():
                efficiency[machines[machine - 1]][q] = time
            jobs.append(Job(op_name, LOCATION, ((q,),)))
            names.append(op_name)
            if len(jobs) > limits.MAX_JOBS:
                raise ProblemError(limits.count_problem(
                    f'{where}: operations (each one a job)', len(jobs), limits.MAX_JOBS))
        precedence.extend(zip(names, names[1:], strict=False))

    robots = tuple(Robot(machine, machine) for machine in machines)
    too_large = limits.scale_problems(robots, efficiency, jobs, {}, None, {})
    if too_large:
        raise ProblemError([f'{source}: {p}' for p in too_large])
    return Problem(
        operation_types=operation_types,
        robot_types=efficiency,
        robots=robots,
        jobs=tuple(jobs),
        precedence=tuple(precedence),
        name=name,
    )


def _operations(tokens, n_machines, where):
    """Yield {machine (1-based): time} per operation of one job line."""
    n_ops = _count(tokens[0], 'number of operations', where)
    position = 1
    for op_index in range(1, n_ops + 1):
        what = f'{where}, operation {op_index}'
        if position >= len(tokens):
            raise ProblemError([f'{what}: line ends early; it announces {n_ops} operations'])
        k = _count(tokens[position], 'number of machines', what)
        if k == 0:
            raise ProblemError([f'{what}: no machine can perform it (k = 0)'])
        pairs = tokens[position + 1:position + 1 + 2 * k]
        if len(pairs) < 2 * k:
            raise ProblemError([f'{what}: announces {k} machine/time pairs, line has only '
                                f'{len(pairs)} numbers left'])
        options = {}
        for machine_token, time_token in zip(pairs[::2], pairs[1::2], strict=True):
            machine = _count(machine_token, 'machine number', what)
            if not 1 <= machine <= n_machines:
                raise ProblemError([f'{what}: machine {machine} is outside 1..{n_machines}'])
            if machine in options:
                raise ProblemError([f'{what}: machine {machine} is listed twice'])
            options[machine] = _time(time_token, what, machine)
        yield options
        position += 1 + 2 * k
    if position != len(tokens):
        raise ProblemError([f'{where}: {len(tokens) - position} numbers left over after '
                            f'its {n_ops} operations'])


def _count(token, what, where, line=None):
    at = where if line is None else f'{where} line {line}'
    try:
        value = int(token)
    except ValueError:
        raise ProblemError([f'{at}: {what} must be an integer, got {shown(token)}']) from None
    if value < 0:
        raise ProblemError([f'{at}: {what} must not be negative, got {value}'])
    return value


def _time(token, where, machine):
    return limits.number(token, f'{where}: time on machine {machine}', Fraction(0),
                         limits.MAX_TIME)
