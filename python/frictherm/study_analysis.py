"""Observed order of convergence and Richardson extrapolation of a resolution study.

A quantity f computed at three resolutions h1 > h2 > h3 (cell sizes, or CFL factors: the time step
is proportional to C) that converges as f(h) = f_inf + c h^p gives, with r21 = h1/h2, r32 = h2/h3,
e21 = f2 - f1 and e32 = f3 - f2 (Celik et al. 2008, "Procedure for estimation and reporting of
uncertainty due to discretization in CFD applications", J. Fluids Eng. 130, 078001, eqs. 2-4):

    p = ln(e21/e32) / ln(r)                                   (constant ratio r = r21 = r32)
    e21/e32 = r32^p (r21^p - 1) / (r32^p - 1)                 (any ratios: solved for p by bisection)
    f_inf = f3 + (f3 - f2) / (r32^p - 1)                      (Richardson, eq. 5)
    GCI_fine = 1.25 |(f3 - f2)/f3| / (r32^p - 1)              (Roache's grid convergence index, eq. 7)

Only monotone convergence (e32/e21 > 0, with p > 0) is extrapolated. Differences of opposite sign are
oscillatory convergence (or noise) and differences that do not shrink are divergence: both are
reported as such, with no order and no extrapolated value, since the formulas above would give a
number that means nothing. Plain Python (no numpy or h5py).
"""
import math

MONOTONE = "monotone"          # e32/e21 > 0 and the differences shrink: p and f_inf are given
OSCILLATORY = "oscillatory"    # e32/e21 < 0
DIVERGING = "diverging"        # same sign, not shrinking (|e32| >= |e21| for equal ratios; or e21 = 0 != e32)
CONVERGED = "converged"        # e21 = e32 = 0 (to round-off): f_inf = f3, no order
TOO_FEW = "too few levels"     # fewer than 3 finite values

# Differences below this fraction of the values' scale count as zero (round-off of the outputs).
ROUND_OFF = 1e-12
SAFETY_FACTOR = 1.25  # Roache's factor of safety for three-level studies (Celik et al. 2008)


class Extrapolation:
    """The result of three levels: ``status`` (one of the constants above), ``order`` p,
    ``limit`` f_inf, ``gci`` (relative, of the finest level), ``ratio`` e32/e21, ``levels`` (the
    three resolutions, coarse to fine) and ``values``. ``order``, ``limit`` and ``gci`` are None
    unless the status is monotone (``limit`` is f3 when converged)."""

    def __init__(self, levels, values, status, order=None, limit=None, gci=None, ratio=None):
        self.levels, self.values = list(levels), list(values)
        self.status, self.order, self.limit, self.gci, self.ratio = status, order, limit, gci, ratio

    @property
    def extrapolated(self):
        return self.limit is not None

    def describe(self, fmt="%.6g"):
        lv = ", ".join("%g" % h for h in self.levels)
        if self.status == MONOTONE:
            return ("monotone over %s: order p = %.3g, extrapolated %s, GCI %.3g %%"
                    % (lv, self.order, fmt % self.limit, 100.0 * self.gci))
        if self.status == CONVERGED:
            return "converged over %s (the finest values agree to round-off): %s" % (lv, fmt % self.limit)
        f1, f2, f3 = self.values
        spread = max(self.values) - min(self.values)
        rel = " (%.2g %% of the finest)" % (100.0 * spread / abs(f3)) if f3 else ""
        if self.status == OSCILLATORY:
            return ("oscillatory over %s (differences %s then %s): no order, no extrapolation; values span %s%s"
                    % (lv, fmt % (f2 - f1), fmt % (f3 - f2), fmt % spread, rel))
        if self.status == DIVERGING:
            return ("not converging over %s (differences %s then %s): no extrapolation; values span %s%s"
                    % (lv, fmt % (f2 - f1), fmt % (f3 - f2), fmt % spread, rel))
        return "%s (%s)" % (self.status, lv)

    def as_dict(self):
        return dict(levels=self.levels, values=self.values, status=self.status, order=self.order,
                    limit=self.limit, gci=self.gci, ratio=self.ratio)


