#pragma once
// Internal: how the battery chooses its times (timing_plan.cpp explains the numbers).

#include <cstddef>
#include <cstdint>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/dp/master.hpp"

namespace pbvbus::conformance::detail {

/// The run's TimingPlan at `baud` for the DUT's parameters `p` and I/O lengths; `profile_tsl` is
/// the slot time of the DP profile with the GSD's MaxTsdr at that baud.
TimingPlan plan_timing(const DutSpec& spec, const dp::SlaveParams& p, std::size_t input_len,
                       std::size_t output_len, bus::Baud baud, std::uint32_t profile_tsl,
                       bus::Ticks dx_interval);

}  // namespace pbvbus::conformance::detail
