// Extended B-splines (Kakouris, Chatzis & Triantafyllou 2024 §3.3): the extension coefficients of the
// paper's figure 4, partition of unity, linear and quadratic reproduction, the extended basis against a
// direct evaluation of eq. 25, classification invariants, EBS = OBS without small cut cells, rebuild.
//
// Tolerances: every quantity is a sum of at most a few hundred products of O(1) B-spline values,
// extension coefficients (1D factors |L| <= 8 for search radius 3, t in [-2, 4] in eq. 23; the
// bodies here give |E| <= 9) and coordinates <= 2; the round-off of such a sum is below 1e-13
// absolute (values) or 1e-13/h (gradients). 1e-12 (values) and 1e-10 (polynomial reproduction,
// products with coordinates and 1/h ~ 10) leave margins of >= 10x.
#include <frictherm/mechanics/ebs.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <vector>

using namespace frictherm::mechanics;

namespace {

template <int Dim>
struct Entry {
  int node;
  double S;
  Vec<Dim> G;
};

template <int Dim>
std::vector<Entry<Dim>> entries(const EbsStencil<Dim>& s) {
  std::vector<Entry<Dim>> out;
  s.for_each([&](int i, double S, const Vec<Dim>& G) { out.push_back({i, S, G}); });
  return out;
}

template <int Dim>
struct Body {
  std::vector<Vec<Dim>> x;
  std::vector<double> V;
};

// n^Dim particles per grid cell on a regular sub-lattice, kept where inside(x); volume Π(h/n)·oop.
template <int Dim>
Body<Dim> fill(const Grid<Dim>& g, int n, double oop, const std::function<bool(const Vec<Dim>&)>& inside) {
  Body<Dim> b;
  double V = (Dim < 3) ? oop : 1.0;
  IVec<Dim> count;
  int total = 1;
  for (int d = 0; d < Dim; ++d) {
    V *= g.cell_size()[d] / n;
    count[d] = g.cells()[d] * n;
    total *= count[d];
  }
  for (int k = 0; k < total; ++k) {
    Vec<Dim> x;
    for (int d = 0, r = k; d < Dim; r /= count[d], ++d) x[d] = g.lo()[d] + (r % count[d] + 0.5) * g.cell_size()[d] / n;
    if (inside(x)) {
      b.x.push_back(x);
      b.V.push_back(V);
    }
  }
  return b;
}

// Random points in the cells (knot spans) that hold particles: where the extended basis is defined.
template <int Dim>
std::vector<Vec<Dim>> sample_points(const Grid<Dim>& g, const Body<Dim>& b, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, b.x.size() - 1);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  std::vector<Vec<Dim>> pts = b.x;
  for (int k = 0; k < count; ++k) {
    const Vec<Dim>& p = b.x[pick(rng)];
    Vec<Dim> x;
    for (int d = 0; d < Dim; ++d) {
      const double c = std::floor((p[d] - g.lo()[d]) / g.cell_size()[d] + 0.5);
      x[d] = g.lo()[d] + (c + u(rng)) * g.cell_size()[d];
    }
    pts.push_back(x);
  }
  return pts;
}

// Plain quadratic B-spline at x for any Dim (Stencil covers 2D and 3D only): f(node, N, grad N).
template <int Dim, class F>
void obs_for_each(const Grid<Dim>& g, const Vec<Dim>& x, F&& f) {
  Weights1D<3> w[Dim];
  for (int d = 0; d < Dim; ++d)
    QuadraticBSplineKernel::eval(x[d], g.lo()[d], g.cell_size()[d], g.inverse_cell_size()[d], 0.0, w[d]);
  const int n = Dim == 1 ? 3 : (Dim == 2 ? 9 : 27);
  for (int a = 0; a < n; ++a) {
    IVec<Dim> l;
    double S = 1.0;
    Vec<Dim> G = Vec<Dim>::Ones();
    for (int d = 0, r = a; d < Dim; ++d, r /= 3) {
      l[d] = w[d].base + r % 3;
      S *= w[d].w[r % 3];
      for (int e = 0; e < Dim; ++e) G[e] *= (e == d) ? w[d].dw[r % 3] : w[d].w[r % 3];
    }
    f(g.node_index(l), S, G);
  }
}

