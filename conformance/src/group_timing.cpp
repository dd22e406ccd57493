// Group "Timing" (TIM-nn): the responder's station delay TSDR at every baud the GSD supports,
// Min_Slave_Interval, and TSYN (IEC 61158-4-3 FDL timing; protocol-facts.md §A TSYN, §C.1 min/max
// TSDR and GSD MaxTsdr, §C.2 TSDR definition and Min_Slave_Interval, §D.2 octet 4 min TSDR).
//
// TSDR = idle bit times from the end of the request's last stop bit to the start of the reply
// (TestBus Exchange::tsdr_bits, exact in virtual time).
//
// Decisions:
// - TIM-01 runs the start-up and one Data_Exchange at each supported baud (one session per baud)
//   and judges the four replies of the slave: Slave_Diag, Set_Prm, Chk_Cfg, Data_Exchange (and
//   the Slave_Diag after Chk_Cfg). Lower bound: the line's min TSDR (11) before Set_Prm, then
//   max(line min TSDR, Set_Prm octet 4). Upper bound: the GSD's MaxTsdr at that baud. An outside
//   slave runs only at the spec's baud; the other bauds are listed as not run (not a failure).
// - TIM-02 polls Data_Exchange 20 times with request starts Min_Slave_Intervall (GSD, 100 us)
//   apart, or the shortest the line allows when one message cycle is longer than that (the
//   message says which); every poll must be answered with the inputs.
// - A GSD without Min_Slave_Intervall (or with 0) is GSD-08's failure, not a timing fault of the
//   device. Neither the GSD specification (PI 2.122: mandatory, no default) nor IEC 61158-6 /
//   EN 50170 (Min_Slave_Interval 1..65535 x 100 us, no default; protocol-facts.md §C.2) defines a
//   default, so TIM-02 uses the smallest legal value, 1 (100 us): a description that states no
//   minimum lets a master poll as fast as the bus allows, and it is what pbvbus's own master
//   takes for such a file (devices/slave_model.cpp master_slave_params). The message says so.
// - TIM-03 sends Slave_Diag, Get_Cfg and Rd_Inp requests exactly TSYN = 33 bit times after the
//   end of the slave's previous reply (TestBus never sends earlier); each must be answered.
// - For an outside slave (paced behind a pty) the results are marked timing_not_meaningful, and
//   TIM-01 judges only that every request is answered within the slot time (the measured TSDRs
//   are in the message): the reply time of a program is its operating system's, not a device's.

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/fdl/bus_params.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kTimingGroup = "Timing";

bool is_answer(const Reply& r) {
  return r.kind == Reply::Kind::Sc || r.kind == Reply::Kind::Telegram;
}

void tsdr_every_baud(TestContext& ctx, TestResult& res) {
  res.timing_not_meaningful = ctx.outside();
  const auto& rates = ctx.spec().gsd->baud_rates();
  if (rates.empty()) {
    res.verdict = Verdict::Fail;
    res.message = "the GSD lists no supported baud rate";
    return;
  }
  Run run(ctx, res);  // the main session; each baud below gets its own
  if (!run) return;
  std::string summary, not_run, error;
  for (const auto& rate : rates) {
    const bus::Baud baud = rate.baud;
    const std::string bn(bus::baud_name(baud));
    if (!run.reopen(baud, error)) {
      not_run += " " + bn + " (" + error + ")";
      continue;
    }
    const std::uint32_t line_min = run.bus().options().params.min_tsdr;
    const std::uint32_t max = rate.max_tsdr;
    const dp::SlaveParams& p = ctx.params();
    const std::uint32_t prm_min = std::max<std::uint32_t>(line_min, p.min_tsdr);
    const std::size_t mark = run.bus().mark();
    std::string why;
    if (!run.start_up(why)) return run.fail("at " + bn + ": " + why);
    run.data_exchange(run.outputs(0x00), "Data_Exchange");
    std::int64_t lo = INT64_MAX, hi = -1;
    bool after_prm = false;
    for (const Exchange& e : run.bus().since(mark)) {
      const Reply r = reply_of(e);
      if (!is_answer(r) || e.tsdr_bits < 0)
        return run.fail("at " + bn + ": " + e.note + " got no reply within the slot time");
      const std::uint32_t min = after_prm ? prm_min : line_min;
      if (!ctx.outside() && (e.tsdr_bits < static_cast<std::int64_t>(min) ||
          e.tsdr_bits > static_cast<std::int64_t>(max)))
        return run.fail("at " + bn + ": the reply to " + e.note +
                        " came after TSDR = " + std::to_string(e.tsdr_bits) +
                        " bit times, outside [" + std::to_string(min) + ", " + std::to_string(max) +
                        "] (min TSDR, GSD MaxTsdr_" + bn + ")");
      lo = std::min(lo, e.tsdr_bits);
      hi = std::max(hi, e.tsdr_bits);
      if (e.note.find("Set_Prm") != std::string::npos) after_prm = true;
    }
    summary += " " + bn + " " + std::to_string(lo) + ".." + std::to_string(hi) + " (max " +
               std::to_string(max) + ");";
  }
  // No session at any baud: nothing was measured (the starting state, or a session at all, could
  // not be established) — the rule was not tested.
  if (summary.empty()) return run.error("no session at any of the GSD's baud rates:" + not_run);
  std::string msg = "TSDR in bit times per baud:" + summary;
  if (!not_run.empty()) msg += " not run at:" + not_run;
  if (ctx.outside())
    msg += " — not judged against [min TSDR, MaxTsdr]: a program behind a pty answers in the "
           "operating system's time scaled by the pace; judged: every request answered within the "
           "slot time";
  run.pass(msg);
}

