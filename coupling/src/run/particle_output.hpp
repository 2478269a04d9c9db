#pragma once
// Per-particle output written once for the serial run (runner_output.cpp) and the decomposed run
// (distributed_run/decomposed_run_output.cpp, issue 32): each body's mass-weighted sums behind the
// series' mean_temperature, mean_displacement and mean_velocity columns (a decomposed run sums its
// ranks' particles with one reduction of flat()), and the snapshot fields in the shapes VTK expects.
#include <frictherm/mechanics/types.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace frictherm::coupling::detail {

/// Σ m_p, Σ m_p T_p, Σ m_p (x_p − X_p) and Σ m_p v_p over each body's particles.
template <int Dim>
struct BodySums {
  explicit BodySums(std::size_t bodies)
      : m(bodies, 0.0), mT(bodies, 0.0), mu(bodies, mechanics::Vec<Dim>::Zero()), mv(bodies, mechanics::Vec<Dim>::Zero()) {}

  void add(std::size_t b, double mass, double T, const mechanics::Vec<Dim>& x, const mechanics::Vec<Dim>& X,
           const mechanics::Vec<Dim>& v) {
    m[b] += mass;
    mT[b] += mass * T;
    mu[b] += mass * (x - X);
    mv[b] += mass * v;
  }

  /// The sums as (2 + 2 Dim) values per body, and back (an MPI_SUM of flat() over ranks).
  std::vector<double> flat() const {
    std::vector<double> f;
    for (std::size_t b = 0; b < m.size(); ++b) {
      f.push_back(m[b]);
      f.push_back(mT[b]);
      for (int d = 0; d < Dim; ++d) f.push_back(mu[b][d]);
      for (int d = 0; d < Dim; ++d) f.push_back(mv[b][d]);
    }
    return f;
  }
  void assign(const std::vector<double>& f) {
    std::size_t i = 0;
    for (std::size_t b = 0; b < m.size(); ++b) {
      m[b] = f[i++];
      mT[b] = f[i++];
      for (int d = 0; d < Dim; ++d) mu[b][d] = f[i++];
      for (int d = 0; d < Dim; ++d) mv[b][d] = f[i++];
    }
  }

  /// mean_temperature.<body> (K), mean_displacement_x.<body>, ... (m) per body: NaN for a body without mass.
  void append_means(std::vector<double>& row) const {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t b = 0; b < m.size(); ++b) {
      row.push_back(m[b] > 0.0 ? mT[b] / m[b] : nan);
      for (int d = 0; d < Dim; ++d) row.push_back(m[b] > 0.0 ? mu[b][d] / m[b] : nan);
    }
  }
  /// mean_velocity_x.<body>, ... (m/s) per body (what the sliding-block charts plot): 0 without mass.
  void append_velocities(std::vector<double>& row) const {
    for (std::size_t b = 0; b < mv.size(); ++b)
      for (int d = 0; d < Dim; ++d) row.push_back(m[b] > 0.0 ? mv[b][d] / m[b] : 0.0);
  }

  std::vector<double> m, mT;
  std::vector<mechanics::Vec<Dim>> mu, mv;
};

/// One process's particles as the snapshot fields read them (n each; stress_zz may be shorter:
/// its missing entries are 0).
template <int Dim>
struct ParticleArrays {
  std::size_t n = 0;
  const mechanics::Vec<Dim>* position = nullptr;
  const mechanics::Vec<Dim>* velocity = nullptr;
  const mechanics::Vec<Dim>* initial_position = nullptr;
  const mechanics::Mat<Dim>* stress = nullptr;
  const std::vector<double>* stress_zz = nullptr;
  const std::vector<double>* mass = nullptr;
  const std::vector<double>* volume = nullptr;
  const std::vector<double>* temperature = nullptr;
  const std::int32_t* material = nullptr;
  const std::int32_t* body = nullptr;
};

/// Writes the named fields into `out` (H5Output, or the decomposed run's rank snapshot), which has
/// snapshot_field(name, const double*, n, components) and snapshot_field(name, const int32_t*, n).
/// Shapes as VTK (ParaView's XDMF reader, Warp By Vector, Calculator) expects: vectors are (n, 3) and
/// the stress is the full 3x3 tensor (n, 9, row-major) in 2D as in 3D. In 2D the z components of
/// vectors are 0 and the stress's zz entry is the out-of-plane stress (stress_zz, 0 in plane stress),
/// its xz, yz, zx, zy entries 0. position keeps (n, Dim): it is the XDMF geometry (XY in 2D), which
/// VTK pads itself. docs/output.md describes every array.
template <int Dim, class Out>
void write_particle_fields(Out& out, const ParticleArrays<Dim>& p, const std::vector<std::string>& fields) {
  const std::size_t n = p.n;
  std::vector<double> buf;
  auto vectors = [&](const std::string& name, auto&& get) {
    buf.assign(n * 3, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      const mechanics::Vec<Dim> v = get(k);
      for (int d = 0; d < Dim; ++d) buf[k * 3 + static_cast<std::size_t>(d)] = v[d];
    }
    out.snapshot_field(name, buf.data(), n, 3);
  };
  auto scalars = [&](const std::string& name, const std::vector<double>& v) { out.snapshot_field(name, v.data(), n, 1); };
  for (const std::string& f : fields) {
    if (f == "position") {
      buf.resize(n * Dim);
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < Dim; ++d) buf[k * Dim + static_cast<std::size_t>(d)] = p.position[k][d];
      out.snapshot_field(f, buf.data(), n, Dim);
    } else if (f == "velocity") {
      vectors(f, [&](std::size_t k) { return p.velocity[k]; });
    } else if (f == "displacement") {
      vectors(f, [&](std::size_t k) { return mechanics::Vec<Dim>(p.position[k] - p.initial_position[k]); });
      // With it the reference positions X (dim columns), the geometry of RUN_reference.xdmf: Warp By
      // Vector on `displacement` there draws x = X + u (docs/output.md "In ParaView").
      buf.resize(n * Dim);
      for (std::size_t k = 0; k < n; ++k)
        for (int d = 0; d < Dim; ++d) buf[k * Dim + static_cast<std::size_t>(d)] = p.initial_position[k][d];
      out.snapshot_field("initial_position", buf.data(), n, Dim);
    } else if (f == "stress") {
      buf.assign(n * 9, 0.0);
      for (std::size_t k = 0; k < n; ++k) {
        double* s = &buf[k * 9];
        for (int i = 0; i < Dim; ++i)
          for (int j = 0; j < Dim; ++j) s[3 * i + j] = p.stress[k](i, j);
        if (Dim == 2 && k < p.stress_zz->size()) s[8] = (*p.stress_zz)[k];
      }
      out.snapshot_field(f, buf.data(), n, 9);
    } else if (f == "stress_zz") {
      scalars(f, *p.stress_zz);
    } else if (f == "mass") {
      scalars(f, *p.mass);
    } else if (f == "volume") {
      scalars(f, *p.volume);
    } else if (f == "temperature") {
      scalars(f, *p.temperature);
    } else if (f == "material") {
      out.snapshot_field(f, p.material, n);
    } else if (f == "body") {
      out.snapshot_field(f, p.body, n);
    }
  }
}

}  // namespace frictherm::coupling::detail
