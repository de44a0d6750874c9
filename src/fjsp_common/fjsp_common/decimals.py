"""How times are written for people: as decimals, never as raw fractions.

Times are exact `Fraction`s in the data (a travel time of distance * 10/3, a time reported by
an agent as a float, converted exactly), and a fraction such as 175921869240253/8796093022208
tells a reader nothing. Every time in a message, a log line, a mission event or a page is
written by this one rule: an exact integer as it is (`32`), any other time with three decimal
places (`20.000`, `91.333`), and with more where two different times written together would
otherwise read the same (`4.9999` and `5`, `12.0004` and `12.0001`).
"""

import math
from fractions import Fraction

PLACES = 3
"""Decimal places of a time that is not an integer, unless more tell two times apart."""

UNKNOWN = '?'
"""How an unknown time (None, NaN, infinite) is written."""


def decimal(time) -> str:
    """One time, written by the rule."""
    return decimals(time)[0]


def decimals(*times) -> tuple[str, ...]:
    """Times written together: each with the same number of places, the fewest (at least
    PLACES) that keep different times different. Accepts Fractions, ints and floats."""
    exact = [_exact(t) for t in times]
    distinct = sorted({t for t in exact if t is not None})
    places = PLACES
    # Rounding keeps order, so two times that read alike have neighbours that do too.
    while any(round(a, places) == round(b, places)
              for a, b in zip(distinct, distinct[1:], strict=False)):
        places += 1
    return tuple(UNKNOWN if t is None else _written(t, places) for t in exact)


def _exact(time) -> Fraction | None:
    if time is None or isinstance(time, bool):
        return None
    if isinstance(time, float) and not math.isfinite(time):
        return None
    return Fraction(time)


def _written(time: Fraction, places: int) -> str:
    if time.denominator == 1:
        return str(time.numerator)
    scaled = round(abs(time) * 10 ** places)
    whole, part = divmod(scaled, 10 ** places)
    sign = '-' if time < 0 else ''
    return f'{sign}{whole}.{part:0{places}d}'
