// Group "FCB/FCV" (FCB-nn): frame count bit handling of the slave's FDL layer (protocol-facts
// §C.6) on Data_Exchange.
//
// Decisions:
// - Whether a repeated Data_Exchange was executed is seen through Rd_Outp (the outputs last
//   taken), read by ANOTHER master (address 2): FCBs are kept per source address (§C.6), so the
//   reads do not disturb the tester's FCB sequence. The repeat's reply must also be the stored
//   reply, byte for byte.
// - A slave without outputs cannot show whether it took them: n/a.
// - "Restart after Set_Prm": after re-parameterisation the master starts again with a first
//   frame (FCV 0, FCB 1); the slave must execute it and store its FCB, so the next frame with
//   FCB 0 is new (even though the last frame before Set_Prm also had FCB 0) and a repeat of that
//   one is again a repeat.
// - "Per master" (FCB-04): between two frames of the tester, master 2 sends its own FCB sequence
//   (a first frame FCV 0 FCB 1, then FCV 1 FCB 0 — Slave_Diag, which changes nothing). The
//   tester's next frame has FCB 0 too; it is new for the tester (its last was FCB 1) and must be
//   executed — a slave that keeps one FCB for all masters takes it for a repeat of master 2's.

#include "groups.hpp"
#include "pbvbus/dp/sap.hpp"
#include "steps.hpp"

