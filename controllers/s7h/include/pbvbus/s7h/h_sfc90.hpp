#pragma once
// SFC 90 "H_CTRL" (docs/h-sfc90.md): the user program's control of the H system's link-up,
// update and cyclic self-test. 000 L564/L803/L1281 and 001 L986/L4074/L4733-4760: "Using
// system function SFC 90 H_CTRL you can inhibit and re-enable link-up and updates ... You can
// also affect the scope and execution of the cyclical self-test ... remove and replace
// individual components of the test ... certain test components can be explicitly called and
// started"; 001 L5301 / 000 L1629: "delay the update via SFC 90 and do not release it again
// until a state of lesser communication or interrupt load occurs".
//
// The seeds point to the SFC reference ("System Software for S7-300/400, System and Standard
// Functions") for MODE/SUBMODE and RET_VAL and give neither; the numbering below is that
// reference's as an S7 engineer uses it (decision, docs/h-sfc90.md "MODE and SUBMODE"):
//
//   MODE  SUBMODE  job
//   0     0        disable link-up          (a standby's start request waits in STOP)
//   1     0        re-enable link-up        (a waiting request links up now)
//   3     0        disable update           (a standby that finished its link-up waits in it)
//   4     0        re-enable update         (a waiting standby enters UPDATE now, t1)
//   10    0..4,FF  remove a component from the cyclic self-test (FF: every component)
//   11    0..4,FF  add it again
//   12    0..4,FF  start it now (once)
//
// RET_VAL: W#16#0000 done; W#16#0001 nothing to do, the state was already the requested one
// (decision: a positive code, the job is not wrong); W#16#8090 MODE invalid; W#16#8091 SUBMODE
// invalid for that MODE; W#16#80C1 not on this system (the S7-1500R/H profile: the 002 excerpt
// has no H_CTRL; decision).
//
// Sans-I/O: decode_h_ctrl() only decodes; h_ctrl() applies a decoded job to the pair's blocks
// (HCpuPair::set_link_up_enabled / set_update_enabled) and to an HSelfTestControl.
#include <array>
#include <cstdint>
#include <string_view>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

class HCpuPair;

inline constexpr std::uint16_t kHCtrlOk = 0x0000;
inline constexpr std::uint16_t kHCtrlAlready = 0x0001;
inline constexpr std::uint16_t kHCtrlBadMode = 0x8090;
inline constexpr std::uint16_t kHCtrlBadSubmode = 0x8091;
inline constexpr std::uint16_t kHCtrlNotAvailable = 0x80C1;

enum class HCtrlJob : std::uint8_t {
  None,  ///< not decodable (RET_VAL says why)
  DisableLinkUp,
  EnableLinkUp,
  DisableUpdate,
  EnableUpdate,
  RemoveTest,
  AddTest,
  StartTest,
};
std::string_view to_string(HCtrlJob j);

/// The components of the cyclic self-test that SUBMODE 0..4 names (our names; the seeds only
/// say "individual components").
enum class SelfTestComponent : std::uint8_t { Ram, Alu, OsChecksum, CodeChecksum, SyncCompare };
inline constexpr int kSelfTestComponents = 5;
inline constexpr std::uint8_t kAllComponents = 0xFF;
std::string_view to_string(SelfTestComponent c);

struct HCtrlDecoded {
  HCtrlJob job = HCtrlJob::None;
  std::uint16_t ret_val = kHCtrlOk;  ///< 8090/8091 when job == None
  int component = -1;                ///< 0..4, or -1 = every component (SUBMODE FF)
};

/// MODE/SUBMODE → the job, or RET_VAL W#16#8090 / 8091.
HCtrlDecoded decode_h_ctrl(std::uint8_t mode, std::uint8_t submode);

/// Which components of the cyclic self-test are in it, and how often each was started by
/// MODE 12 (the self-test itself is not modelled: docs/h-system.md "Not done yet").
class HSelfTestControl {
 public:
  bool included(SelfTestComponent c) const { return m_in[static_cast<std::size_t>(c)]; }
  int started(SelfTestComponent c) const { return m_started[static_cast<std::size_t>(c)]; }
  /// MODE 10/11: false if every named component already was so.
  bool set_included(int component, bool in);
  void start(int component);

 private:
  std::array<bool, kSelfTestComponents> m_in{true, true, true, true, true};
  std::array<int, kSelfTestComponents> m_started{};
};

/// SFC 90 called at `now`: decodes, applies and returns RET_VAL (kHCtrlOk, kHCtrlAlready,
/// 8090, 8091, 80C1). The pair's deadlines due at `now` run first (HCpuPair's rule).
std::uint16_t h_ctrl(HCpuPair& pair, HSelfTestControl& self_test, std::uint8_t mode,
                     std::uint8_t submode, bus::Ticks now);

}  // namespace pbvbus::devices
