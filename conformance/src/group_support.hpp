#pragma once
// Internal: what the nine groups of branch cgrp share (Global_Control, Set_Slave_Add, Timing,
// Interruption, Class 2, Fail-safe, DP-V1, Consistency, GSD) on top of groups.hpp.
//
// `Run` is one test's conversation with the device under test: it opens a session, sends the DP
// services (encoded by groups.hpp's srd()/sdn()), decodes the answers, and on destruction copies
// the session's transcript into the result as evidence. A test sets its verdict through pass(),
// fail() or na() and returns.
//
// Decisions (also in docs/conformance.md, "Groups (cgrp)"):
// - Data_Exchange polls are spaced like cbat's steps.hpp: no earlier than
//   TestBusOptions::dx_interval (10 x Min_Slave_Intervall) after the end of the same master's
//   previous Data_Exchange, unless the test gives its own start time (TIM-02, TIM-03): so only
//   the Timing group depends on how fast the slave may be polled.
// - Every request of these groups goes with FCV = 0 (Data_Exchange included): the responder
//   executes each one as a new request (§C.6: FCV = 0 means "FCB not valid"), so no verdict here
//   can hinge on the FCB state, which is the FCB/FCV group's business.
// - DP-V0 services come from SSAP 62 (MS0) whoever sends them — the class-1 tester or the
//   class-2 master at address 2 (§D.1). MSAC_C1 Read/Write go from SSAP 51 to DSAP 51, Alarm_Ack
//   from SSAP 51 to DSAP 50.
// - The start-up is the master's sequence of §D.9: Slave_Diag, Set_Prm, Chk_Cfg, Slave_Diag; it
//   succeeds when Set_Prm and Chk_Cfg are acknowledged (SC, or a response without data) and the
//   last diagnosis says "ready for data exchange" (octet 1 & 0x47 = 0, octet 2 Prm_Req = 0), as
//   a master judges it.
// - Evidence: the exchanges of every session the test opened (its own, from the session's opening
//   on: an outside slave's start-state check included, earlier tests' excluded), but at most 64 exchanges
//   (the first 24 and the last 40; the message says how many were left out) — a test that loops
//   stops at the first telegram that decides against the DUT, so that one is among the last.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "groups.hpp"
#include "steps.hpp"  // hex()

#include "pbvbus/conformance/battery.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::conformance::detail {

/// The standard part of a Slave_Diag answer, if it is a telegram with at least six octets.
std::optional<dp::StandardDiag> standard_diag(const Reply& r);
/// Ready for data exchange as a master judges it (§D.4): octet 1 & (0x01|0x02|0x04|0x40) = 0 and
/// octet 2 Prm_Req = 0.
bool diag_ready(const dp::StandardDiag& d);

/// Back in Wait_Prm as the other groups judge it: Station_Not_Ready and no master (octet 4 FF).
/// Prm_Req and the ident are the Start-up and GSD groups' rules (so that their mutants fail
/// there, not here), except where a test says otherwise.
bool wait_prm_diag(const dp::StandardDiag& d);

/// A Data_Exchange answered as a slave in data exchange answers: with data, or SC when the
/// slave has no inputs.
bool data_answer(const TestContext& ctx, const Reply& r);

/// White box: the outputs the model's application holds now (what drives the process), in
/// Data_Exchange order.
std::vector<std::uint8_t> applied_outputs(devices::SlaveModel& model);
/// "the outputs the slave applies read 11 11 (expected 00 00)" style text.
std::string outputs_text(std::span<const std::uint8_t> got, std::span<const std::uint8_t> want);

/// Address of the class-2 master the groups play (SA 2, §D.1 MS0 SSAP 62).
inline constexpr std::uint8_t kClass2Master = 2;

/// Which test cases a group builds: a compact way to fill a TestCase.
TestCase make_case(std::string id, std::string group, std::string name, std::string requirement,
                   std::vector<devices::SlaveMutant> targets,
                   std::function<void(TestContext&, TestResult&)> run);