// Checks at every point: partition of unity, zero gradient sum, all nodes distinct and stable, the
// stencil equal to eq. 25 evaluated directly from the OBS values and E_IJ, and reproduction of a
// random linear and quadratic polynomial with the B-spline coefficients of the quasi-interpolant.
template <int Dim>
void check_properties(const Grid<Dim>& g, const EbsBasis<Dim>& ebs, const std::vector<Vec<Dim>>& pts, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // p(x) = a + b·x + x^T C x. Node-centred quadratic B-splines reproduce x_a exactly with
  // coefficients X_a and x_a^2 with X_a^2 - h_a^2/4 (Σ N_i (X_i - x)^2 = h^2/4, the B-spline's
  // second moment), so p has coefficients c_I = p(X_I) - Σ_a C_aa h_a^2/4 (digest §2.2).
  const double a = u(rng);
  Vec<Dim> bl;
  Mat<Dim> C;
  for (int i = 0; i < Dim; ++i) {
    bl[i] = u(rng);
    for (int j = 0; j <= i; ++j) C(i, j) = C(j, i) = u(rng);
  }
  double shift = 0.0;
  for (int d = 0; d < Dim; ++d) shift += C(d, d) * g.cell_size()[d] * g.cell_size()[d] / 4.0;
  auto coef_quad = [&](const Vec<Dim>& X) { return a + bl.dot(X) + X.dot(C * X) - shift; };
  const double hmin = g.min_cell_size();
  for (const Vec<Dim>& x : pts) {
    const EbsStencil<Dim> s = ebs.evaluate(x);
    const auto e = entries(s);
    ASSERT_EQ(static_cast<int>(e.size()), s.size());
    double sum = 0.0, quad = 0.0;
    Vec<Dim> gsum = Vec<Dim>::Zero(), xr = Vec<Dim>::Zero(), gquad = Vec<Dim>::Zero();
    Mat<Dim> gx = Mat<Dim>::Zero();
    std::set<int> seen;
    for (const auto& en : e) {
      EXPECT_TRUE(seen.insert(en.node).second) << "node " << en.node << " listed twice";
      EXPECT_EQ(ebs.node_state(en.node), EbsNode::stable) << "EBS function on a non-stable node " << en.node;
      const Vec<Dim> X = g.node_position(en.node);
      sum += en.S;
      gsum += en.G;
      xr += en.S * X;
      gx += X * en.G.transpose();
      quad += en.S * coef_quad(X);
      gquad += en.G * coef_quad(X);
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << "partition of unity at " << x.transpose();
    EXPECT_LT(gsum.norm() * hmin, 1e-12) << "gradient sum at " << x.transpose();
    EXPECT_LT((xr - x).norm(), 1e-10) << "linear reproduction at " << x.transpose();
    EXPECT_LT((gx - Mat<Dim>::Identity()).norm(), 1e-10) << "gradient of x at " << x.transpose();
    const double p = a + bl.dot(x) + x.dot(C * x);
    const Vec<Dim> dp = bl + 2.0 * C * x;
    EXPECT_NEAR(quad, p, 1e-10) << "quadratic reproduction at " << x.transpose();
    EXPECT_LT((gquad - dp).norm(), 1e-10) << "quadratic gradient at " << x.transpose();

    // Eq. 25-26 directly: N^e_I = N_I + Σ_J E_IJ N_J from the plain B-spline stencil.
    std::map<int, std::pair<double, Vec<Dim>>> ref;
    obs_for_each<Dim>(g, x, [&](int n, double S, const Vec<Dim>& G) {
      const EbsNode st = ebs.node_state(n);
      ASSERT_NE(st, EbsNode::inactive) << "inactive B-spline non-zero in a material cell at " << x.transpose();
      auto add = [&](int I, double E) {
        auto& r = ref.try_emplace(I, 0.0, Vec<Dim>::Zero()).first->second;
        r.first += E * S;
        r.second += E * G;
      };
      if (st == EbsNode::stable) add(n, 1.0);
      else ebs.for_each_extension(n, add);
    });
    ASSERT_EQ(ref.size(), e.size()) << "at " << x.transpose();
    for (const auto& en : e) {
      ASSERT_TRUE(ref.count(en.node));
      EXPECT_NEAR(en.S, ref[en.node].first, 1e-12);
      EXPECT_LT((en.G - ref[en.node].second).norm() * hmin, 1e-12);
    }
  }
}

// Exact (bitwise) equality of the extended and the plain quadratic B-spline stencils.
template <int Dim>
void expect_equals_obs(const Grid<Dim>& g, const EbsBasis<Dim>& ebs, const std::vector<Vec<Dim>>& pts) {
  for (const Vec<Dim>& x : pts) {
    const auto e = entries(ebs.evaluate(x));
    std::vector<Entry<Dim>> o;
    Stencil<Dim, QuadraticBSplineKernel> obs;
    obs.evaluate(g, x, Vec<Dim>::Zero());
    obs.for_each(g, [&](int i, double S, const Vec<Dim>& G) { o.push_back({i, S, G}); });
    ASSERT_EQ(e.size(), o.size());
    for (std::size_t k = 0; k < e.size(); ++k) {
      EXPECT_EQ(e[k].node, o[k].node);
      EXPECT_EQ(e[k].S, o[k].S);
      EXPECT_TRUE(e[k].G == o[k].G);
    }
  }
}

template <int Dim>
std::map<int, double> extension(const EbsBasis<Dim>& ebs, int J) {
  std::map<int, double> m;
  ebs.for_each_extension(J, [&](int I, double E) { m[I] = E; });
  return m;
}

Grid<2> grid2(double hx = 0.1, double hy = 0.1) { return Grid<2>(Vec<2>(0.0, 0.0), Vec<2>(hx, hy), {14, 16}); }

}  // namespace

