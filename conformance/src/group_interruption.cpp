// Group "Interruption" (INT-nn): bus interruption longer and shorter than the watchdog, power
// off/on of the device, and of the master (IEC 61158-6 DP response monitoring and slave state
// machine; protocol-facts.md §D.8 watchdog, §D.4 the diagnosis of an unparameterised slave,
// §D.2 WD_Fact_1/2).
//
// Decisions:
// - These tests parameterise the run's watchdog (TimingPlan, timing_plan.cpp): at least 100 ms
//   and 4 × the longest exchange at the run's baud and pace (WD_Fact_1 × WD_Fact_2 × 10 ms, or
//   × 1 ms with WD_Base_1ms in the GSD-assembled DPV1_Status_1), so that at 9.6 kbit/s, where
//   one Chk_Cfg lasts 20 ms, no normal exchange looks like a silence.
// - "Longer than the watchdog" = 1.5 × TWD of silence, "shorter" = 0.5 × TWD.
// - After a watchdog expiry or a power cycle the slave must be in Wait_Prm: Slave_Diag octet 1
//   has Station_Not_Ready, octet 4 (Master_Add) is FF, and Data_Exchange is not answered with
//   data (Prm_Req and the ident are the Start-up and GSD groups' rules). After a power cycle the
//   first four octets must read `02 05 00 FF` (Prm_Req included, as a fresh slave shows it;
//   Ext_Diag, octet 1 bit 3, tolerated: a device may report a diagnosis from its start-up).
// - "Outputs safe" is white box (the model's applied outputs read zero); for an outside slave
//   that part is skipped and the message says so.

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kInterruptionGroup = "Interruption";

/// The context's parameters with the run's watchdog (TimingPlan: at least 100 ms and four times
/// the longest exchange at the run's baud and pace).
dp::SlaveParams with_short_watchdog(const TestContext& ctx, bus::Ticks& twd) {
  dp::SlaveParams p = with_plan_watchdog(ctx, ctx.params());
  p.station_status |= dp::kPrmWdOn;
  twd = watchdog_time(p);
  return p;
}

/// The slave is back in Wait_Prm: Station_Not_Ready, no master, Data_Exchange refused.
bool in_wait_prm(Run& run, const std::string& when, std::vector<std::uint8_t>* diag6 = nullptr) {
  std::string why;
  const auto d = run.diag(why, "Slave_Diag " + when);
  if (!d) {
    run.fail(when + ": " + why);
    return false;
  }
  if (diag6) {
    const auto b = d->encode();
    diag6->assign(b.begin(), b.end());
  }
  if (!wait_prm_diag(*d)) {
    run.fail(
        when + ": the diagnosis " + hex(d->encode()) +
        " is not that of a slave in Wait_Prm (octet 1 Station_Not_Ready, octet 4 FF expected)");
    return false;
  }
  const Reply dx = reply_of(run.data_exchange(run.outputs(0x00), "Data_Exchange " + when));
  if (dx.ok_with_data() || dx.kind == Reply::Kind::Sc) {
    run.fail(when + ": Data_Exchange was answered " + dx.describe() +
             " (must be refused in Wait_Prm)");
    return false;
  }
  return true;
}

/// White box: the model's applied outputs are all zero. True for an outside slave.
bool outputs_safe(Run& run, const std::string& when) {
  if (!run.model()) return true;
  const auto got = applied_outputs(*run.model());
  const std::vector<std::uint8_t> zero(got.size(), 0);
  if (got == zero) return true;
  run.fail(when + ": " + outputs_text(got, zero));
  return false;
}

/// Start-up with the short watchdog and one Data_Exchange with outputs `fill`.
bool operate(Run& run, const dp::SlaveParams& p, std::uint8_t fill) {
  std::string why;
  if (!run.start_up(why, &p)) {
    run.not_ready(why, "the GSD's parameters and the run's watchdog (WD_On)");
    return false;
  }
  const Reply r = reply_of(run.data_exchange(run.outputs(fill), "Data_Exchange"));
  if (!data_answer(run.ctx(), r)) {
    run.fail("Data_Exchange after the start-up answered " + r.describe());
    return false;
  }
  return true;
}

void long_interruption(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  bus::Ticks twd = 0;
  const auto p = with_short_watchdog(ctx, twd);
  if (!operate(run, p, 0x0F)) return;
  run.bus().set_bus_interrupted(true);
  run.bus().idle(twd + twd / 2);
  run.bus().set_bus_interrupted(false);
  if (!in_wait_prm(run, "after a bus interruption of 1.5 x TWD")) return;
  if (!outputs_safe(run, "after the watchdog expired")) return;
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("fresh start-up after the interruption: " + why);
  const Reply r =
      reply_of(run.data_exchange(run.outputs(0x0F), "Data_Exchange after the new start-up"));
  if (!data_answer(ctx, r))
    return run.fail("Data_Exchange after the new start-up answered " + r.describe());
  run.pass("after " + std::to_string(bus::ticks_to_us(twd + twd / 2) / 1000) +
           " ms without bus (TWD " + std::to_string(bus::ticks_to_us(twd) / 1000) +
           " ms) the slave was in Wait_Prm; a fresh start-up succeeded");
}

