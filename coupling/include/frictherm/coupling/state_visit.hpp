#pragma once
// Helpers for visit_state members (checkpoints, issue 17): a visitor v(name, member) takes
// std::vector<T> (T double, int32, long, uint64 or fixed-size Eigen) and double, long, bool;
// `std::decay_t<V>::reading` says whether it restores. These convert the members it does not take.
#include <Eigen/Core>

#include <cstddef>
#include <type_traits>
#include <vector>

namespace frictherm::coupling::state {

template <class V> constexpr bool reading() { return std::decay_t<V>::reading; }

/// Eigen::VectorXd as a vector of doubles.
template <class V> void vector(V&& v, const char* name, Eigen::VectorXd& x) {
  std::vector<double> tmp;
  if constexpr (!reading<V>()) tmp.assign(x.data(), x.data() + x.size());
  v(name, tmp);
  if constexpr (reading<V>()) x = Eigen::Map<const Eigen::VectorXd>(tmp.data(), static_cast<Eigen::Index>(tmp.size()));
}

/// A vector of integers of another type (size_t, int, unsigned char) as longs.
template <class V, class I> void integers(V&& v, const char* name, std::vector<I>& x) {
  std::vector<long> tmp;
  if constexpr (!reading<V>()) tmp.assign(x.begin(), x.end());
  v(name, tmp);
  if constexpr (reading<V>()) {
    x.resize(tmp.size());
    for (std::size_t i = 0; i < tmp.size(); ++i) x[i] = static_cast<I>(tmp[i]);
  }
}

/// One integer of another type as a long.
template <class V, class I> void integer(V&& v, const char* name, I& x) {
  long tmp = static_cast<long>(x);
  v(name, tmp);
  if constexpr (reading<V>()) x = static_cast<I>(tmp);
}

}  // namespace frictherm::coupling::state
