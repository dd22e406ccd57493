#pragma once
// Internal: the DP services as the battery's tests send them, over a Session (conformance/src/
// steps.cpp). Every call is one request through TestBus::request() with a note, so the evidence
// of a test reads as a protocol trace. Shared by every group (cbat's and cgrp's).
//
// Decisions:
// - DP-V0 services go as SRD high from SSAP 62 (MS0) to the service's SAP, with FCV = FCB = 0
//   (the frame count bit is exercised only by the FCB group, which passes it explicitly):
//   a conformant slave executes every such frame (§C.6), so the tests do not depend on FCB
//   bookkeeping they do not check.
// - `sa` = the tester's address unless a test plays another master.
// - Data_Exchange polls of one master are spaced by TestBusOptions::dx_interval, which the
//   battery sets to 10 × the GSD's Min_Slave_Intervall: a relaxed DP cycle (a master with ten
//   such slaves), so that only the Timing group's Min_Slave_Interval test depends on how fast
//   the slave may be polled.
// - start_up() is what a class-1 master does (§D.9): Slave_Diag, Set_Prm, Chk_Cfg, Slave_Diag;
//   it returns "" when the last diagnosis says "ready for data exchange" (S1's rule, §D.4), else
//   what went wrong, in words with the bytes.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "groups.hpp"
#include "pbvbus/dp/master.hpp"

namespace pbvbus::conformance::detail {

/// The FDL address the tester uses as a second master (locking, class-2 reads).
inline constexpr std::uint8_t kOtherMaster = 2;

/// Octets as "02 05 00 FF 0A 01".
std::string hex(std::span<const std::uint8_t> b);

/// The tester's own FDL address on this session.
std::uint8_t tester_address(Session& s);

/// One SRD request and its decoded reply (the exchange stays in the bus transcript).
Reply service(Session& s, std::optional<std::uint8_t> dsap, std::span<const std::uint8_t> du,
              std::string note, std::optional<std::uint8_t> sa = std::nullopt, bool fcv = false,
              bool fcb = false);

Reply slave_diag(Session& s, std::string note = "Slave_Diag",
                 std::optional<std::uint8_t> sa = std::nullopt);
Reply set_prm(Session& s, std::span<const std::uint8_t> du, std::string note = "Set_Prm",
              std::optional<std::uint8_t> sa = std::nullopt);
Reply chk_cfg(Session& s, std::span<const std::uint8_t> du, std::string note = "Chk_Cfg",
              std::optional<std::uint8_t> sa = std::nullopt);
Reply get_cfg(Session& s, std::string note = "Get_Cfg", std::optional<std::uint8_t> sa = std::nullopt);
Reply rd_inp(Session& s, std::string note = "Rd_Inp", std::optional<std::uint8_t> sa = std::nullopt);
Reply rd_outp(Session& s, std::string note = "Rd_Outp", std::optional<std::uint8_t> sa = std::nullopt);
/// Data_Exchange (default SAP, no DSAP/SSAP) with `outputs`; at least
/// TestBusOptions::dx_interval after the end of the previous Data_Exchange from the same master.
Reply data_exchange(Session& s, std::span<const std::uint8_t> outputs,
                    std::string note = "Data_Exchange", std::optional<std::uint8_t> sa = std::nullopt,
                    bool fcv = false, bool fcb = false);
/// Global_Control (SDN to `da`, default broadcast 127, DSAP 58, SSAP 62): no reply.
void global_control(Session& s, std::uint8_t control, std::uint8_t group_select,
                    std::string note = "Global_Control", std::uint8_t da = 127,
                    std::optional<std::uint8_t> sa = std::nullopt);

/// The Set_Prm DU of `p` (p.set_prm_du()).
std::vector<std::uint8_t> prm_du(const dp::SlaveParams& p);
/// The Chk_Cfg DU of `p`.
std::vector<std::uint8_t> cfg_du(const dp::SlaveParams& p);

/// Slave_Diag → Set_Prm(params) → Chk_Cfg → Slave_Diag; "" when the DUT is ready for data
/// exchange, else why not. `params` defaults to ctx.params().
std::string start_up(Session& s, TestContext& ctx,
                     const std::optional<dp::SlaveParams>& params = std::nullopt);

/// Output octets for a Data_Exchange: `len` octets seeded by `seed` (never all zero when len > 0).
std::vector<std::uint8_t> output_pattern(std::size_t len, std::uint8_t seed);

/// The 6 standard diagnosis octets the battery expects (§D.4).
std::vector<std::uint8_t> expected_diag(std::uint8_t status1, std::uint8_t status2,
                                        std::uint8_t status3, std::uint8_t master_add,
                                        std::uint16_t ident);
/// "" if `r` is a DL/DH telegram whose first octets are `expected`, else what came instead.
/// `exact` = the whole DU must be `expected` (else a prefix, e.g. diagnosis with ext blocks).
std::string expect_data(const Reply& r, std::span<const std::uint8_t> expected, bool exact = true);
/// "" if `r` is SC, else what came.
std::string expect_sc(const Reply& r);
/// "" if `r` is RS, else what came.
std::string expect_rs(const Reply& r);

/// What a test expects of the 6 standard diagnosis octets (§D.4): the bits under each mask must
/// equal the value; Master_Add and the ident are compared when set.
struct DiagExpect {
  std::uint8_t s1_mask = 0, s1 = 0;
  std::uint8_t s2_mask = 0, s2 = 0;
  std::optional<std::uint8_t> master;
  std::optional<std::uint16_t> ident;
};
/// "" if `r` is diagnosis data meeting `e`, else what came (the octets in hex).
std::string check_diag(const Reply& r, const DiagExpect& e);
/// "" if `r` is exactly the 6 octets `expected` — where the reply is longer (extended
/// diagnosis blocks follow) the Ext_Diag bit (octet 1 bit 3) and Ext_Diag_Overflow (octet 3
/// bit 7) are not compared, the other 46 bits are.
std::string expect_std_diag(const Reply& r, std::span<const std::uint8_t> expected);

/// Opens a session (main baud unless given); on failure `r` is an Error (its starting state could
/// not be established) and nullptr is returned.
std::unique_ptr<Session> open_session(TestContext& ctx, TestResult& r,
                                      std::optional<bus::Baud> baud = std::nullopt);
/// The watchdog time of `p` (TWD = WD_Fact_1 × WD_Fact_2 × 10 ms, or × 1 ms with WD_Base_1ms in
/// DPV1_Status_1 of a DP-V1 Set_Prm), in ticks.
bus::Ticks watchdog_time(const dp::SlaveParams& p);
/// `p` with the WD factors of the run's watchdog tests (TimingPlan::twd, rounded up to what
/// WD_Fact_1 × WD_Fact_2 × base can say); watchdog_time() of the result is the exact TWD.
dp::SlaveParams with_plan_watchdog(const TestContext& ctx, dp::SlaveParams p);

/// Result helpers: set verdict + message (keep the first failure's message).
void fail(TestResult& r, const std::string& why);
void not_applicable(TestResult& r, const std::string& why);
/// Error: the test's precondition could not be established (keeps an earlier Fail or Error).
void error(TestResult& r, const std::string& why);
/// For start_up()'s result as a test's precondition: an Error when `start_up_why` is not empty;
/// returns whether it was.
bool precondition(TestResult& r, const std::string& start_up_why,
                  const std::string& with = "the GSD's parameters");
/// Fails `r` with `what: why` when `why` is not empty; returns whether it failed.
bool check(TestResult& r, const std::string& what, const std::string& why);

}  // namespace pbvbus::conformance::detail