def _solve_order(r21, r32, e21, e32):
    """p of monotone convergence (e32/e21 > 0, p > 0) from f = f_inf + c h^p through three levels:
    e21/e32 = r32^p (r21^p - 1) / (r32^p - 1) (Celik et al. 2008 eqs. 3a-3c, with s = 1), solved by
    bisection; for r21 = r32 = r it is p = ln(e21/e32)/ln(r) and that is returned exactly."""
    target = math.log(e21 / e32)
    if abs(r21 / r32 - 1.0) < 1e-12:
        return target / math.log(r32)
    a21, a32 = math.log(r21), math.log(r32)

    def lhs(p):  # ln of the right-hand side above; increases with p
        return math.log(math.expm1(p * a21)) + p * a32 - math.log(math.expm1(p * a32))

    lo, hi = 1e-9, 1.0
    while lhs(hi) < target and hi < 1e3:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if lhs(mid) < target:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    return 0.5 * (lo + hi)


def three_levels(levels, values):
    """Observed order and Richardson extrapolation from three resolutions and their values.

    `levels` are the resolutions (cell sizes or CFL factors, any order, all distinct and > 0),
    `values` the quantity at each. Returns an Extrapolation."""
    pairs = sorted(zip(levels, values), key=lambda hv: -hv[0])  # coarse to fine
    (h1, f1), (h2, f2), (h3, f3) = pairs
    if not (h1 > h2 > h3 > 0):
        raise ValueError("three_levels needs three distinct resolutions > 0, got %r" % (list(levels),))
    hs, fs = (h1, h2, h3), (f1, f2, f3)
    if not all(math.isfinite(f) for f in fs):
        return Extrapolation(hs, fs, TOO_FEW)
    scale = max(abs(f) for f in fs)
    tiny = ROUND_OFF * scale
    e21, e32 = f2 - f1, f3 - f2
    if abs(e21) <= tiny and abs(e32) <= tiny:
        return Extrapolation(hs, fs, CONVERGED, limit=f3, gci=0.0, ratio=None)
    if abs(e21) <= tiny:
        return Extrapolation(hs, fs, DIVERGING, ratio=math.inf)
    ratio = e32 / e21
    if abs(e32) <= tiny:  # the finest two agree to round-off: converged at the finest level
        return Extrapolation(hs, fs, CONVERGED, limit=f3, gci=0.0, ratio=ratio)
    if ratio < 0:
        return Extrapolation(hs, fs, OSCILLATORY, ratio=ratio)
    r21, r32 = h1 / h2, h2 / h3
    # Same sign: converging at some p > 0 only if e21/e32 > lim_{p->0} r32^p (r21^p - 1)/(r32^p - 1)
    # = ln(r21)/ln(r32) (1 when the ratios are equal: the differences must shrink).
    if math.log(e21 / e32) <= math.log(math.log(r21) / math.log(r32)) + 1e-12:
        return Extrapolation(hs, fs, DIVERGING, ratio=ratio)
    p = _solve_order(r21, r32, e21, e32)
    limit = f3 + e32 / (r32**p - 1.0)   # Celik et al. 2008 eq. 4
    gci = SAFETY_FACTOR * abs(e32 / f3) / (r32**p - 1.0) if f3 != 0 else math.inf
    return Extrapolation(hs, fs, MONOTONE, order=p, limit=limit, gci=gci, ratio=ratio)


def two_levels(levels, values, order):
    """Richardson extrapolation from two resolutions with an assumed (not observed) order p."""
    (h1, f1), (h2, f2) = sorted(zip(levels, values), key=lambda hv: -hv[0])
    r = h1 / h2
    limit = f2 + (f2 - f1) / (r**order - 1.0)
    gci = 3.0 * abs((f2 - f1) / f2) / (r**order - 1.0) if f2 != 0 else math.inf  # Roache: Fs = 3 for two levels
    return Extrapolation((h1, h2), (f1, f2), "assumed order", order=order, limit=limit, gci=gci)


def study_levels(levels, values, assumed_order=None):
    """The analysis along one direction of a study: every consecutive triple (coarse to fine), and the
    estimate from the finest one. Levels whose value is not finite (a failed run) are left out.

    Returns a dict: ``levels``, ``values`` (finite only, coarse to fine), ``triples`` (one
    Extrapolation per consecutive triple, which shows whether p settles: the asymptotic range),
    ``best`` (the finest triple's Extrapolation, or with 2 levels and `assumed_order` an
    extrapolation with that order, or None)."""
    pairs = sorted(((h, f) for h, f in zip(levels, values) if f is not None and math.isfinite(f)),
                   key=lambda hv: -hv[0])
    hs = [h for h, _ in pairs]
    fs = [f for _, f in pairs]
    triples = [three_levels(hs[i:i + 3], fs[i:i + 3]) for i in range(len(hs) - 2)]
    best = triples[-1] if triples else None
    if best is None and len(hs) == 2 and assumed_order:
        best = two_levels(hs, fs, assumed_order)
    return dict(levels=hs, values=fs, triples=triples, best=best)