void short_interruption(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  bus::Ticks twd = 0;
  const auto p = with_short_watchdog(ctx, twd);
  if (!operate(run, p, 0x0F)) return;
  run.bus().set_bus_interrupted(true);
  run.bus().idle(twd / 2);
  run.bus().set_bus_interrupted(false);
  const Reply r = reply_of(run.data_exchange(run.outputs(0x0F), "Data_Exchange after 0.5 x TWD"));
  if (!data_answer(ctx, r))
    return run.fail("after a bus interruption of half the watchdog time Data_Exchange answered " +
                    r.describe() + " (the slave must still be in Data_Exch)");
  std::string why;
  const auto d = run.diag(why, "Slave_Diag after the short interruption");
  if (!d) return run.fail(why);
  if (!diag_ready(*d) || d->master_add != run.tester())
    return run.fail("after the short interruption the diagnosis " + hex(d->encode()) +
                    " is not that of a slave in Data_Exch with the tester");
  run.pass("a bus interruption of half the watchdog time left the slave in Data_Exch");
}

void dut_power_cycle(TestContext& ctx, TestResult& res) {
  if (ctx.outside())
    return not_applicable(res, "the battery cannot power a program behind a pty off and on (it can "
                               "only switch the pty's own station, which the program does not see)");
  Run run(ctx, res);
  if (!run) return;
  bus::Ticks twd = 0;
  const auto p = with_short_watchdog(ctx, twd);
  if (!operate(run, p, 0xF0)) return;
  run.bus().set_dut_power(false);
  run.bus().idle(10 * bus::kTicksPerMs);
  run.bus().set_dut_power(true);
  run.bus().idle(10 * bus::kTicksPerMs);
  std::vector<std::uint8_t> d6;
  if (!in_wait_prm(run, "after power off/on", &d6)) return;
  const std::vector<std::uint8_t> want = {0x02, 0x05, 0x00, 0xFF};
  std::vector<std::uint8_t> masked(d6.begin(), d6.begin() + 4);
  masked[0] &= static_cast<std::uint8_t>(~dp::kDiagExtDiag);
  if (masked != want)
    return run.fail("after power off/on the diagnosis reads " + hex(d6) +
                    ", expected 02 05 00 FF ..");
  if (!outputs_safe(run, "after power off/on")) return;
  run.pass(std::string("after power off/on the slave was in Wait_Prm (") + hex(d6) + ")" +
           (run.model() ? " with its outputs safe" : "; outputs not visible (outside slave)"));
}

void master_power_off(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  bus::Ticks twd = 0;
  const auto p = with_short_watchdog(ctx, twd);
  if (!operate(run, p, 0x3C)) return;
  if (run.model() && ctx.output_len() > 0) {
    const auto got = applied_outputs(*run.model());
    if (got != run.outputs(0x3C))
      return run.fail("before the master's power-off: " + outputs_text(got, run.outputs(0x3C)));
  }
  run.bus().idle(twd + twd / 2);  // the master is off: nothing on the line
  if (!outputs_safe(run, "1.5 x TWD after the master went silent")) return;
  if (!in_wait_prm(run, "after the master's power-off")) return;
  run.pass(std::string("1.5 x TWD after the master went silent the slave was in Wait_Prm") +
           (run.model() ? " with its outputs safe" : "; outputs not visible (outside slave)"));
}

}  // namespace

void add_interruption_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "INT-01", kInterruptionGroup, "Bus interruption longer than the watchdog",
      "With WD_On, a slave that hears no frame from its master for the watchdog time TWD sets its "
      "outputs safe and returns to Wait_Prm; a new start-up then succeeds (IEC 61158-6 DP "
      "response monitoring; protocol-facts.md §D.8, §D.2)",
      {SlaveMutant::IgnoreWatchdog}, long_interruption));
  out.push_back(make_case(
      "INT-02", kInterruptionGroup, "Bus interruption shorter than the watchdog",
      "A silence shorter than TWD does not end data exchange (IEC 61158-6 DP response monitoring; "
      "protocol-facts.md §D.8)",
      {}, short_interruption));
  out.push_back(make_case(
      "INT-03", kInterruptionGroup, "Power off/on of the device",
      "After power off/on the slave starts in Wait_Prm with Prm_Req and no master, diagnosis "
      "`02 05 00 FF idH idL`, its outputs safe (IEC 61158-6 DP slave state machine; "
      "protocol-facts.md §D.8, §D.4)",
      {SlaveMutant::KeepStateOnPowerCycle}, dut_power_cycle));
  out.push_back(
      make_case("INT-04", kInterruptionGroup, "Power off of the master",
                "When the master goes silent the watchdog expires: outputs safe, back to Wait_Prm "
                "(IEC 61158-6 DP response monitoring; protocol-facts.md §D.8)",
                {SlaveMutant::IgnoreWatchdog}, master_power_off));
}

}  // namespace pbvbus::conformance::detail