// Figure 4 of the paper, 1D, C_c = 0.75: cells 4 and 8 are boundary cells, 5-7 interior, the
// degenerate bases are 4 and 10. Paper numbering (1-based cells c = [c-1, c] h, basis i supported on
// cells i-2..i) maps to ours (cell k = knot span [k-1/2, k+1/2] h centred on node k) as paper cell
// c = our cell c and paper basis i = our node i - 1: paper bases 4 and 10 are our nodes 3 and 9.
TEST(Ebs, Figure4Coefficients1D) {
  const double h = 0.1, A = 0.01;
  const Grid<1> g(Vec<1>(0.0), Vec<1>(h), {12});
  Body<1> b;  // material on [3.9, 8.0] h: φ = 0.6 in cell 4, 1 in cells 5-7, 0.5 in cell 8
  const double seg[][2] = {{3.9, 4.5}, {4.5, 5.5}, {5.5, 6.5}, {6.5, 7.5}, {7.5, 8.0}};
  for (const auto& s : seg)
    for (int q = 0; q < 4; ++q) {
      b.x.push_back(Vec<1>((s[0] + (q + 0.5) * (s[1] - s[0]) / 4.0) * h));
      b.V.push_back((s[1] - s[0]) / 4.0 * h * A);
    }
  EbsOptions opt;
  opt.occupation = 0.75;
  opt.out_of_plane = A;
  EbsBasis<1> ebs(opt);
  ebs.rebuild(g, b.x, b.V, 0, b.x.size());
  auto node = [&](int i) { return g.node_index({i}); };
  const double phi[] = {0, 0, 0, 0, 0.6, 1, 1, 1, 0.5, 0, 0, 0, 0};
  for (int c = 0; c <= 12; ++c) EXPECT_NEAR(ebs.volume_fraction(node(c)), phi[c], 1e-12) << "cell " << c;
  EXPECT_EQ(ebs.cell_state(node(4)), EbsCell::boundary);
  EXPECT_EQ(ebs.cell_state(node(8)), EbsCell::boundary);
  for (int c : {5, 6, 7}) EXPECT_EQ(ebs.cell_state(node(c)), EbsCell::interior);
  for (int c : {3, 9}) EXPECT_EQ(ebs.cell_state(node(c)), EbsCell::exterior);
  for (int i = -1; i <= 13; ++i) {
    const EbsNode want = (i == 3 || i == 9) ? EbsNode::degenerate : (i >= 4 && i <= 8 ? EbsNode::stable : EbsNode::inactive);
    EXPECT_EQ(ebs.node_state(node(i)), want) << "node " << i;
  }
  EXPECT_EQ(ebs.degenerate_count(), 2);
  EXPECT_EQ(ebs.stable_count(), 5);
  // Paper basis 4 from bases 5, 6, 7: E = (3, -3, 1); basis 10 from 7, 8, 9: E = (1, -3, 3).
  const auto e3 = extension(ebs, node(3)), e9 = extension(ebs, node(9));
  ASSERT_EQ(e3.size(), 3u);
  ASSERT_EQ(e9.size(), 3u);
  EXPECT_NEAR(e3.at(node(4)), 3.0, 1e-12);
  EXPECT_NEAR(e3.at(node(5)), -3.0, 1e-12);
  EXPECT_NEAR(e3.at(node(6)), 1.0, 1e-12);
  EXPECT_NEAR(e9.at(node(6)), 1.0, 1e-12);
  EXPECT_NEAR(e9.at(node(7)), -3.0, 1e-12);
  EXPECT_NEAR(e9.at(node(8)), 3.0, 1e-12);
  check_properties<1>(g, ebs, sample_points(g, b, 200, 1), 11);

  // C_c = 0.5: cell 4 (φ = 0.6) turns interior, so only node 9 (φ_8 = 0.5 <= C_c) stays degenerate.
  opt.occupation = 0.5;
  ebs.set_options(opt);
  ebs.rebuild(g, b.x, b.V, 0, b.x.size());
  EXPECT_EQ(ebs.node_state(node(3)), EbsNode::stable);
  EXPECT_EQ(ebs.node_state(node(9)), EbsNode::degenerate);
  EXPECT_EQ(ebs.degenerate_count(), 1);
}

