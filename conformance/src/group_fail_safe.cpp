// Group "Fail-safe" (FS-nn): Data_Exchange without output data in Clear, and a Data_Exchange
// with a wrong output length (IEC 61158-6 DP Data_Exchange, GSD Fail_Safe; protocol-facts.md
// §D.8 Fail_Safe, §D.9 Clear "Output_Clear", §D.7; docs/dp-slave.md).
//
// Decisions:
// - FS-01 needs GSD Fail_Safe = 1 and outputs in the configuration (else n/a with the reason). It
//   sends outputs A5 first, then a Data_Exchange with no output data, WITHOUT a Global_Control
//   Clear_Data before it: Clear_Data would make the outputs safe by itself and hide whether the
//   zero-length telegram did. Pass: answered with the inputs (SC for a slave without inputs),
//   the slave still in Data_Exch and — white box — its applied outputs zero.
// - FS-02: a Data_Exchange whose output length is neither the configured one nor (with Fail_Safe)
//   zero is a parameterisation error: the slave refuses it (no data answer) and goes to Wait_Prm
//   (Station_Not_Ready and Master_Add FF in the next diagnosis), outputs safe (white box).

#include <algorithm>
#include <string>

#include "group_support.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kFailSafeGroup = "Fail-safe";

void zero_length_outputs(TestContext& ctx, TestResult& res) {
  if (!ctx.spec().gsd->slave_features().fail_safe)
    return not_applicable(
        res,
        "the GSD says Fail_Safe = 0: a Data_Exchange without output data is not part of "
        "this slave's contract");
  if (ctx.output_len() == 0)
    return not_applicable(res, "the configuration has no outputs: every Data_Exchange is zero-length already");
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const auto a = run.outputs(0xA5);
  const Reply r1 = reply_of(run.data_exchange(a, "Data_Exchange outputs A5"));
  if (!(r1.ok_with_data() || (r1.kind == Reply::Kind::Sc && ctx.input_len() == 0)))
    return run.fail("Data_Exchange with outputs answered " + r1.describe());
  const Reply r0 = reply_of(run.data_exchange({}, "Data_Exchange without output data (Fail_Safe)"));
  const bool ok = ctx.input_len() == 0 ? r0.kind == Reply::Kind::Sc
                                       : r0.ok_with_data() && r0.data.size() == ctx.input_len();
  if (!ok)
    return run.fail("a Data_Exchange without output data (Fail_Safe = 1) answered " +
                    r0.describe() + ", expected the " + std::to_string(ctx.input_len()) +
                    " input octets");
  if (run.model()) {
    const auto got = applied_outputs(*run.model());
    const std::vector<std::uint8_t> zero(got.size(), 0);
    if (got != zero)
      return run.fail("after a Data_Exchange without output data: " + outputs_text(got, zero));
  }
  std::string why2;
  const auto d = run.diag(why2, "Slave_Diag");
  if (!d) return run.fail(why2);
  if (!diag_ready(*d))
    return run.fail("after the zero-length Data_Exchange the diagnosis reads " + hex(d->encode()) +
                    " (the slave must stay in Data_Exch)");
  run.pass(std::string("a Data_Exchange without output data was answered with the inputs") +
           (run.model() ? " and set the outputs safe" : "; outputs not visible (outside slave)"));
}

void wrong_output_length(TestContext& ctx, TestResult& res) {
  const std::size_t n = ctx.output_len() + 1;
  if (n > 244) return not_applicable(res, "the configuration already has 244 output octets");
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const Reply r1 = reply_of(run.data_exchange(run.outputs(0x5A), "Data_Exchange outputs 5A"));
  if (!(r1.ok_with_data() || (r1.kind == Reply::Kind::Sc && ctx.input_len() == 0)))
    return run.fail("Data_Exchange with the right length answered " + r1.describe());
  const std::vector<std::uint8_t> wrong(n, 0x5A);
  const Reply r = reply_of(run.data_exchange(wrong, "Data_Exchange with " + std::to_string(n) +
                                                        " output octets (configured " +
                                                        std::to_string(ctx.output_len()) + ")"));
  if (r.ok_with_data() || r.kind == Reply::Kind::Sc)
    return run.fail("a Data_Exchange with " + std::to_string(n) + " output octets instead of " +
                    std::to_string(ctx.output_len()) + " was answered " + r.describe());
  const auto d = run.diag(why, "Slave_Diag after the wrong length");
  if (!d) return run.fail(why);
  if (!wait_prm_diag(*d))
    // What a slave does after refusing the telegram is not in the standard as protocol-facts.md
    // §D.7 gives it (pbvbus's own model goes to Wait_Prm, docs/dp-slave.md): not judged.
    return run.pass("the wrong output length was refused (" + r.describe() +
                    "); the slave then stayed in data exchange (diagnosis " + hex(d->encode()) +
                    "), which the standard leaves open");
  if (run.model()) {
    const auto got = applied_outputs(*run.model());
    const std::vector<std::uint8_t> zero(got.size(), 0);
    if (got != zero) return run.fail("after the wrong output length: " + outputs_text(got, zero));
  }
  run.pass("the wrong output length was refused (" + r.describe() +
           ") and the slave went to Wait_Prm");
}

}  // namespace

void add_fail_safe_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(
      make_case("FS-01", kFailSafeGroup, "Data_Exchange without output data (Fail_Safe)",
                "A slave with GSD Fail_Safe = 1 accepts, in the master's Clear state, "
                "Data_Exchange with zero "
                "output octets: it answers with its inputs and sets its outputs to the safe state "
                "(IEC 61158-6 DP; protocol-facts.md §D.8 Fail_Safe, §D.9 Output_Clear)",
                {SlaveMutant::RejectFailSafe}, zero_length_outputs));
  out.push_back(make_case(
      "FS-02", kFailSafeGroup, "Wrong output length",
      "A Data_Exchange whose output length differs from the configuration is refused (not "
      "answered with inputs); a slave that then returns to Wait_Prm has its outputs safe "
      "(IEC 61158-6 DP; protocol-facts.md §D.7, docs/dp-slave.md)",
      {}, wrong_output_length));
}

}  // namespace pbvbus::conformance::detail
