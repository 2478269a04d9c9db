#pragma once
// What each dataset of a run file holds: SI units (temperatures in K) and a readable name, written by
// H5Output as the attributes `units` and `long_name` of every series and table column, snapshot
// field and /meta entry (docs/output.md, "Units and names"). Units follow the UDUNITS spelling
// ParaView, xarray and pint read: "m", "m/s", "kg m/s", "Pa", "J", "W", "K", "s", "m^2"; "1" is a
// pure number or count, "" marks text.
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace frictherm::coupling {

struct OutputQuantity {
  std::string units;      // SI; "1" for counts and pure numbers, "" for text
  std::string long_name;  // e.g. "kinetic energy", "mean temperature of body block"
  /// Categorical integer columns (CF conventions flag_values / flag_meanings): code and name,
  /// e.g. the hot-spot fates 0 undecided, 1 dying, 2 runaway.
  std::vector<std::pair<int, std::string>> flags;
};

/// The quantity behind a series or table column, snapshot field or /meta key `name` of a dim-D
/// run. Per-body and per-pair columns (`mean_temperature.block`, `friction_work_first.base.block`)
/// take the units of the part before the first '.', and the rest names the body or pair. std::nullopt
/// for a name the catalogue does not know (then no attributes are written, and the ctest
/// python.output_units fails: add the name in output_quantities.cpp).
std::optional<OutputQuantity> output_quantity(const std::string& name, int dim);

}  // namespace frictherm::coupling