// The same configuration as rows of a 2D strip (y fully covered): E = (3,-3,1) ⊗ (0,1,0); and the
// corner of a square cut at 0.6 on its low sides, where E is the product of the 1D weights.
TEST(Ebs, Figure4Coefficients2D) {
  const Grid<2> g = grid2();
  auto strip = fill<2>(g, 10, 1.0, [](const Vec<2>& x) { return x[0] > 0.39 && x[0] < 0.80 && x[1] > 0.25 && x[1] < 1.25; });
  EbsBasis<2> ebs;
  ebs.rebuild(g, strip.x, strip.V, 0, strip.x.size());
  for (int j = 5; j <= 10; ++j) {
    const auto e3 = extension(ebs, g.node_index({3, j})), e9 = extension(ebs, g.node_index({9, j}));
    ASSERT_EQ(e3.size(), 3u) << "row " << j;
    ASSERT_EQ(e9.size(), 3u) << "row " << j;
    EXPECT_NEAR(e3.at(g.node_index({4, j})), 3.0, 1e-12);
    EXPECT_NEAR(e3.at(g.node_index({5, j})), -3.0, 1e-12);
    EXPECT_NEAR(e3.at(g.node_index({6, j})), 1.0, 1e-12);
    EXPECT_NEAR(e9.at(g.node_index({6, j})), 1.0, 1e-12);
    EXPECT_NEAR(e9.at(g.node_index({7, j})), -3.0, 1e-12);
    EXPECT_NEAR(e9.at(g.node_index({8, j})), 3.0, 1e-12);
  }
  check_properties<2>(g, ebs, sample_points(g, strip, 300, 2), 12);

  auto square = fill<2>(g, 10, 1.0, [](const Vec<2>& x) { return x[0] > 0.39 && x[0] < 0.80 && x[1] > 0.39 && x[1] < 0.80; });
  ebs.rebuild(g, square.x, square.V, 0, square.x.size());
  EXPECT_NEAR(ebs.volume_fraction(g.node_index({4, 4})), 0.36, 1e-12);
  EXPECT_EQ(ebs.node_state(g.node_index({3, 3})), EbsNode::degenerate);
  const auto ec = extension(ebs, g.node_index({3, 3}));  // Q = cell (5,5), κ = (4,4), t = (-1,-1)
  const double w[] = {3.0, -3.0, 1.0};
  ASSERT_EQ(ec.size(), 9u);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(ec.at(g.node_index({4 + i, 4 + j})), w[i] * w[j], 1e-12);
  check_properties<2>(g, ebs, sample_points(g, square, 300, 3), 13);
}