class Run {
 public:
  /// Opens a session at `baud` (the spec's main baud if unset). If that fails the result is an
  /// Error with the reason (the test's starting state could not be established) and the Run is
  /// false.
  Run(TestContext& ctx, TestResult& result, std::optional<bus::Baud> baud = std::nullopt);
  ~Run();
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  explicit operator bool() const { return m_session != nullptr; }
  TestContext& ctx() { return m_ctx; }
  Session& session() { return *m_session; }
  TestBus& bus() { return m_session->bus(); }
  devices::SlaveModel* model() { return m_session->model(); }
  std::uint8_t tester() const { return m_tester; }
  /// The DUT's address as the test knows it (spec address; changed by set_dut()).
  std::uint8_t dut() const { return m_dut; }
  void set_dut(std::uint8_t a) { m_dut = a; }
  /// Bit times at the session's baud → ticks.
  bus::Ticks bits(std::int64_t n) const;
  /// Closes this session (its transcript goes into the evidence) and opens another at `baud`;
  /// false with `error` when the DUT cannot run there (the old session is closed either way).
  bool reopen(std::optional<bus::Baud> baud, std::string& error);

  // --- DP-V0 services (SRD high, FCV = 0) from `sa` (the tester unless given) to dut(). ----
  Exchange slave_diag(std::string note = "Slave_Diag", std::optional<std::uint8_t> sa = {});
  Exchange set_prm(std::span<const std::uint8_t> du, std::string note = "Set_Prm",
                   std::optional<std::uint8_t> sa = {});
  Exchange chk_cfg(std::span<const std::uint8_t> du, std::string note = "Chk_Cfg",
                   std::optional<std::uint8_t> sa = {});
  Exchange get_cfg(std::string note = "Get_Cfg", std::optional<std::uint8_t> sa = {});
  Exchange rd_inp(std::string note = "Rd_Inp", std::optional<std::uint8_t> sa = {});
  Exchange rd_outp(std::string note = "Rd_Outp", std::optional<std::uint8_t> sa = {});
  Exchange data_exchange(std::span<const std::uint8_t> outputs, std::string note = "Data_Exchange",
                         std::optional<bus::Ticks> not_before = {},
                         std::optional<std::uint8_t> sa = {});
  /// Any other DP-V0 service (SRD from SSAP 62 to `dsap`) from the tester, at `not_before`.
  Exchange service(std::uint8_t dsap, std::span<const std::uint8_t> du, std::string note,
                   std::optional<bus::Ticks> not_before = {});
  /// Broadcast Global_Control (SDN to 127, DSAP 58, SSAP 62) from the tester.
  Exchange global_control(std::uint8_t control_command, std::uint8_t group_select,
                          std::string note = "Global_Control");
  /// Set_Slave_Add (SAP 55) to `da`: New_Slave_Address, Ident_Number, No_Add_Chg.
  Exchange set_slave_add(std::uint8_t da, std::uint8_t new_address, std::uint16_t ident,
                         bool no_add_chg, std::string note = "Set_Slave_Add");
  /// MSAC_C1 to SAP 51 (Read/Write) or SAP 50 (Alarm_Ack), from SSAP 51 of the tester.
  Exchange c1(std::uint8_t dsap, std::span<const std::uint8_t> pdu, std::string note);

  /// Slave_Diag decoded; nullopt (and `why`) when the answer is not a diagnosis.
  std::optional<dp::StandardDiag> diag(std::string& why, std::string note = "Slave_Diag",
                                       std::optional<std::uint8_t> sa = {});

  /// The start-up of §D.9 with `params` (the context's unless given) from `sa` (the tester unless
  /// given). False with the reason in `why`.
  bool start_up(std::string& why, const dp::SlaveParams* params = nullptr,
                std::optional<std::uint8_t> sa = {});
  /// Outputs of the DUT's configuration, every octet `fill`.
  std::vector<std::uint8_t> outputs(std::uint8_t fill) const;

  // --- Verdicts (the last call wins). ---
  void pass(std::string message);
  void fail(std::string message);
  void na(std::string message);
  /// The test's precondition could not be established: its rule was not tested.
  void error(std::string message);
  /// error() for a failed start-up with `with` (the GSD's parameters unless said: the test's
  /// precondition).
  void not_ready(const std::string& why, const std::string& with = "the GSD's parameters");

 private:
  void collect();

  TestContext& m_ctx;
  TestResult& m_result;
  std::unique_ptr<Session> m_session;
  std::vector<Exchange> m_evidence;
  std::uint8_t m_tester = 1;
  std::uint8_t m_dut = 0;
};

}  // namespace pbvbus::conformance::detail
