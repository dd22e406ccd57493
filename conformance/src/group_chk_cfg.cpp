// Group "Chk_Cfg" (CFG-nn): the configuration check (protocol-facts §D.3, §D.4, §D.8).
//
// Decisions:
// - Chk_Cfg is answered SC; a mismatch shows as Cfg_Fault (diag octet 1 bit 2) with Station_
//   Not_Ready, and the slave goes back to Wait_Prm, so Data_Exchange gets RS. The diagnosis
//   checks here look at the bits of this group's rule (Cfg_Fault, Station_Not_Ready) only:
//   Prm_Req and the Ident_Number are the Start-up group's, so one broken rule fails one group.
// - "One identifier changed": the first identifier octet with its lowest bit flipped (a general
//   identifier then has another length; a special one another count) — the same length, other
//   meaning. "Wrong length": the last octet dropped, or an identifier 0x10 added to a one-octet
//   configuration.
// - Chk_Cfg in Wait_Prm: refused means the slave does not reach Data_Exch — RS, or SC without
//   effect (the diagnosis still shows Not_Ready, Data_Exchange gets RS); either passes.
// - Data_Exchange in Wait_Cfg (after a good Set_Prm, before any Chk_Cfg; §D.8 "Wait_Cfg accepts
//   Chk_Cfg"): refused with RS, and the diagnosis after it still shows Station_Not_Ready. What
//   the slave does next is not this test's rule (the standard does not say whether the refused
//   telegram sends it back to Wait_Prm), so a good Chk_Cfg afterwards is not judged.

#include "groups.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "steps.hpp"

namespace pbvbus::conformance::detail {

namespace {

using devices::SlaveMutant;

constexpr const char* kChkCfgGroup = "Chk_Cfg";

void right_config(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto prm = prm_du(ctx.params());
  if (check(r, "Set_Prm", expect_sc(set_prm(*s, prm)))) return;
  const auto cfg = cfg_du(ctx.params());
  if (check(r, "Chk_Cfg with the real configuration", expect_sc(chk_cfg(*s, cfg)))) return;
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady | dp::kDiagCfgFault | dp::kDiagPrmFault;
  e.s1 = 0;
  e.s2_mask = dp::kDiagPrmReq;
  e.s2 = 0;
  e.master = tester_address(*s);
  check(r, "Slave_Diag (Data_Exch)", check_diag(slave_diag(*s), e));
}

/// The precondition of the tests that send something in Wait_Cfg: the GSD's Set_Prm was taken
/// (no Prm_Fault, the tester owns the slave). An Error otherwise: a refused Set_Prm leaves the
/// slave in Wait_Prm, where RS and Not_Ready would pass these tests for the wrong reason.
bool set_prm_taken(TestResult& r, Session& s) {
  const Reply d = slave_diag(s, "Slave_Diag after Set_Prm (Wait_Cfg expected)");
  DiagExpect e;
  e.s1_mask = dp::kDiagPrmFault;
  e.s1 = 0;
  e.master = tester_address(s);
  if (const auto why = check_diag(d, e); !why.empty()) {
    error(r, "precondition not established: the Set_Prm with the GSD's parameters was not taken (" +
                 why + "); the Set_Prm group's tests say why");
    return false;
  }
  return true;
}

/// The preparatory Set_Prm's reply as a master judges it (the same rule as start_up()): SC, or a
/// response without data with status OK or DL.
std::string expect_ack(const Reply& r) {
  if (r.kind == Reply::Kind::Sc) return {};
  if (r.kind == Reply::Kind::Telegram && r.data.empty() &&
      (r.status == fdl::ResponseStatus::OK || r.status == fdl::ResponseStatus::DL))
    return {};
  return "expected SC, got " + r.describe();
}

void expect_cfg_fault(TestContext& ctx, TestResult& r, const std::vector<std::uint8_t>& cfg, const std::string& what) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto prm = prm_du(ctx.params());
  if (check(r, "Set_Prm", expect_ack(set_prm(*s, prm)))) return;
  if (!set_prm_taken(r, *s)) return;
  if (check(r, "Chk_Cfg, " + what, expect_sc(chk_cfg(*s, cfg, "Chk_Cfg, " + what)))) return;
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady | dp::kDiagCfgFault;
  e.s1 = dp::kDiagStationNotReady | dp::kDiagCfgFault;
  if (check(r, "Slave_Diag after Chk_Cfg with " + what + " (Cfg_Fault, back to Wait_Prm)",
            check_diag(slave_diag(*s), e)))
    return;
  const auto out = output_pattern(ctx.output_len(), 0x0F);
  check(r, "Data_Exchange after the refused Chk_Cfg", expect_rs(data_exchange(*s, out)));
}

void wrong_identifier(TestContext& ctx, TestResult& r) {
  auto cfg = cfg_du(ctx.params());
  if (cfg.empty()) {
    not_applicable(r, "the configuration is empty");
    return;
  }
  cfg[0] = static_cast<std::uint8_t>(cfg[0] ^ 0x01);
  expect_cfg_fault(ctx, r, cfg, "one identifier changed");
}

void wrong_cfg_length(TestContext& ctx, TestResult& r) {
  auto cfg = cfg_du(ctx.params());
  if (cfg.size() > 1) cfg.pop_back();
  else cfg.push_back(0x10);
  expect_cfg_fault(ctx, r, cfg, "wrong length");
}

void chk_cfg_in_wait_prm(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto cfg = cfg_du(ctx.params());
  const Reply c = chk_cfg(*s, cfg, "Chk_Cfg in Wait_Prm");
  if (!c.rs() && c.kind != Reply::Kind::Sc) {
    fail(r, "Chk_Cfg in Wait_Prm: expected RS (or SC without effect), got " + c.describe());
    return;
  }
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady;
  e.s1 = dp::kDiagStationNotReady;
  if (check(r, "Slave_Diag (still Wait_Prm)", check_diag(slave_diag(*s), e))) return;
  const auto out = output_pattern(ctx.output_len(), 0x3C);
  check(r, "Data_Exchange", expect_rs(data_exchange(*s, out)));
}

void data_exchange_in_wait_cfg(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto prm = prm_du(ctx.params());
  if (check(r, "Set_Prm", expect_ack(set_prm(*s, prm)))) return;
  if (!set_prm_taken(r, *s)) return;
  const auto out = output_pattern(ctx.output_len(), 0x5A);
  const Reply x = data_exchange(*s, out, "Data_Exchange in Wait_Cfg (no Chk_Cfg yet)");
  if (!x.rs()) {
    fail(r, "Data_Exchange after Set_Prm, before Chk_Cfg (Wait_Cfg): expected RS (refused), got " +
                x.describe());
    return;
  }
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady;
  e.s1 = dp::kDiagStationNotReady;
  check(r, "Slave_Diag after the refused Data_Exchange (still not ready)", check_diag(slave_diag(*s), e));
}

}  // namespace