// Bodies cut arbitrarily by a rectangular-cell grid, several C_c, 2D plane strain with thickness.
TEST(Ebs, PartitionOfUnityAndReproduction2D) {
  const Grid<2> g = grid2(0.1, 0.125);
  const double t = 0.02;
  const std::vector<std::function<bool(const Vec<2>&)>> shapes = {
      [](const Vec<2>& x) { return (x - Vec<2>(0.713, 1.02)).norm() < 0.433; },  // disk
      [](const Vec<2>& x) {                                                      // annulus
        const double r = (x - Vec<2>(0.69, 0.97)).norm();
        return r > 0.21 && r < 0.57;
      },
      [](const Vec<2>& x) {  // rectangle rotated by 0.37 rad
        const Vec<2> d = x - Vec<2>(0.71, 1.0);
        const double c = std::cos(0.37), s = std::sin(0.37);
        return std::abs(c * d[0] + s * d[1]) < 0.47 && std::abs(-s * d[0] + c * d[1]) < 0.29;
      }};
  unsigned seed = 100;
  for (std::size_t k = 0; k < shapes.size(); ++k)
    for (double Cc : {0.5, 0.75, 0.9}) {
      SCOPED_TRACE(testing::Message() << "shape " << k << ", C_c = " << Cc);
      const auto b = fill<2>(g, 4, t, shapes[k]);
      EbsOptions opt;
      opt.occupation = Cc;
      opt.out_of_plane = t;
      EbsBasis<2> ebs(opt);
      ebs.rebuild(g, b.x, b.V, 0, b.x.size());
      EXPECT_GT(ebs.degenerate_count(), 0);
      EXPECT_GT(ebs.extended_cell_count(), 0);
      EXPECT_EQ(ebs.promoted_count(), 0);
      seed += 2;
      check_properties<2>(g, ebs, sample_points(g, b, 400, seed), seed + 1);
    }
}

TEST(Ebs, PartitionOfUnityAndReproduction3D) {
  const Grid<3> g(Vec<3>(-0.2, 0.0, 0.1), Vec<3>(0.1, 0.12, 0.09), {10, 10, 11});
  const auto b = fill<3>(g, 3, 1.0, [](const Vec<3>& x) { return (x - Vec<3>(0.31, 0.57, 0.58)).norm() < 0.37; });
  for (double Cc : {0.5, 0.8}) {
    SCOPED_TRACE(testing::Message() << "C_c = " << Cc);
    EbsOptions opt;
    opt.occupation = Cc;
    EbsBasis<3> ebs(opt);
    ebs.rebuild(g, b.x, b.V, 0, b.x.size());
    EXPECT_GT(ebs.degenerate_count(), 0);
    EXPECT_EQ(ebs.promoted_count(), 0);
    check_properties<3>(g, ebs, sample_points(g, b, 300, 7), 8);
  }
}

