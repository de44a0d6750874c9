"""A lower bound for any scenario from its longest precedence chains, each solved as a
scenario of its own (`restricted`): the "chain" bound (docs/solver.md, "Chains and
operation sets").

Unlike the other bounds it sees that a chain's jobs are slow unless fast robots travel
between them: the staffing, the waits for the robots and their ways are chosen together.
"""

import itertools
from fractions import Fraction

from fjsp_planner.model.problem import Problem
from fjsp_planner.solving.bounds.restricted import restricted_bound

MOST_CHAINS = 24
"""Chains tried at most, longest first (at their fastest, with heads and tails)."""
PAIRED_CHAINS = 5
"""After the chains alone, every two of this many longest are tried together: their robots
and ways are coupled."""


def chain_bound(problem: Problem, time_limit: float, incumbent: Fraction | None = None
                ) -> Fraction | None:
    """The bound of the module docstring over the longest chains CP-SAT solves within
    `time_limit` seconds, or None when it does not apply (running jobs, no precedence) or
    proves nothing. With `incumbent`, a makespan known to be reachable, it never exceeds
    that."""
    if not problem.precedence:
        return None

    def chain_sets(heads, tails, fastest):
        chains = longest_chains(problem, heads, tails, fastest)
        paired = [tuple(dict.fromkeys(a + b)) for a, b in itertools.combinations(
            chains[:PAIRED_CHAINS], 2)]
        return chains[:MOST_CHAINS] + paired

    return restricted_bound(problem, chain_sets, time_limit, incumbent)


def longest_chains(problem: Problem, heads, tails, fastest) -> list[tuple[str, ...]]:
    """For every job, the precedence chain through it that grows backwards by the
    predecessor ending latest and forwards by the successor with the longest way to the end
    (at the fastest durations); distinct chains, the longest (head + durations + tail)
    first."""
    before = {job.name: [] for job in problem.jobs}
    after = {job.name: [] for job in problem.jobs}
    for a, b in problem.precedence:
        before[b].append(a)
        after[a].append(b)
    found = set()
    for job in problem.jobs:
        chain = [job.name]
        while before[chain[0]]:
            chain.insert(0, max(before[chain[0]], key=lambda a: (heads[a] + fastest[a], a)))
        while after[chain[-1]]:
            chain.append(max(after[chain[-1]], key=lambda b: (fastest[b] + tails[b], b)))
        found.add(tuple(chain))
    return sorted(found, key=lambda chain: (-(heads[chain[0]] + tails[chain[-1]] + sum(
        fastest[j] for j in chain)), chain))

