// Group "Consistency" (CON-nn): a module consistent over its whole length is handed over as one
// unit (IEC 61158-6 DP configuration identifier bit 7; protocol-facts.md §D.3, §F "What a
// simulation must guarantee" 1).
//
// The wire cannot show tearing by itself: one telegram always carries one image. What can be
// seen is a reply whose module mixes two sampling instants. So the test makes the device write
// the SAME value into every word of the module, a new value every DP cycle, and checks that all
// words of that module are equal in every reply.
//
// Decisions:
// - White box, model only: every 2-octet channel (1-octet if the module's input length is odd)
//   of the first consistent input module gets a COUNTER of DP cycles
//   (SlaveModel::add_channel_behaviour); 200 Data_Exchanges follow. n/a for an outside slave
//   (the battery cannot make its inputs move in step) and for a configuration without a
//   consistent input module of at least two channels.
// - The output direction is checked alongside when that module (or another consistent one) has
//   outputs: each Data_Exchange sends the cycle number in every word of it, and the outputs the
//   model applies must show one cycle's value in all words.

#include <algorithm>
#include <string>

#include "group_support.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kConsistencyGroup = "Consistency";
constexpr int kCycles = 200;

bool words_equal(std::span<const std::uint8_t> m, std::size_t width) {
  for (std::size_t o = width; o + width <= m.size(); o += width)
    if (!std::equal(m.begin(), m.begin() + static_cast<std::ptrdiff_t>(width),
                    m.begin() + static_cast<std::ptrdiff_t>(o)))
      return false;
  return true;
}

void consistent_module(TestContext& ctx, TestResult& res) {
  if (ctx.outside())
    return not_applicable(res, "an outside slave's inputs cannot be made to change in step (white box only)");
  Run run(ctx, res);
  if (!run) return;
  auto& model = *run.model();
  auto& app = model.application();
  std::optional<std::size_t> in_mod, out_mod;
  for (std::size_t m = 0; m < app.modules(); ++m) {
    const auto& ml = app.module(m);
    if (!ml.consistent) continue;
    if (!in_mod && ml.in_len >= 2) in_mod = m;
    if (!out_mod && ml.out_len >= 2) out_mod = m;
  }
  if (!in_mod && !out_mod)
    return run.na(
        "the configuration has no module consistent over its whole length with two or "
        "more octets");
  std::size_t in_w = 0;
  if (in_mod) {
    const auto& ml = app.module(*in_mod);
    in_w = ml.in_len % 2 == 0 ? 2 : 1;
    for (std::size_t off = 0; off < ml.in_len; off += in_w) {
      const std::string e = model.add_channel_behaviour(*in_mod, off, in_w,
                                                        devices::IoBehaviour::counter_per_cycle());
      if (!e.empty()) return run.error("the test could not set up the model (a COUNTER channel was refused): " + e);
    }
  }
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  std::vector<std::uint8_t> out(ctx.output_len(), 0);
  for (int c = 0; c < kCycles; ++c) {
    if (out_mod) {
      const auto& ml = app.module(*out_mod);
      for (std::size_t o = 0; o < ml.out_len; ++o)
        out[ml.out_offset + o] =
            static_cast<std::uint8_t>(o % 2 == 0 && ml.out_len % 2 == 0 ? c >> 8 : c);
    }
    const Reply r = reply_of(run.data_exchange(out, "Data_Exchange " + std::to_string(c + 1)));
    if (in_mod) {
      const auto& ml = app.module(*in_mod);
      if (!r.ok_with_data() || r.data.size() < ml.in_offset + ml.in_len)
        return run.fail("Data_Exchange " + std::to_string(c + 1) + " answered " + r.describe());
      const std::span<const std::uint8_t> m(r.data.data() + ml.in_offset, ml.in_len);
      if (!words_equal(m, in_w))
        return run.fail("Data_Exchange " + std::to_string(c + 1) + ": the consistent module " +
                        std::to_string(*in_mod) + " reads " + hex(m) +
                        " — its channels, written together, come from different cycles");
    } else if (!(r.ok_with_data() || (r.kind == Reply::Kind::Sc && ctx.input_len() == 0))) {
      return run.fail("Data_Exchange " + std::to_string(c + 1) + " answered " + r.describe());
    }
    if (out_mod) {
      const auto& ml = app.module(*out_mod);
      std::vector<std::uint8_t> got(ml.out_len);
      app.read_outputs(*out_mod, got);
      const std::span<const std::uint8_t> sent(out.data() + ml.out_offset, ml.out_len);
      if (!std::equal(got.begin(), got.end(), sent.begin(), sent.end()))
        return run.fail("Data_Exchange " + std::to_string(c + 1) +
                        ": the consistent output module " + std::to_string(*out_mod) + " applied " +
                        hex(got) + " after receiving " + hex(sent));
    }
  }
  std::string what;
  if (in_mod) what = "input module " + std::to_string(*in_mod);
  if (out_mod)
    what += std::string(what.empty() ? "" : " and ") + "output module " + std::to_string(*out_mod);
  run.pass("over " + std::to_string(kCycles) + " Data_Exchanges the consistent " + what +
           " always showed one cycle's value in every word");
}

}  // namespace

void add_consistency_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "CON-01", kConsistencyGroup, "Module consistent over its whole length",
      "The input octets of a module whose identifier says \"consistent over the whole length\" "
      "come from one sampling instant, and its outputs are applied together (IEC 61158-6 DP "
      "configuration identifier bit 7; protocol-facts.md §D.3, §F)",
      {SlaveMutant::TearConsistent}, consistent_module));
}

}  // namespace pbvbus::conformance::detail
