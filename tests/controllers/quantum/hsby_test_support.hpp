#pragma once
// Shared by the Hot Standby pair's tests: a fake remote I/O head (io_head.hpp) and a small pair
// on a scheduler. The state RAM is small (32 0x, 32 1x, 16 3x, 64 4x); the plan carries all of
// 0x/1x/3x and 4x 0-47 every scan, with the non-transfer area 4x 40-43 (40-41 reverse transfer,
// 42 the status register) and the command register at 4x 0 (400001). Scan 10 ms, transfer 2 ms.
// Both racks run the same logic: 4x 1 counts the scans (the value written by the scan that
// started at t = 10 ms * k is k + 1 when rack 0 is primary from 0 ms).
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/quantum/hsby_pair.hpp"

namespace pbvbus::quantum::hsby_test {

inline constexpr bus::Ticks kMs = bus::kTicksPerMs;
inline constexpr bus::Ticks kScan = 10 * kMs;
inline constexpr bus::Ticks kXfer = 2 * kMs;
inline constexpr std::uint32_t kReverse0 = 40, kReverse1 = 41, kStatus = 42, kNonTransferLast = 43;

class FakeHead final : public IoHead {
 public:
  void set_role(bus::Ticks now, HeadRole r) override {
    role = r;
    roles.emplace_back(now, r);
  }
  void read_inputs(StateRam& ram) override {
    ++reads;
    ram.set_input_reg(0, input);
  }
  void write_outputs(const StateRam& ram) override { outputs.push_back(ram.holding(1)); }
  bool hears_active_master(bus::Ticks) const override {
    if (hears) return *hears;
    return other != nullptr && other->role == HeadRole::Active;
  }

  HeadRole role = HeadRole::Off;
  std::vector<std::pair<bus::Ticks, HeadRole>> roles;
  int reads = 0;
  std::vector<std::uint16_t> outputs;  ///< 4x 1 at each write_outputs
  std::uint16_t input = 0;             ///< read into 3x 0 at each read_inputs
  std::optional<bool> hears;           ///< forced answer; default: the other head is Active
  const FakeHead* other = nullptr;
};

inline HsbyPairParams small_params() {
  HsbyPairParams p;
  p.sizes = StateRamSizes{32, 32, 16, 64};
  p.plan.every_scan = {{RefType::Coil0x, 0, 32},
                       {RefType::Input1x, 0, 32},
                       {RefType::Register3x, 0, 16},
                       {RefType::Register4x, 0, 48}};
  p.plan.non_transfer = NonTransferArea{40, 4};
  p.command_register = 0;
  p.scan_time = kScan;
  p.transfer_time = kXfer;
  p.update_time = 50 * kMs;
  return p;
}

inline void count_scans(StateRam& ram, bus::Ticks) {
  ram.set_holding(1, static_cast<std::uint16_t>(ram.holding(1) + 1));
}

struct Rig {
  explicit Rig(HsbyPairParams p = small_params()) : pair(sched, std::move(p), {&h0, &h1}) {
    h0.other = &h1;
    h1.other = &h0;
    pair.set_logic(count_scans);
  }
  void at(bus::Ticks t) { sched.run_until(t); }
  bool has_event(PairEventKind k, int rack = -2) const {
    for (const auto& e : pair.events())
      if (e.kind == k && (rack == -2 || e.rack == rack)) return true;
    return false;
  }

  bus::Scheduler sched;
  FakeHead h0, h1;
  HsbyPair pair;
};

}  // namespace pbvbus::quantum::hsby_test