void add_chk_cfg_tests(std::vector<TestCase>& out) {
  out.push_back({"CFG-01", kChkCfgGroup, "Right configuration accepted",
                 "Chk_Cfg with the slave's real configuration (the GSD modules' identifiers in order) "
                 "after a good Set_Prm brings it to Data_Exch (§D.3, §D.8)",
                 right_config, {}});
  out.push_back({"CFG-02", kChkCfgGroup, "Wrong identifier refused",
                 "Chk_Cfg with one identifier changed sets Cfg_Fault (diag octet 1 bit 2) and the "
                 "slave goes back to Wait_Prm (§D.3, §D.8)",
                 wrong_identifier, {SlaveMutant::AcceptWrongCfg}});
  out.push_back({"CFG-03", kChkCfgGroup, "Wrong configuration length refused",
                 "Chk_Cfg with more or fewer identifier octets than the real configuration sets "
                 "Cfg_Fault (§D.3)",
                 wrong_cfg_length, {SlaveMutant::AcceptWrongCfg}});
  out.push_back({"CFG-04", kChkCfgGroup, "Chk_Cfg in Wait_Prm refused",
                 "Before a Set_Prm, Chk_Cfg does not bring the slave to data exchange (Wait_Prm accepts "
                 "only Set_Prm, Slave_Diag, Get_Cfg, Set_Slave_Add; §D.8)",
                 chk_cfg_in_wait_prm, {}});
  out.push_back({"CFG-05", kChkCfgGroup, "Data_Exchange in Wait_Cfg refused",
                 "After a good Set_Prm and before a good Chk_Cfg (Wait_Cfg) the slave accepts only "
                 "Chk_Cfg (or Set_Prm again): a Data_Exchange gets RS and does not bring it to "
                 "data exchange (§D.8)",
                 data_exchange_in_wait_cfg, {SlaveMutant::DataExchangeInWaitCfg}});
}

}  // namespace pbvbus::conformance::detail
