// Hot-spot fates in the thermal-only continuation: dying by conduction or running away (hotspot_fates.hpp).
#include <frictherm/coupling/hotspot_fates.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace frictherm::coupling {

const char* to_string(HotSpotFate fate) {
  switch (fate) {
    case HotSpotFate::undecided: return "undecided";
    case HotSpotFate::dying: return "dying";
    case HotSpotFate::runaway: return "runaway";
  }
  return "?";
}

std::vector<std::string> hotspot_fate_columns() {
  return {"id",           "fate",          "particle_count",      "start_time",
          "initial_peak_temperature", "final_peak_temperature", "max_peak_temperature",
          "max_reaction_progress",    "decision_time", "runaway_time", "time_to_runaway"};
}

std::vector<double> hotspot_fate_row(const HotSpotFateRecord& r) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {static_cast<double>(r.id), static_cast<double>(r.fate), static_cast<double>(r.particles.size()),
          r.start_time, r.initial_peak_temperature, r.peak_temperature, r.max_peak_temperature,
          r.max_progress, r.decision_time, r.runaway_time,
          r.fate == HotSpotFate::runaway ? r.runaway_time - r.start_time : nan};
}

HotSpotFates::HotSpotFates(HotSpotFateOptions options) : opt_(options) {
  if (!(opt_.runaway_progress > 0.0 && opt_.runaway_progress <= 1.0))
    throw std::invalid_argument("HotSpotFates: runaway_progress must be in (0, 1]");
  if (!(opt_.runaway_temperature > 0.0))
    throw std::invalid_argument("HotSpotFates: runaway_temperature must be > 0");
}

void HotSpotFates::begin(const HotSpotTracker& tracker, double time) {
  records_.clear();
  started_ = true;
  last_time_ = time;
  for (const HotSpot& h : tracker.hot_spots()) {
    HotSpotFateRecord r;
    r.id = h.id;
    r.particles = h.particles;
    r.start_time = time;
    r.initial_peak_temperature = r.peak_temperature = r.max_peak_temperature = r.previous_peak_temperature =
        h.peak_temperature;
    records_.push_back(std::move(r));
  }
}

template <int Dim>
void HotSpotFates::update(const mechanics::Particles<Dim>& p, const std::vector<double>& progress,
                          const HotSpotTracker& tracker, double time, const std::vector<double>* criterion,
                          const std::vector<double>* criterion_progress) {
  if (criterion && criterion->size() != p.size()) criterion = nullptr;
  if (criterion_progress && criterion_progress->size() != p.size()) criterion_progress = nullptr;
  std::vector<HotSpotFateMeasure> measures(records_.size());
  for (std::size_t j = 0; j < records_.size(); ++j) {
    HotSpotFateMeasure& m = measures[j];
    for (std::size_t k : records_[j].particles) {
      if (k >= p.size()) continue;
      const double T = criterion ? (*criterion)[k] : p.temperature[k];
      double lam = k < progress.size() ? progress[k] : 0.0;
      if (criterion_progress) lam = std::max(lam, (*criterion_progress)[k]);
      m.add(T, lam, tracker.is_hot(k, T));
    }
  }
  decide(measures, time);
}

void HotSpotFates::decide(const std::vector<HotSpotFateMeasure>& measures, double time) {
  if (measures.size() != records_.size())
    throw std::invalid_argument("HotSpotFates::decide: " + std::to_string(measures.size()) + " measures for " +
                                std::to_string(records_.size()) + " hot spots");
  last_time_ = time;
  for (std::size_t j = 0; j < records_.size(); ++j) {
    HotSpotFateRecord& r = records_[j];
    const double peak = measures[j].peak_temperature, lam = measures[j].progress;
    const bool hot = measures[j].hot;
    r.previous_peak_temperature = r.peak_temperature;
    r.peak_temperature = peak;
    r.max_peak_temperature = std::max(r.max_peak_temperature, peak);
    r.max_progress = lam;
    if (r.fate != HotSpotFate::undecided) continue;
    if (lam >= opt_.runaway_progress || peak >= opt_.runaway_temperature) {
      r.fate = HotSpotFate::runaway;
      r.decision_time = r.runaway_time = time;
    } else if (!hot) {
      r.fate = HotSpotFate::dying;  // conduction took every particle of the spot below the threshold
      r.decision_time = time;
    }
  }
}

void HotSpotFates::finish() {
  for (HotSpotFateRecord& r : records_)
    if (r.fate == HotSpotFate::undecided && r.peak_temperature < r.initial_peak_temperature &&
        r.peak_temperature < r.previous_peak_temperature) {
      r.fate = HotSpotFate::dying;  // still above the threshold, but cooling
      r.decision_time = last_time_;
    }
}

bool HotSpotFates::all_decided() const {
  return std::all_of(records_.begin(), records_.end(),
                     [](const HotSpotFateRecord& r) { return r.fate != HotSpotFate::undecided; });
}

template void HotSpotFates::update<2>(const mechanics::Particles<2>&, const std::vector<double>&, const HotSpotTracker&,
                                      double, const std::vector<double>*, const std::vector<double>*);
template void HotSpotFates::update<3>(const mechanics::Particles<3>&, const std::vector<double>&, const HotSpotTracker&,
                                      double, const std::vector<double>*, const std::vector<double>*);

}  // namespace frictherm::coupling
