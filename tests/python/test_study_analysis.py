"""The order and Richardson analysis of frictherm.study (frictherm/study_analysis.py) on synthetic
data f(h) = f_inf + c h^p, whose order and limit are known exactly."""
import math

import pytest

from frictherm.study_analysis import (CONVERGED, DIVERGING, MONOTONE, OSCILLATORY, study_levels, three_levels,
                                      two_levels)


@pytest.mark.parametrize("ratios", [(2.0, 2.0), (2.0, 1.5), (1.7, 2.3), (3.0, 1.2)])
@pytest.mark.parametrize("p", [0.5, 1.0, 2.0, 3.0])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_three_levels_recover_order_and_limit(ratios, p, sign):
    f_inf, c = 3.0, 5.0 * sign
    h = [0.01, 0.01 / ratios[0], 0.01 / ratios[0] / ratios[1]]
    f = [f_inf + c * x**p for x in h]
    e = three_levels(h, f)
    assert e.status == MONOTONE
    # The differences f2 - f1 and f3 - f2 are at least ~1e-6 here, so round-off of f (1e-16 relative)
    # puts at most ~1e-9 into p; the limit's error is that times the finest difference.
    assert e.order == pytest.approx(p, rel=1e-8)
    assert e.limit == pytest.approx(f_inf, abs=1e-12)
    # GCI = 1.25 |f3 - f2| / |f3| / (r^p - 1) = 1.25 |f3 - f_inf| / |f3| for exact data (eq. 5 of Celik et al.)
    assert e.gci == pytest.approx(1.25 * abs(f[2] - f_inf) / abs(f[2]), rel=1e-7)


def test_levels_in_any_order():
    h = [0.0025, 0.01, 0.005]
    e = three_levels(h, [1.0 + x**2 for x in h])
    assert e.order == pytest.approx(2.0, rel=1e-10) and e.limit == pytest.approx(1.0, abs=1e-14)


def test_oscillatory_is_not_extrapolated():
    e = three_levels([4.0, 2.0, 1.0], [1.0, 2.0, 1.5])
    assert e.status == OSCILLATORY and e.order is None and e.limit is None and not e.extrapolated
    assert "oscillatory" in e.describe()


def test_diverging_is_not_extrapolated():
    assert three_levels([4.0, 2.0, 1.0], [1.0, 2.0, 3.0]).status == DIVERGING     # differences do not shrink
    assert three_levels([4.0, 2.0, 1.0], [1.0, 1.0, 3.0]).status == DIVERGING     # constant, then a jump
    # Unequal ratios: f3 - f2 larger than f2 - f1 can still be convergence (the last step is longer)...
    h = [0.01, 0.01 / 1.7, 0.01 / 1.7 / 2.3]
    assert three_levels(h, [3.0 - 5 * x**0.5 for x in h]).status == MONOTONE
    # ...but not when it exceeds what any order p > 0 gives: e21/e32 -> ln(r21)/ln(r32) as p -> 0.
    bound = math.log(1.7) / math.log(2.3)
    assert three_levels(h, [0.0, 1.0, 1.0 + 1.001 / bound]).status == DIVERGING
    assert three_levels(h, [0.0, 1.0, 1.0 + 0.999 / bound]).status == MONOTONE


def test_identical_values_are_converged():
    e = three_levels([0.5, 0.25, 0.1], [2.0, 2.0, 2.0])
    assert e.status == CONVERGED and e.limit == 2.0
    assert three_levels([0.5, 0.25, 0.1], [1.0, 2.0, 2.0]).status == CONVERGED  # the finest two agree


def test_study_levels_triples_and_failed_levels():
    h = [0.008, 0.004, 0.002, 0.001, 0.0005]
    f = [7.0 + 0.3 * x for x in h]
    f[1] = math.nan  # a failed run is left out
    a = study_levels(h, f)
    assert a["levels"] == [0.008, 0.002, 0.001, 0.0005]
    assert len(a["triples"]) == 2
    assert a["triples"][0].order == pytest.approx(1.0, rel=1e-8)      # ratios 4 and 2
    assert a["best"].limit == pytest.approx(7.0, abs=1e-12)
    assert study_levels(h[:2], f[:1] + [7.1])["best"] is None          # two levels, no assumed order


def test_two_levels_with_an_assumed_order():
    e = two_levels([0.2, 0.1], [1.0 + 0.2**2, 1.0 + 0.1**2], 2.0)
    assert e.limit == pytest.approx(1.0, abs=1e-14) and e.status == "assumed order"