// No small cut cells -> no degenerate basis -> EBS is the plain quadratic B-spline, bit for bit.
TEST(Ebs, NoSmallCutCellsEqualsPlainBSpline) {
  const Grid<2> g = grid2();
  // (a) edges on knot-span boundaries: every material cell full (φ = 1 > C_c).
  const auto aligned = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return x[0] > 0.25 && x[0] < 0.95 && x[1] > 0.35 && x[1] < 0.85; });
  // (b) edges cutting cells at phi = 0.9, corners at 0.81, all > C_c = 0.75.
  const auto cut = fill<2>(g, 10, 1.0, [](const Vec<2>& x) { return x[0] > 0.26 && x[0] < 0.94 && x[1] > 0.36 && x[1] < 0.84; });
  // (c) a disk with C_c = 0: every cell holding material is interior.
  const auto disk = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return (x - Vec<2>(0.71, 0.83)).norm() < 0.43; });
  const std::pair<const Body<2>*, double> cases[] = {{&aligned, 0.75}, {&cut, 0.75}, {&disk, 0.0}};
  for (const auto& [b, Cc] : cases) {
    EbsOptions opt;
    opt.occupation = Cc;
    EbsBasis<2> ebs(opt);
    ebs.rebuild(g, b->x, b->V, 0, b->x.size());
    EXPECT_EQ(ebs.degenerate_count(), 0);
    EXPECT_EQ(ebs.extended_cell_count(), 0);
    expect_equals_obs<2>(g, ebs, sample_points(g, *b, 300, 5));
  }
  const Grid<3> g3(Vec<3>(0.0, 0.0, 0.0), Vec<3>(0.1, 0.1, 0.1), {8, 8, 8});
  const auto box = fill<3>(g3, 2, 1.0, [](const Vec<3>& x) { return x.minCoeff() > 0.25 && x.maxCoeff() < 0.55; });
  EbsBasis<3> ebs3;
  ebs3.rebuild(g3, box.x, box.V, 0, box.x.size());
  EXPECT_EQ(ebs3.degenerate_count(), 0);
  expect_equals_obs<3>(g3, ebs3, sample_points(g3, box, 100, 6));
}

// A body without any interior cell (a strip half a cell thick): every would-be degenerate node is
// kept as a plain B-spline, so EBS = OBS and the promotion is reported.
TEST(Ebs, ThinBodyKeepsPlainBSpline) {
  const Grid<2> g = grid2();
  const auto b = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return x[0] > 0.25 && x[0] < 1.05 && x[1] > 0.5 && x[1] < 0.55; });
  EbsBasis<2> ebs;
  ebs.rebuild(g, b.x, b.V, 0, b.x.size());
  EXPECT_EQ(ebs.degenerate_count(), 0);
  EXPECT_GT(ebs.promoted_count(), 0);
  expect_equals_obs<2>(g, ebs, b.x);
}

// Rebuilding an object for a moved body equals building a fresh one; the index-list overload equals
// the range overload; points away from the body get no function.
TEST(Ebs, RebuildIsStateless) {
  const Grid<2> g = grid2();
  const auto b1 = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return (x - Vec<2>(0.45, 0.5)).norm() < 0.3; });
  const auto b2 = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return (x - Vec<2>(0.93, 1.07)).norm() < 0.34; });
  EbsBasis<2> reused, fresh;
  reused.rebuild(g, b1.x, b1.V, 0, b1.x.size());
  reused.rebuild(g, b2.x, b2.V, 0, b2.x.size());
  std::vector<std::size_t> idx(b2.x.size());
  for (std::size_t k = 0; k < idx.size(); ++k) idx[k] = idx.size() - 1 - k;
  fresh.rebuild(g, b2.x, b2.V, idx);
  EXPECT_EQ(reused.degenerate_count(), fresh.degenerate_count());
  EXPECT_EQ(reused.stable_count(), fresh.stable_count());
  for (const Vec<2>& x : sample_points(g, b2, 300, 9)) {
    const auto a = entries(reused.evaluate(x)), c = entries(fresh.evaluate(x));
    ASSERT_EQ(a.size(), c.size());
    for (std::size_t k = 0; k < a.size(); ++k) {
      EXPECT_EQ(a[k].node, c[k].node);
      EXPECT_NEAR(a[k].S, c[k].S, 1e-15);  // same terms; only the summation order of φ may differ
    }
  }
  EXPECT_EQ(reused.evaluate(Vec<2>(0.45, 0.5)).size(), 0);  // old body's centre: nothing there now
  EXPECT_EQ(reused.evaluate(Vec<2>(-5.0, 0.5)).size(), 0);  // outside the grid
  std::size_t active = 0;
  reused.for_each_active_node([&](int n, EbsNode s) {
    ++active;
    EXPECT_EQ(reused.node_state(n), s);
  });
  EXPECT_EQ(static_cast<int>(active), reused.stable_count() + reused.degenerate_count());
}

