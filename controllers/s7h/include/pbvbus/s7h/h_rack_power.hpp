#pragma once
// The power of the two racks of an S7-400H (docs/h-changes.md): a redundant PS 407 10A R pair
// per rack (F1: "half of a redundant PS 407 10A R failing: no effect", 000 L2517, 001
// L8387-8390), the backup battery and the RAM test after an unbuffered POWER ON (~8 s per MB,
// 000 L640/L786, 001 L1149-1153), and a checksum error found by that power-on self-test
// (001 Table 5-6: DEFECTIVE). Sans-I/O, built on HCpuPair: the CPU is powered in the pair
// (power_on) only when its RAM test is over. The owner calls on_time() at next_deadline().
#include <array>
#include <cstdint>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

/// OB 81 power-supply error (decision, docs/h-changes.md: 001 L1484-1503 names the 24 V
/// supply failure among OB 81's causes; W#16#39xx incoming / 38xx outgoing as for 39C3/38C3).
inline constexpr std::uint16_t kPsFailureIncoming = 0x3923;
inline constexpr std::uint16_t kPsFailureOutgoing = 0x3823;

/// 000 L640: "approximately 8 seconds per megabyte of RAM" (MB = 1024 KB; exact in ticks).
constexpr bus::Ticks ram_test_time(std::uint32_t ram_kb) {
  return static_cast<bus::Ticks>(ram_kb) * 8 * bus::kTicksPerSecond / 1024;
}

struct HRackPowerParams {
  bool redundant_ps = true;                  ///< two PS 407 10A R per rack (000 L465)
  std::array<bool, 2> battery{true, true};   ///< a backup battery in rack r's PS
  std::uint32_t ram_kb = 0;                  ///< RAM the power-on test checks
};

class HRackPower {
 public:
  explicit HRackPower(HCpuPair& pair, HRackPowerParams p = {});

  /// Rack r's supply switched on (both halves). Buffered (battery and not the first power-on):
  /// the pair's power_on now; else the RAM test first: power_on at now + ram_test_time.
  void switch_on(int rack, bus::Ticks now);
  /// Both halves switched off: the pair's power_off (F1).
  void switch_off(int rack, bus::Ticks now);
  /// One half of rack r's PS fails. The other half still supplies: an entry W#16#3923 only,
  /// the CPU keeps running. No half left (or no redundant PS): the CPU fails (F1). Returns
  /// true if the CPU lost power. A half already failed: nothing.
  bool fail_half(int rack, int half, bus::Ticks now);
  /// The half is replaced: W#16#3823 if the other half had kept the CPU on; power returns
  /// (switch_on's rule) if both had failed.
  void repair_half(int rack, int half, bus::Ticks now);
  /// A checksum error found by the power-on self-test of rack r: the CPU goes DEFECTIVE when it
  /// is powered (001 Table 5-6). false unless rack r is in its RAM test.
  bool checksum_in_power_on_test(int rack, bus::Ticks now);

  /// In the RAM test: the CPU cannot be addressed over MPI, STOP flashes (000 L640).
  bool self_testing(int rack) const { return m_test_end[idx(rack)] != bus::kNever; }
  bool half_ok(int rack, int half) const { return m_half[idx(rack)][idx(half)]; }
  bus::Ticks next_deadline() const;
  void on_time(bus::Ticks now);

 private:
  static std::size_t idx(int r);
  bool supplied(int r) const;
  HCpuPair& m_pair;
  HRackPowerParams m_p;
  std::array<std::array<bool, 2>, 2> m_half{{{true, true}, {true, true}}};
  std::array<bool, 2> m_on{false, false};        ///< the supply is switched on
  std::array<bool, 2> m_ever_on{false, false};   ///< a first power-on was done
  std::array<bus::Ticks, 2> m_test_end{bus::kNever, bus::kNever};
  std::array<bool, 2> m_checksum{false, false};  ///< found by the running power-on test
};

}  // namespace pbvbus::devices
