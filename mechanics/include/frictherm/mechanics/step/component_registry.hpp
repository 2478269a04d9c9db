#pragma once
// What the step's component registries share (issue 32; docs/step.md): the contact methods
// (contact_methods/registry.cpp), the loads (loads/registry.cpp), the grid-velocity filters
// (filters/registry.cpp) and the rigid drivers (rigids/registry.cpp) each list their components'
// selections, functions that return the component for a simulation that uses it or null; a new
// component is its file plus one line in its registry.
#include <cstddef>
#include <vector>

namespace frictherm::mechanics {

template <int Dim>
class Simulation;

/// The components whose selection in `registry` returns one for `sim`, in the registry's order.
template <class Component, int Dim, std::size_t N>
std::vector<const Component*> select_components(const Component* (*const (&registry)[N])(Simulation<Dim>&),
                                                Simulation<Dim>& sim) {
  std::vector<const Component*> selected;
  for (const auto select : registry)
    if (const Component* c = select(sim)) selected.push_back(c);
  return selected;
}

}  // namespace frictherm::mechanics

/// In a component's file: its selection `select_fn` (the name its registry lists) for 2D and 3D, from
/// the static `Impl<Dim>::select(Simulation<Dim>&)`, which returns the component or null.
#define FRICTHERM_STEP_COMPONENT_SELECTION(Interface, select_fn, Impl)                                 \
  template <int Dim>                                                                                  \
  const Interface<Dim>* select_fn(Simulation<Dim>& sim) { return Impl<Dim>::select(sim); }            \
  template const Interface<2>* select_fn(Simulation<2>&);                                             \
  template const Interface<3>* select_fn(Simulation<3>&);
