#include "pbvbus/simulation/report.hpp"

#include <algorithm>
#include <cstdio>
#include <ostream>

namespace pbvbus::tools {

RotationStats rotation_stats(std::vector<bus::Ticks> samples) {
  RotationStats r;
  r.count = samples.size();
  if (samples.empty()) return r;
  const auto mid = samples.begin() + static_cast<std::ptrdiff_t>((samples.size() - 1) / 2);
  std::nth_element(samples.begin(), mid, samples.end());
  r.median = *mid;
  const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end());
  r.min = *lo;
  r.max = *hi;
  return r;
}

std::string_view live_type_key(fdl::StationType t) {
  switch (t) {
    case fdl::StationType::Slave: return "slave";
    case fdl::StationType::MasterNotReady: return "master_not_ready";
    case fdl::StationType::MasterReady: return "master_ready";
    case fdl::StationType::MasterInRing: return "master_in_ring";
  }
  return "?";
}

}  // namespace pbvbus::tools
