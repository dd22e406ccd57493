// Group "Read services" (RD-nn): Get_Cfg, Rd_Inp, Rd_Outp (protocol-facts §D.1, §D.3, §D.7,
// §D.8).
//
// Decisions:
// - Get_Cfg must answer exactly the configuration a configuration tool derives from the GSD:
//   the chosen modules' identifier octets in module order (the Chk_Cfg DU).
// - Rd_Inp answers the slave's CURRENT input image (§D.7), which a device's process may change at
//   any time. So Rd_Inp is read between two Data_Exchanges: when both replies carry the same
//   inputs the image did not move and Rd_Inp must equal them octet for octet; when they differ
//   (live inputs, e.g. a counter) only Rd_Inp's length is judged, and the message says so.
//   Rd_Outp is compared with the outputs of the last Data_Exchange. For a slave model the
//   inputs are first set to a known non-zero pattern through the model's application (white
//   box), so that the comparison is not between zeros; an outside slave answers with whatever
//   its program has.
// - Rd_Inp/Rd_Outp are read in Data_Exch (the slave's image exists there, §D.7), from the owner
//   and from another master (address 2): both must be answered.
// - A slave without inputs (outputs) answers Rd_Inp (Rd_Outp) with SC like Data_Exchange
//   (§B.1): then the test is n/a for the data comparison.

#include "groups.hpp"
#include "steps.hpp"

namespace pbvbus::conformance::detail {

namespace {

using devices::SlaveMutant;

constexpr const char* kReadServicesGroup = "Read services";

/// White box: a model's inputs set to a pattern (module by module, whole modules).
void set_model_inputs(Session& s, std::uint8_t seed) {
  devices::SlaveModel* m = s.model();
  if (!m) return;
  auto& app = m->application();
  for (std::size_t i = 0; i < app.modules(); ++i) {
    const auto& ml = app.module(i);
    if (ml.in_len == 0) continue;
    const auto v = output_pattern(ml.in_len, static_cast<std::uint8_t>(seed + i));
    app.write_inputs(i, v);
  }
}

void get_cfg_matches_gsd(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  const auto cfg = cfg_du(ctx.params());
  if (check(r, "Get_Cfg in Wait_Prm", expect_data(get_cfg(*s, "Get_Cfg in Wait_Prm"), cfg))) return;
  if (precondition(r, start_up(*s, ctx))) return;
  if (check(r, "Get_Cfg in Data_Exch", expect_data(get_cfg(*s, "Get_Cfg in Data_Exch"), cfg))) return;
  check(r, "Get_Cfg from master 2", expect_data(get_cfg(*s, "Get_Cfg from master 2", kOtherMaster), cfg));
}

void rd_inp_test(TestContext& ctx, TestResult& r, std::optional<std::uint8_t> reader) {
  if (ctx.input_len() == 0) {
    not_applicable(r, "the configuration has no inputs");
    return;
  }
  auto s = open_session(ctx, r);
  if (!s) return;
  if (precondition(r, start_up(*s, ctx))) return;
  set_model_inputs(*s, 0x31);
  const auto out = output_pattern(ctx.output_len(), 0x42);
  const Reply dx = data_exchange(*s, out);
  if (!dx.ok_with_data() || dx.data.size() != ctx.input_len()) {
    fail(r, "Data_Exchange: expected " + std::to_string(ctx.input_len()) + " input octets, got " + dx.describe());
    return;
  }
  const std::string who = reader ? "Rd_Inp from master 2" : "Rd_Inp from the owner";
  const Reply rd = rd_inp(*s, who, reader);
  const Reply dx2 = data_exchange(*s, out, "Data_Exchange after Rd_Inp");
  if (!dx2.ok_with_data() || dx2.data.size() != ctx.input_len()) {
    fail(r, "Data_Exchange after Rd_Inp: expected " + std::to_string(ctx.input_len()) +
                " input octets, got " + dx2.describe());
    return;
  }
  if (dx2.data == dx.data) {
    if (check(r, who + " (inputs unchanged between the Data_Exchanges before and after it)",
              expect_data(rd, dx.data)))
      return;
    r.message = who + " = " + hex(rd.data) + ", the inputs of both Data_Exchanges around it";
    return;
  }
  if (!rd.ok_with_data() || rd.data.size() != ctx.input_len()) {
    fail(r, who + ": expected " + std::to_string(ctx.input_len()) + " input octets, got " + rd.describe());
    return;
  }
  r.message = "the inputs moved between the Data_Exchanges around " + who + " (" + hex(dx.data) +
              " → " + hex(dx2.data) + ": a live process image); " + who + " = " + hex(rd.data) +
              ", judged on its length only";
}

void rd_outp_test(TestContext& ctx, TestResult& r, std::optional<std::uint8_t> reader) {
  if (ctx.output_len() == 0) {
    not_applicable(r, "the configuration has no outputs");
    return;
  }
  auto s = open_session(ctx, r);
  if (!s) return;
  if (precondition(r, start_up(*s, ctx))) return;
  const auto out = output_pattern(ctx.output_len(), 0x53);
  const Reply dx = data_exchange(*s, out);
  if (ctx.input_len() == 0 ? dx.kind != Reply::Kind::Sc : !dx.ok_with_data()) {
    fail(r, "Data_Exchange: " + dx.describe());
    return;
  }
  const std::string who = reader ? "Rd_Outp from master 2" : "Rd_Outp from the owner";
  check(r, who + " (= the outputs last written)", expect_data(rd_outp(*s, who, reader), out));
}

void rd_by_other_master(TestContext& ctx, TestResult& r) {
  if (ctx.input_len() == 0 && ctx.output_len() == 0) {
    not_applicable(r, "the configuration has neither inputs nor outputs");
    return;
  }
  if (ctx.input_len() > 0) rd_inp_test(ctx, r, kOtherMaster);
  if (r.verdict == Verdict::Fail) return;
  if (ctx.output_len() > 0) {
    const Verdict before = r.verdict;
    rd_outp_test(ctx, r, kOtherMaster);
    if (before == Verdict::Pass && r.verdict == Verdict::NotApplicable) r.verdict = Verdict::Pass;
  }
}

}  // namespace

void add_read_service_tests(std::vector<TestCase>& out) {
  out.push_back({"RD-01", kReadServicesGroup, "Get_Cfg = the GSD configuration",
                 "Get_Cfg answers the real configuration: the configured GSD modules' identifier "
                 "octets in module order, in any state and to any master (§D.3, §D.8)",
                 get_cfg_matches_gsd, {SlaveMutant::WrongGetCfg, SlaveMutant::GetCfgSapsNotSwapped}});
  out.push_back({"RD-02", kReadServicesGroup, "Rd_Inp",
                 "Rd_Inp (SAP 56) answers the slave's inputs: those of the last Data_Exchange reply, "
                 "with the configured input length (§D.7)",
                 [](TestContext& c, TestResult& r) { rd_inp_test(c, r, std::nullopt); }, {}});
  out.push_back({"RD-03", kReadServicesGroup, "Rd_Outp",
                 "Rd_Outp (SAP 57) answers the outputs last written by Data_Exchange, with the "
                 "configured output length (§D.7)",
                 [](TestContext& c, TestResult& r) { rd_outp_test(c, r, std::nullopt); }, {}});
  out.push_back({"RD-04", kReadServicesGroup, "Rd_Inp / Rd_Outp for another master",
                 "A master that does not own the slave may read its inputs and outputs (Rd_Inp, "
                 "Rd_Outp are answered to any master; §D.8 locking)",
                 rd_by_other_master, {}});
}

}  // namespace pbvbus::conformance::detail
