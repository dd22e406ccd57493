// Group "Start-up" (STA-nn): the slave's answers from power-on to data exchange (protocol-facts
// §D.4, §D.8, §D.9) — what a class-1 master sees while it brings a slave up.
//
// Expected diagnosis octets (§D.4), tester = master 1, ident from the GSD:
//   Wait_Prm  02 05 00 FF idH idL  (Station_Not_Ready; Prm_Req + the always-1 bit; no master)
//   Wait_Cfg  02 0C 00 01 idH idL  (still not ready; WD_On + always-1, Prm_Req cleared; master 1)
//   Data_Exch 00 0C 00 01 idH idL  (ready; WD_On + always-1; master 1)
// with the battery's Set_Prm (Lock_Req + WD_On, the GSD's ident and User_Prm_Data).

#include "groups.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"
#include "steps.hpp"

namespace pbvbus::conformance::detail {

namespace {

using devices::SlaveMutant;

constexpr const char* kStartupGroup = "Start-up";

std::uint16_t ident(TestContext& ctx) { return ctx.spec().gsd->ident_number(); }

std::vector<std::uint8_t> diag_wait_prm(TestContext& ctx) {
  return expected_diag(dp::kDiagStationNotReady, dp::kDiagPrmReq | dp::kDiagAlways1, 0, dp::kNoMaster,
                       ident(ctx));
}

std::uint8_t wd_bit(const dp::SlaveParams& p) {
  return (p.station_status & dp::kPrmWdOn) ? dp::kDiagWdOn : 0;
}

void power_on_diag(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  // A program behind a pty cannot be powered on by the battery: its Wait_Prm is the verified
  // start state (released by its owner), which must show the same diagnosis.
  const std::string when = ctx.outside() ? "in the start state (an outside slave: after the "
                                           "unlock, not a power-on)"
                                         : "after power-on";
  const Reply d = slave_diag(*s, "Slave_Diag " + when);
  if (!check(r, "Slave_Diag " + when, expect_std_diag(d, diag_wait_prm(ctx))) && ctx.outside())
    r.message = "Wait_Prm diagnosis " + hex(d.data) + " " + when;
}

void full_start_up(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const dp::SlaveParams& p = ctx.params();
  const std::uint8_t me = tester_address(*s);
  if (check(r, "Slave_Diag", expect_std_diag(slave_diag(*s), diag_wait_prm(ctx)))) return;
  const auto prm = prm_du(p);
  if (check(r, "Set_Prm", expect_sc(set_prm(*s, prm)))) return;
  const auto cfg = cfg_du(p);
  if (check(r, "Chk_Cfg", expect_sc(chk_cfg(*s, cfg)))) return;
  const auto ready = expected_diag(0, static_cast<std::uint8_t>(dp::kDiagAlways1 | wd_bit(p)), 0, me, ident(ctx));
  if (check(r, "Slave_Diag after Chk_Cfg", expect_std_diag(slave_diag(*s), ready))) return;
  const auto out = output_pattern(ctx.output_len(), 0x21);
  const Reply dx = data_exchange(*s, out);
  if (ctx.input_len() == 0) {
    check(r, "Data_Exchange (no inputs: SC, §B.1)", expect_sc(dx));
    return;
  }
  if (!dx.ok_with_data() || dx.data.size() != ctx.input_len())
    fail(r, "Data_Exchange: expected DL/DH with " + std::to_string(ctx.input_len()) +
                " input octets, got " + dx.describe());
}

void diag_in_each_state(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const dp::SlaveParams& p = ctx.params();
  const std::uint8_t me = tester_address(*s);
  if (check(r, "Wait_Prm", expect_std_diag(slave_diag(*s, "Slave_Diag in Wait_Prm"), diag_wait_prm(ctx))))
    return;
  const auto prm = prm_du(p);
  if (check(r, "Set_Prm", expect_sc(set_prm(*s, prm)))) return;
  const auto wait_cfg = expected_diag(dp::kDiagStationNotReady,
                                      static_cast<std::uint8_t>(dp::kDiagAlways1 | wd_bit(p)), 0, me, ident(ctx));
  if (check(r, "Wait_Cfg", expect_std_diag(slave_diag(*s, "Slave_Diag in Wait_Cfg"), wait_cfg))) return;
  const auto cfg = cfg_du(p);
  if (check(r, "Chk_Cfg", expect_sc(chk_cfg(*s, cfg)))) return;
  const auto dxch = expected_diag(0, static_cast<std::uint8_t>(dp::kDiagAlways1 | wd_bit(p)), 0, me, ident(ctx));
  check(r, "Data_Exch", expect_std_diag(slave_diag(*s, "Slave_Diag in Data_Exch"), dxch));
}

void data_exchange_refused_before_prm(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto out = output_pattern(ctx.output_len(), 0x33);
  if (check(r, "Data_Exchange in Wait_Prm", expect_rs(data_exchange(*s, out, "Data_Exchange before Set_Prm"))))
    return;
  // ... and it changed nothing: still Wait_Prm.
  check(r, "Slave_Diag afterwards", expect_std_diag(slave_diag(*s), diag_wait_prm(ctx)));
}

void fdl_status_of_a_slave(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const std::uint8_t me = tester_address(*s);
  const std::uint8_t dut = s->dut_address();
  const Exchange e = s->bus().request(fdl_status(dut, me), "FDL_Status");
  // SD1 reply, DA = tester, SA = DUT, FC 0x00 (response, station type 00 = slave, status OK).
  const std::vector<std::uint8_t> want = {0x10, me, dut, 0x00, static_cast<std::uint8_t>(me + dut), 0x16};
  if (!e.answered) fail(r, "FDL_Status: no reply");
  else if (e.response != want) fail(r, "FDL_Status: expected " + hex(want) + ", got " + hex(e.response));
}

}  // namespace

void add_startup_tests(std::vector<TestCase>& out) {
  out.push_back({"STA-01", kStartupGroup, "Power-on diagnosis",
                 "After power-on a slave answers Slave_Diag with 02 05 00 FF and its Ident_Number: "
                 "Station_Not_Ready, Prm_Req and the always-1 bit of Station_Status_2, no master "
                 "(IEC 61158-6 DP Slave_Diag; §D.4)",
                 power_on_diag, {SlaveMutant::NoPrmReqBit, SlaveMutant::WrongDiagIdent}});
  out.push_back({"STA-02", kStartupGroup, "Start-up sequence",
                 "Slave_Diag, Set_Prm (SC), Chk_Cfg (SC), Slave_Diag (ready, Prm_Req cleared, "
                 "Master_Add = the master), then Data_Exchange answered DL/DH with the configured "
                 "input length (§D.8, §D.9)",
                 full_start_up, {SlaveMutant::NoPrmReqBit, SlaveMutant::WrongDiagIdent}});
  out.push_back({"STA-03", kStartupGroup, "Diagnosis in each state",
                 "Station_Status octets in Wait_Prm (02 05), Wait_Cfg (02 0C with WD_On) and "
                 "Data_Exch (00 0C), Master_Add and Ident_Number as parameterised (§D.4)",
                 diag_in_each_state, {SlaveMutant::NoPrmReqBit, SlaveMutant::WrongDiagIdent}});
  out.push_back({"STA-04", kStartupGroup, "Data_Exchange refused before parameterisation",
                 "In Wait_Prm a slave rejects Data_Exchange (RS, the default SAP is not active) "
                 "and stays in Wait_Prm (§D.7, §D.8)",
                 data_exchange_refused_before_prm, {SlaveMutant::NoPrmReqBit, SlaveMutant::WrongDiagIdent}});
  out.push_back({"STA-05", kStartupGroup, "FDL_Status of a passive station",
                 "Request FDL Status is answered by the FDL layer with FC 0x00 (station type "
                 "slave, OK), SD1 (§B.3)",
                 fdl_status_of_a_slave, {}});
}

}  // namespace pbvbus::conformance::detail
