"""Richardson extrapolation against sequences with a known limit and order."""
import pytest

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.verification.convergence import richardson


@pytest.mark.parametrize("limit, C, p, ratio", [(20.9, -3.0, 1.7, 2.0), (1.0, 0.5, 3.0, 1.5)])
def test_recovers_the_order_and_limit_of_a_power_law(limit, C, p, ratio):
    values = [limit + C * (1.0 / ratio ** k) ** p for k in range(3)]
    order, extrapolated = richardson(*values, ratio=ratio)
    assert order == pytest.approx(p, rel=1e-10)
    assert extrapolated == pytest.approx(limit, rel=1e-12)


@pytest.mark.parametrize("values", [(1.0, 2.0, 1.5), (1.0, 1.5, 2.5), (1.0, 1.0, 1.0)])
def test_a_sequence_that_does_not_converge_monotonically_is_refused(values):
    with pytest.raises(InputError):
        richardson(*values)
