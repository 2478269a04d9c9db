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


def _synthetic_study(tolerance=0.1, reference=None):
    """A Study over rows made up as f = 1 + 3 h^2 + 0.5 C (no runs): along h the limit at each C is
    1 + 0.5 C (order 2), along C the limit at each h is 1 + 3 h^2 (order 1), both together 1."""
    from frictherm.study import Study
    from frictherm.study_runs import Output
    cells, cfls = [0.04, 0.02, 0.01], [0.4, 0.2, 0.1]
    rows = [dict(cell=h, cfl=c, status="completed", values={"f": 1.0 + 3.0 * h**2 + 0.5 * c}, wall_s=0.0,
                 cpu_s=1e-6 / (h**3 * c), run_wall_s=0.0, steps=1, particles=1, file="x.h5", note="")
            for h in cells for c in cfls]
    return Study("synthetic.json", rows, [Output("f")], cells, cfls, reference=reference, tolerance=tolerance)


def test_study_reference_errors_and_recommendation_on_synthetic_rows():
    st = _synthetic_study()
    a = st.analysis("f")
    for c, la in a["along_cell"].items():
        assert la["best"].order == pytest.approx(2.0, rel=1e-8) and la["best"].limit == pytest.approx(1 + 0.5 * c)
    for h, la in a["along_cfl"].items():
        assert la["best"].order == pytest.approx(1.0, rel=1e-8) and la["best"].limit == pytest.approx(1 + 3 * h**2)
    ref, source = a["reference"]
    assert ref == pytest.approx(1.0, abs=1e-10) and source.startswith("extrapolated in C at each cell")
    errors = {(r["cell"], r["cfl"]): r["values"]["f"] - 1.0 for r in st.rows}
    for key, e in errors.items():
        assert a["errors"][key] == pytest.approx(e, abs=1e-10)
    # the cheapest run within 10 %: by brute force over the made-up costs
    best = min((r for r in st.rows if errors[(r["cell"], r["cfl"])] <= 0.1), key=lambda r: r["cpu_s"])
    assert a["recommendation"] is best
    from frictherm.study_report import summary_lines
    text = "\n".join(summary_lines(st))
    assert "the 3 limits in h span" in text and "Cheapest run within 10 %" in text
    # a given reference wins over every extrapolation
    given = _synthetic_study(reference={"f": 2.0}).analysis("f")
    f = 1.0 + 3.0 * 0.01**2 + 0.5 * 0.1
    assert given["reference"] == (2.0, "given") and given["errors"][(0.01, 0.1)] == pytest.approx((f - 2.0) / 2.0)
