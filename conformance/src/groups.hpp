#pragma once
// Internal: the battery's test groups (one file per group, conformance/src/group_*.cpp) and the
// helpers they share to build DP requests and read replies (conformance/src/dp_requests.cpp).
// Groups in report order; all_tests() (battery.cpp) calls these in this order.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance::detail {

// --- groups (each appends its TestCases) --------------------------------------------------
void add_startup_tests(std::vector<TestCase>& out);         // "Start-up"   STA-nn  (cbat)
void add_set_prm_tests(std::vector<TestCase>& out);         // "Set_Prm"    PRM-nn  (cbat)
void add_chk_cfg_tests(std::vector<TestCase>& out);         // "Chk_Cfg"    CFG-nn  (cbat)
void add_read_service_tests(std::vector<TestCase>& out);    // "Read services" RD-nn (cbat)
void add_fcb_tests(std::vector<TestCase>& out);             // "FCB/FCV"    FCB-nn  (cbat)
void add_global_control_tests(std::vector<TestCase>& out);  // "Global_Control" GC-nn (cgrp)
void add_set_slave_add_tests(std::vector<TestCase>& out);   // "Set_Slave_Add" ADD-nn (cgrp)
void add_timing_tests(std::vector<TestCase>& out);          // "Timing"     TIM-nn  (cgrp)
void add_interruption_tests(std::vector<TestCase>& out);    // "Interruption" INT-nn (cgrp)
void add_class2_tests(std::vector<TestCase>& out);          // "Class 2"    C2-nn   (cgrp)
void add_fail_safe_tests(std::vector<TestCase>& out);       // "Fail-safe"  FS-nn   (cgrp)
void add_dpv1_tests(std::vector<TestCase>& out);            // "DP-V1"      V1-nn   (cgrp)
void add_consistency_tests(std::vector<TestCase>& out);     // "Consistency" CON-nn (cgrp)
void add_gsd_tests(std::vector<TestCase>& out);             // "GSD"        GSD-nn  (cgrp)

// --- requests (encoded SD1/SD2 frames, SD..ED) ---------------------------------------------
/// An SRD (high priority, as DP masters send) from `sa`/`ssap` to `da`/`dsap` with `data`.
/// FCV/FCB: DP services other than Data_Exchange are sent with FCV = 0 (§D); a test that
/// exercises FCB passes them explicitly.
std::vector<std::uint8_t> srd(std::uint8_t da, std::uint8_t sa, std::optional<std::uint8_t> dsap,
                              std::optional<std::uint8_t> ssap, std::span<const std::uint8_t> data,
                              bool fcv = false, bool fcb = false);
/// An SDN (low priority) broadcast/unicast (Global_Control to address 127).
std::vector<std::uint8_t> sdn(std::uint8_t da, std::uint8_t sa, std::optional<std::uint8_t> dsap,
                              std::optional<std::uint8_t> ssap, std::span<const std::uint8_t> data);
/// FDL_Status request (SD1, FC 0x49).
std::vector<std::uint8_t> fdl_status(std::uint8_t da, std::uint8_t sa);

// --- replies --------------------------------------------------------------------------------
/// What came back, decoded: none, a bad frame, SC, or a telegram (with its FC status and DU).
struct Reply {
  enum class Kind : std::uint8_t { None, Bad, Sc, Telegram };
  Kind kind = Kind::None;
  std::uint8_t fc = 0;  ///< response FC (Telegram)
  fdl::ResponseStatus status{};
  std::vector<std::uint8_t> data;  ///< DU (Telegram)
  std::string error;               ///< why Bad
  // Additions (cbat): the reply's addressing (Telegram), to check the mirror rule of §B.2.
  std::uint8_t da = 0;
  std::uint8_t sa = 0;
  std::optional<std::uint8_t> dsap;
  std::optional<std::uint8_t> ssap;
  bool ok_with_data() const;       ///< Telegram with status DL or DH
  bool rs() const;                 ///< Telegram with status RS
  std::string describe() const;    ///< "SC", "DL 02 05 00 ...", "no reply", "bad frame: ..."
};
Reply reply_of(const Exchange& e);

/// "" when the reply of `e` (if any) mirrors its request's addresses and SAPs (§B.2), else what
/// is wrong with it, in words with the octets (conformance/src/reply_addressing.cpp).
std::string reply_addressing_fault(const Exchange& e);

}  // namespace pbvbus::conformance::detail
