#pragma once
// What HSystemModel measured of one update of the CPU pair (400H; docs/h-system.md "The
// H-system model", "Update phases on the I/O"): the pair's phase times and what the I/O saw.
#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

struct UpdateMeasure {
  bus::Ticks t1 = 0;  ///< the standby enters UPDATE (from the pair; t3 = t1 in this model)
  bus::Ticks t3 = 0;  ///< start of the no-I/O window
  bus::Ticks t4 = 0;  ///< start of the output hold (t5 - T_PH)
  bus::Ticks t5 = 0;  ///< Redundant mode / the swap, or the abort
  int standby = -1;   ///< the rack that was updated
  bus::Ticks last_scan_before = bus::kNever;      ///< the last OB 1 started before t3
  bus::Ticks first_scan_after = bus::kNever;      ///< the first OB 1 at/after t5 (or the abort)
  bus::Ticks standby_operate_from = bus::kNever;  ///< the standby's side Operate (= t4)
  bool aborted = false;
  bool done = false;  ///< t5 or the abort has passed

  /// Measured no-I/O window: first OB 1 after − last OB 1 before (kNever if either is missing).
  /// At most W + one scan time: the last scan before t3 started > t3 − scan_time, and the
  /// first one after runs at t5 itself (a late OB 1 starts at once).
  bus::Ticks no_io_window() const {
    if (last_scan_before == bus::kNever || first_scan_after == bus::kNever) return bus::kNever;
    return first_scan_after - last_scan_before;
  }
  /// Output-hold window: t5 − standby side Operate (= T_PH); kNever if the side never operated.
  bus::Ticks output_hold_window() const {
    if (standby_operate_from == bus::kNever || !done) return bus::kNever;
    return t5 - standby_operate_from;
  }
};

}  // namespace pbvbus::devices
