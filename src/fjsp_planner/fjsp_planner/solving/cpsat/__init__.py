"""The CP-SAT backend, split by concern as docs/solver.md describes: `grid` (integer time),
`variables`, `constraints` (rules and cuts), `objective`, `model` (assembly, hints, reading a
solution back) and `search` (running CP-SAT)."""

from fjsp_planner.solving.cpsat.search import SearchHandle, solve_cpsat

__all__ = ['SearchHandle', 'solve_cpsat']
