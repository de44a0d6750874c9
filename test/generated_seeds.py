"""Seeds for the property tests on generated scenarios (`fjsp_planner.model.generator`).

Each run draws fresh seeds from a base that pytest's header prints (`generated scenarios:
FJSP_SEED=...`); `FJSP_SEED=<base> pytest ...` repeats a run exactly. A seed that ever
failed is kept in its test's fixed list, so it is checked on every run from then on.
"""

import os

SEED_VARIABLE = 'FJSP_SEED'


def base() -> int:
    return int(os.environ[SEED_VARIABLE])


def fresh(count: int, salt: int) -> list[int]:
    """`count` seeds of this run; `salt` keeps two tests' seeds apart."""
    return [base() * 1000 + salt * 100 + i for i in range(count)]