// The smallest Min_Slave_Interval IEC 61158-6 allows (x 100 us), used when the GSD states none.
constexpr std::uint16_t kSmallestMinSlaveInterval = 1;

void min_slave_interval(TestContext& ctx, TestResult& res) {
  res.timing_not_meaningful = ctx.outside();
  Run run(ctx, res);
  if (!run) return;
  const std::uint16_t gsd_msi = ctx.spec().gsd->slave_features().min_slave_intervall;
  const std::uint16_t msi = gsd_msi != 0 ? gsd_msi : kSmallestMinSlaveInterval;
  const std::string assumed =
      gsd_msi != 0 ? ""
                   : "; the GSD states no Min_Slave_Intervall (GSD-08), so the smallest legal value " +
                         std::to_string(kSmallestMinSlaveInterval) + " (" +
                         std::to_string(kSmallestMinSlaveInterval * 100) + " us) was used";
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const bus::Ticks interval = static_cast<bus::Ticks>(msi) * 100 * bus::kTicksPerUs;
  const auto out = run.outputs(0x00);
  bus::Ticks prev = -1, shortest = INT64_MAX, longest = 0;
  constexpr int kPolls = 20;
  for (int i = 0; i < kPolls; ++i) {
    std::optional<bus::Ticks> nb;
    if (prev >= 0) nb = prev + interval;
    const Exchange e = run.data_exchange(out, "Data_Exchange " + std::to_string(i + 1), nb);
    const Reply r = reply_of(e);
    if (!(r.ok_with_data() || (r.kind == Reply::Kind::Sc && ctx.input_len() == 0)))
      return run.fail("Data_Exchange " + std::to_string(i + 1) + ", " +
                      std::to_string(prev >= 0 ? bus::ticks_to_us(e.request_start - prev) : 0) +
                      " us after the previous poll (Min_Slave_Intervall " +
                      std::to_string(msi * 100) + " us), answered " + r.describe() + assumed);
    if (prev >= 0) {
      shortest = std::min(shortest, e.request_start - prev);
      longest = std::max(longest, e.request_start - prev);
    }
    prev = e.request_start;
  }
  std::string msg = std::to_string(kPolls) + " Data_Exchanges answered, request starts " +
                    std::to_string(bus::ticks_to_us(shortest)) + ".." +
                    std::to_string(bus::ticks_to_us(longest)) + " us apart (Min_Slave_Intervall " +
                    std::to_string(msi * 100) + " us)";
  if (shortest > interval)
    msg += "; one message cycle is longer than Min_Slave_Intervall at this baud";
  run.pass(msg + assumed);
}

void tsyn(TestContext& ctx, TestResult& res) {
  res.timing_not_meaningful = ctx.outside();
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  // Slave_Diag, Get_Cfg and Rd_Inp in turn (no Data_Exchange: how fast the slave may be polled
  // is TIM-02's rule), each 33 bit times after the end of the previous reply.
  const struct {
    std::uint8_t sap;
    const char* name;
  } services[] = {{60, "Slave_Diag"}, {59, "Get_Cfg"}, {56, "Rd_Inp"}};
  Exchange prev = run.service(60, {}, "Slave_Diag");
  std::int64_t worst = 0;
  for (int i = 0; i < 6; ++i) {
    if (!prev.answered) return run.fail(prev.note + " was not answered");
    const bus::Ticks at = prev.response_end + run.bits(fdl::BusParams::kTsyn);
    const auto& sv = services[i % 3];
    Exchange e = run.service(sv.sap, {}, std::string(sv.name) + " after 33 bit times of idle", at);
    const std::int64_t idle =
        bus::ticks_to_bits(e.request_start - prev.response_end, run.bus().baud());
    worst = std::max(worst, idle);
    const Reply r = reply_of(e);
    if (!is_answer(r))
      return run.fail(e.note + " (" + std::to_string(idle) +
                      " bit times after the previous reply) "
                      "got " +
                      r.describe());
    prev = std::move(e);
  }
  std::string msg = "six requests sent after 33 bit times of idle were all answered";
  if (worst > static_cast<std::int64_t>(fdl::BusParams::kTsyn))
    msg += " (the tester could not keep exactly 33: up to " + std::to_string(worst) + ")";
  run.pass(msg);
}

}  // namespace

void add_timing_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "TIM-01", kTimingGroup, "TSDR at every supported baud rate",
      "The responder answers no earlier than min TSDR (11 bit times, or what Set_Prm octet 4 set) "
      "and no later than the GSD's MaxTsdr for the baud, at every baud the GSD supports "
      "(IEC 61158-4-3 station delay; protocol-facts.md §C.1, §C.2, §D.2)",
      {SlaveMutant::TsdrTooLate}, tsdr_every_baud));
  out.push_back(make_case(
      "TIM-02", kTimingGroup, "Min_Slave_Interval",
      "A slave polled with Data_Exchange at its GSD Min_Slave_Intervall (request start to request "
      "start) answers every poll (IEC 61158-6 DP bus parameter Min_Slave_Interval; "
      "protocol-facts.md §C.2)",
      {SlaveMutant::SlowSlaveInterval}, min_slave_interval));
  out.push_back(make_case(
      "TIM-03", kTimingGroup, "Request after TSYN answered",
      "A station is ready to receive once the line has been idle for TSYN = 33 bit times; a "
      "request "
      "that follows the slave's reply after exactly 33 bit times is answered (IEC 61158-4-3 "
      "synchronisation time; protocol-facts.md §A, §C.2)",
      // Its Get_Cfg reply is checked for its SAPs like every reply (battery.cpp).
      {devices::SlaveMutant::GetCfgSapsNotSwapped}, tsyn));
}

}  // namespace pbvbus::conformance::detail
