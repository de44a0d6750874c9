"""Times as a person reads them: decimals, with the places that tell two times apart."""

import math
from fractions import Fraction

import pytest

from fjsp_common.decimals import decimal, decimals


@pytest.mark.parametrize(('times', 'written'), [
    ((32,), ('32',)),
    ((Fraction(64, 2),), ('32',)),
    ((32.0,), ('32',)),
    ((Fraction(13, 3),), ('4.333',)),
    ((Fraction(1, 2),), ('0.500',)),
    ((-Fraction(1, 3),), ('-0.333',)),
    ((Fraction(175921869240253, 8796093022208), Fraction(118782445801396367, 5629499534213120)),
     ('20.000', '21.100')),
    ((Fraction(4999, 1000), Fraction(13, 3), 5), ('4.999', '4.333', '5')),
    ((Fraction(49999, 10000), 5), ('4.9999', '5')),
    ((12.0004, 12.0001, 12.0004), ('12.0004', '12.0001', '12.0004')),
    ((20.0000001, 20), ('20.0000001', '20')),
    ((None, math.nan, math.inf, Fraction(7, 4)), ('?', '?', '?', '1.750')),
])
def test_times_are_written_as_decimals(times, written):
    assert decimals(*times) == written


def test_one_time_alone():
    assert decimal(Fraction(91, 3) * 3 + Fraction(1, 3)) == '91.333'
