"""The at-bound flag judges a parameter on the scale it was searched on."""

from __future__ import annotations

import pytest

from labbrdf.fitting.uncertainty import AT_BOUND_FRAC
from labbrdf.fitting.uncertainty import at_bound as _at_bound
from labbrdf.models.base import Parameter


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        (2.8e-4, False),  # 16 decades from its lower bound: flagged on the linear scale
        (1e-12 * (1 + 0.5 * AT_BOUND_FRAC * 16 * 2.302585), True),
        (1e4 * (1 - 0.5 * AT_BOUND_FRAC * 16 * 2.302585), True),
        (1e-12 * 1.01, False),
    ],
)
def test_log_parameter_is_at_its_bound_on_the_log_scale(value: float, expected: bool) -> None:
    q = Parameter("A", value, 1e-12, 1e4, log=True)
    assert (_at_bound(q, q.min) or _at_bound(q, q.max)) is expected


def test_linear_parameter_keeps_the_linear_rule() -> None:
    q = Parameter("alpha", 1.0 - 0.5 * AT_BOUND_FRAC, 0.0, 1.0)
    assert _at_bound(q, q.max) and not _at_bound(q, q.min)
    q = Parameter("alpha", 0.5, 0.0, 1.0)
    assert not _at_bound(q, q.max) and not _at_bound(q, q.min)