// φ_c (eq. 19) is the body's volume in the cell, whatever the particles' positions: a rectangle of
// 2 × 2 particles per cell, stretched 2 % along x and compressed along y to J = 0.99 and shifted by
// fractions of a cell, so that columns of particles cross the cells' faces. Counting each particle
// whole in the cell of its position gave 1, 2 or 3 columns per cell, φ = 0.495 / 0.99 / 1.485 for
// cells full of material, and at C_c = 0.5 such a cell turned "boundary": its nodes became
// degenerate inside the body and the extension (3, -3, 1) cancelled the lumped mass of the stable
// node two cells in (the Neo-Hookean rings of tests/verification/test_penalty_rings.cpp blew up so).
// Bounds: volume conservation to round-off (1e-12, sums of ~1e3 terms); a full cell holds 0.99 of
// its volume, and the square particle domains (side 0.4975 h) on the 0.51 h × 0.485 h lattice leave
// gaps and overlaps of 0.0125 h, which move φ by at most ±0.025 per direction: |φ − 0.99| < 0.06
// (whole particles: ≥ 0.49 off). Lumped masses Σ_p N^e_I(x_p) Ω_p > 0 at every stable node.
TEST(Ebs, VolumeFractionIsTheCoveredVolume) {
  const Grid<2> g = grid2();
  const double t = 0.01, lx = 1.02, ly = 0.99 / 1.02;
  const auto ref = fill<2>(g, 2, t, [](const Vec<2>& x) { return x[0] > 0.3 && x[0] < 0.9 && x[1] > 0.4 && x[1] < 1.2; });
  const Vec<2> X0(0.3, 0.4);
  for (double shift : {0.0, 0.013, 0.027, 0.041, 0.062, 0.083}) {
    Body<2> b;
    for (std::size_t k = 0; k < ref.x.size(); ++k) {
      const Vec<2> d = ref.x[k] - X0;
      b.x.push_back(X0 + Vec<2>(lx * d[0] + shift, ly * d[1] + 0.5 * shift));
      b.V.push_back(0.99 * ref.V[k]);
    }
    const double xlo = X0[0] + shift, xhi = X0[0] + 0.6 * lx + shift;  // the deformed rectangle
    const double ylo = X0[1] + 0.5 * shift, yhi = X0[1] + 0.8 * ly + 0.5 * shift;
    for (double Cc : {0.5, 0.75}) {
      SCOPED_TRACE(testing::Message() << "shift " << shift << ", C_c = " << Cc);
      EbsOptions opt;
      opt.occupation = Cc;
      opt.out_of_plane = t;
      EbsBasis<2> ebs(opt);
      ebs.rebuild(g, b.x, b.V, 0, b.x.size());
      double total = 0.0, body = 0.0;
      for (double V : b.V) body += V;
      int full = 0;
      for (int n = 0; n < static_cast<int>(g.node_count()); ++n) {
        total += ebs.volume_fraction(n) * g.cell_volume() * t;
        const Vec<2> c = g.node_position(n);  // cell n = [c − h/2, c + h/2]
        if (c[0] - 0.05 > xlo && c[0] + 0.05 < xhi && c[1] - 0.05 > ylo && c[1] + 0.05 < yhi) {
          ++full;
          EXPECT_NEAR(ebs.volume_fraction(n), 0.99, 0.06) << "cell " << n;
          EXPECT_EQ(ebs.cell_state(n), EbsCell::interior) << "cell " << n;
        }
      }
      EXPECT_GE(full, 20);
      EXPECT_NEAR(total, body, 1e-12 * body);
      std::map<int, double> mass;
      for (std::size_t k = 0; k < b.x.size(); ++k)
        for (const auto& en : entries(ebs.evaluate(b.x[k]))) mass[en.node] += en.S * b.V[k];
      for (const auto& [n, m] : mass) EXPECT_GT(m, 0.0) << "lumped mass of stable node " << n;
    }
  }
}