namespace pbvbus::conformance::detail {

namespace {

using devices::SlaveMutant;

constexpr const char* kFcbGroup = "FCB/FCV";
constexpr std::uint8_t kReader = 2;

bool setup(TestContext& ctx, TestResult& r, std::unique_ptr<Session>& s) {
  if (ctx.output_len() == 0) {
    not_applicable(r, "the configuration has no outputs: a repeat cannot be told from a new request");
    return false;
  }
  s = open_session(ctx, r);
  if (!s) return false;
  if (precondition(r, start_up(*s, ctx))) return false;
  // The tests see "executed or not" through Rd_Outp by master 2: that view must work first. A
  // Data_Exchange with FCV = 0 is executed whatever the FCB state (§C.6).
  const auto probe = output_pattern(ctx.output_len(), 0x6C);
  data_exchange(*s, probe, "Data_Exchange FCV=0 (is Rd_Outp a view of the outputs?)");
  const Reply rd = rd_outp(*s, "Rd_Outp from master 2", kReader);
  if (const auto why = expect_data(rd, probe); !why.empty()) {
    error(r, "precondition not established: Rd_Outp from master 2 does not show the outputs of a "
             "Data_Exchange with FCV = 0 (" + why + "), so these tests cannot see whether a frame "
             "was executed; RD-03/RD-04 say why");
    return false;
  }
  return true;
}

/// Rd_Outp by master 2 must show `want`.
bool outputs_are(TestResult& r, Session& s, const std::vector<std::uint8_t>& want, const std::string& what) {
  return !check(r, what, expect_data(rd_outp(s, "Rd_Outp from master 2", kReader), want));
}

/// Every test opens the FCB sequence with a first frame (FCV 0, FCB 1, §C.6): the slave must
/// execute it and store FCB 1 for the tester whatever an earlier test left (an outside slave
/// keeps its FCB memory across tests; a fresh model has none).
bool first_frame(TestResult& r, Session& s, const std::vector<std::uint8_t>& out) {
  data_exchange(s, out, "first frame: Data_Exchange FCV=0 FCB=1", std::nullopt, false, true);
  return outputs_are(r, s, out, "the first frame is executed");
}

void repeat_not_executed(TestContext& ctx, TestResult& r) {
  std::unique_ptr<Session> s;
  if (!setup(ctx, r, s)) return;
  const auto a0 = output_pattern(ctx.output_len(), 0x11);
  const auto a = output_pattern(ctx.output_len(), 0x01);
  const auto b = output_pattern(ctx.output_len(), 0x80);
  if (!first_frame(r, *s, a0)) return;
  data_exchange(*s, a, "Data_Exchange FCV=1 FCB=0, outputs A", std::nullopt, true, false);
  const Exchange first = s->bus().transcript().back();
  if (!first.answered) {
    fail(r, "Data_Exchange FCV=1 FCB=0: no reply");
    return;
  }
  data_exchange(*s, b, "Data_Exchange FCV=1 FCB=0 again (repeat), outputs B", std::nullopt, true, false);
  const Exchange again = s->bus().transcript().back();
  if (!again.answered) {
    fail(r, "repeat: no reply");
    return;
  }
  if (again.response != first.response) {
    fail(r, "repeat: expected the stored reply " + hex(first.response) + ", got " + hex(again.response));
    return;
  }
  outputs_are(r, *s, a, "after the repeat the outputs are still A (the repeat was not executed)");
}

void toggle_executed(TestContext& ctx, TestResult& r) {
  std::unique_ptr<Session> s;
  if (!setup(ctx, r, s)) return;
  const auto a0 = output_pattern(ctx.output_len(), 0x12);
  const auto a = output_pattern(ctx.output_len(), 0x02);
  const auto b = output_pattern(ctx.output_len(), 0x90);
  if (!first_frame(r, *s, a0)) return;
  data_exchange(*s, a, "Data_Exchange FCV=1 FCB=0 (toggled), outputs A", std::nullopt, true, false);
  if (!outputs_are(r, *s, a, "outputs A taken")) return;
  data_exchange(*s, b, "Data_Exchange FCV=1 FCB=1 (toggled), outputs B", std::nullopt, true, true);
  outputs_are(r, *s, b, "after the toggled FCB the outputs are B");
}

void restart_after_set_prm(TestContext& ctx, TestResult& r) {
  std::unique_ptr<Session> s;
  if (!setup(ctx, r, s)) return;
  const auto a = output_pattern(ctx.output_len(), 0x03);
  const auto b = output_pattern(ctx.output_len(), 0xA0);
  const auto c = output_pattern(ctx.output_len(), 0x40);
  const auto d = output_pattern(ctx.output_len(), 0xC0);
  if (!first_frame(r, *s, a)) return;
  data_exchange(*s, a, "Data_Exchange FCV=1 FCB=0, outputs A", std::nullopt, true, false);
  // Re-parameterisation: Set_Prm + Chk_Cfg (the slave leaves data exchange and comes back).
  const auto prm = prm_du(ctx.params());
  if (check(r, "Set_Prm", expect_sc(set_prm(*s, prm, "Set_Prm (re-parameterisation)")))) return;
  const auto cfg = cfg_du(ctx.params());
  if (check(r, "Chk_Cfg", expect_sc(chk_cfg(*s, cfg, "Chk_Cfg (re-parameterisation)")))) return;
  data_exchange(*s, b, "first frame after Set_Prm: FCV=0 FCB=1, outputs B", std::nullopt, false, true);
  if (!outputs_are(r, *s, b, "first frame after Set_Prm executed (outputs B)")) return;
  data_exchange(*s, c, "Data_Exchange FCV=1 FCB=0, outputs C (new: toggled from the first frame)",
                std::nullopt, true, false);
  if (!outputs_are(r, *s, c, "FCB 0 after the first frame is new (outputs C)")) return;
  data_exchange(*s, d, "Data_Exchange FCV=1 FCB=0 again (repeat), outputs D", std::nullopt, true, false);
  outputs_are(r, *s, c, "the repeat is not executed (outputs still C)");
}

void fcb_per_master(TestContext& ctx, TestResult& r) {
  std::unique_ptr<Session> s;
  if (!setup(ctx, r, s)) return;
  const auto a = output_pattern(ctx.output_len(), 0x04);
  const auto b = output_pattern(ctx.output_len(), 0xB0);
  if (!first_frame(r, *s, a)) return;
  const auto diag = [&](bool fcv, bool fcb, const std::string& note) {
    return service(*s, dp::kSapSlaveDiag, {}, note, kReader, fcv, fcb);
  };
  if (check(r, "master 2's first frame", expect_data(diag(false, true, "master 2: Slave_Diag FCV=0 FCB=1 (first frame)"), {}, false)))
    return;
  if (check(r, "master 2's second frame", expect_data(diag(true, false, "master 2: Slave_Diag FCV=1 FCB=0"), {}, false)))
    return;
  data_exchange(*s, b, "tester: Data_Exchange FCV=1 FCB=0 (new for the tester), outputs B", std::nullopt, true, false);
  outputs_are(r, *s, b, "the tester's FCB 0 after master 2's FCB 0 is executed (outputs B)");
}

}  // namespace

void add_fcb_tests(std::vector<TestCase>& out) {
  out.push_back({"FCB-01", kFcbGroup, "Repeat not executed",
                 "A Data_Exchange with FCV=1 and the same FCB as the previous one from that master is "
                 "a repeat: the slave resends its stored reply and does not take the new outputs "
                 "(IEC 61158-4-3 frame count bit; §C.6)",
                 repeat_not_executed, {SlaveMutant::IgnoreFcb}});
  out.push_back({"FCB-02", kFcbGroup, "Toggled FCB executed",
                 "A Data_Exchange with FCV=1 and the FCB toggled is a new request: its outputs are "
                 "taken (§C.6)",
                 toggle_executed, {}});
  out.push_back({"FCB-03", kFcbGroup, "FCB restart after Set_Prm",
                 "After re-parameterisation the first frame (FCV=0, FCB=1) is executed and starts the "
                 "FCB sequence again: the next toggled frame is new, its repeat is not (§C.6)",
                 restart_after_set_prm, {SlaveMutant::IgnoreFcb}});
  out.push_back({"FCB-04", kFcbGroup, "FCB kept per master",
                 "The responder keeps the frame count bit per requesting station: another master's "
                 "FCB sequence in between does not make the tester's next toggled frame a repeat "
                 "(§C.6: the FCB is stored per source address)",
                 fcb_per_master, {SlaveMutant::FcbGlobal}});
}

}  // namespace pbvbus::conformance::detail