// Eq. 22 on a nodal field: extrapolating the quadratic's B-spline coefficients from the stable
// nodes gives the exact coefficients at the degenerate nodes (degree-2 Lagrange is exact on Q2).
TEST(Ebs, ExtrapolateNodalField) {
  const Grid<2> g = grid2();
  const auto b = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return (x - Vec<2>(0.71, 0.83)).norm() < 0.43; });
  EbsBasis<2> ebs;
  ebs.rebuild(g, b.x, b.V, 0, b.x.size());
  auto c = [&](const Vec<2>& X) { return 0.3 + X[0] - 2.0 * X[1] + X[0] * X[1] + 1.5 * X[1] * X[1] * X[0] * X[0]; };
  std::vector<double> u(g.node_count(), std::nan(""));
  std::vector<Vec<2>> v(g.node_count(), Vec<2>::Constant(std::nan("")));
  ebs.for_each_active_node([&](int n, EbsNode s) {
    if (s == EbsNode::stable) {
      u[static_cast<std::size_t>(n)] = c(g.node_position(n));
      v[static_cast<std::size_t>(n)] = g.node_position(n);
    }
  });
  ebs.extrapolate(u);
  ebs.extrapolate(v);
  int checked = 0;
  ebs.for_each_active_node([&](int n, EbsNode s) {
    if (s != EbsNode::degenerate) return;
    ++checked;
    EXPECT_NEAR(u[static_cast<std::size_t>(n)], c(g.node_position(n)), 1e-10);
    EXPECT_LT((v[static_cast<std::size_t>(n)] - g.node_position(n)).norm(), 1e-10);
  });
  EXPECT_EQ(checked, ebs.degenerate_count());
}

// Gradients against central differences inside cells (N^e is a polynomial on each knot span).
TEST(Ebs, GradientMatchesFiniteDifferences) {
  const Grid<2> g = grid2();
  const auto b = fill<2>(g, 4, 1.0, [](const Vec<2>& x) { return (x - Vec<2>(0.71, 0.83)).norm() < 0.43; });
  EbsBasis<2> ebs;
  ebs.rebuild(g, b.x, b.V, 0, b.x.size());
  // N^e is quadratic on a knot span, so central differences are exact up to round-off
  // ~1e-16 |E N| / eps ~ 1e-9 (particles sit >= h/8 from span edges, far beyond eps).
  const double eps = 1e-6;
  for (const Vec<2>& x : b.x) {
    std::map<int, std::pair<double, Vec<2>>> at;
    for (const auto& en : entries(ebs.evaluate(x))) at[en.node] = {en.S, en.G};
    for (int d = 0; d < 2; ++d) {
      Vec<2> xp = x, xm = x;
      xp[d] += eps;
      xm[d] -= eps;
      std::map<int, double> sp, sm;
      for (const auto& en : entries(ebs.evaluate(xp))) sp[en.node] = en.S;
      for (const auto& en : entries(ebs.evaluate(xm))) sm[en.node] = en.S;
      for (const auto& [n, v] : at) EXPECT_NEAR(v.second[d], (sp[n] - sm[n]) / (2.0 * eps), 1e-6) << "node " << n;
    }
  }
}

TEST(Ebs, RejectsBadInput) {
  const Grid<2> g = grid2();
  EbsBasis<2> ebs;
  std::vector<Vec<2>> x = {Vec<2>(0.5, 0.5), Vec<2>(2.0, 0.5)};  // second outside [lo - h/2, hi + h/2)
  std::vector<double> V = {1e-3, 1e-3};
  EXPECT_THROW(ebs.rebuild(g, x, V, 0, 2), std::out_of_range);
  x[1] = Vec<2>(0.6, 0.5);
  V[1] = 0.0;
  EXPECT_THROW(ebs.rebuild(g, x, V, 0, 2), std::invalid_argument);
  EXPECT_THROW(ebs.rebuild(g, x, V, 0, 3), std::out_of_range);
  ebs.rebuild(g, x, V, 0, 0);  // an empty body: no functions anywhere
  EXPECT_EQ(ebs.evaluate(Vec<2>(0.5, 0.5)).size(), 0);
  EXPECT_EQ(ebs.stable_count(), 0);
}
