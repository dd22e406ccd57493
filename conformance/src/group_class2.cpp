// Group "Class 2" (C2-nn): a class-2 master (address 2, SSAP 62) next to the class-1 tester that
// owns the slave (IEC 61158-6 DP locking by Set_Prm Lock_Req; protocol-facts.md §D.8 "Locking",
// §D.4 octet 4 Diag.Master_Add, §D.7 Rd_Inp/Rd_Outp, §D.2 Lock/Unlock table).
//
// Decisions:
// - While locked, the slave answers anyone's Slave_Diag, Get_Cfg, Rd_Inp and Rd_Outp; Rd_Outp
//   carries the outputs the owner sent last (docs/dp-slave.md). A foreign Set_Prm/Chk_Cfg may be
//   acknowledged (the FDL acknowledges; the DP layer ignores it) — what counts is that the owner
//   (Master_Add) and data exchange with the tester stay, and a Data_Exchange from the class-2
//   master is refused.
// - "Takes control": after the tester's Set_Prm with Unlock_Req (§D.2: Lock 0, Unlock 1), or
//   after the tester's watchdog (C2-04: the run's TWD, TimingPlan) has expired, the
//   class-2 master's own start-up succeeds and Master_Add = 2.

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kClass2Group = "Class 2";

dp::SlaveParams class2_params(const TestContext& ctx) {
  dp::SlaveParams p = ctx.params();
  p.station_status = dp::kPrmLockReq | dp::kPrmWdOn;
  return p;
}

void reads_while_locked(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const auto out = run.outputs(0x3C);
  const Reply dx = reply_of(run.data_exchange(out, "tester: Data_Exchange outputs 3C"));
  if (!data_answer(ctx, dx)) return run.fail("tester's Data_Exchange answered " + dx.describe());
  const auto d = run.diag(why, "class 2: Slave_Diag", kClass2Master);
  if (!d) return run.fail("class 2: " + why);
  if (d->master_add != run.tester())
    return run.fail("class 2: Slave_Diag octet 4 (Master_Add) = " +
                    hex(std::vector<std::uint8_t>{d->master_add}) + ", expected the owner " +
                    std::to_string(run.tester()));
  const Reply cfg = reply_of(run.get_cfg("class 2: Get_Cfg", kClass2Master));
  const auto want_cfg = ctx.params().chk_cfg_du();
  if (!cfg.ok_with_data() || cfg.data != want_cfg)
    return run.fail("class 2: Get_Cfg answered " + cfg.describe() + ", expected DL " +
                    hex(want_cfg));
  const Reply in = reply_of(run.rd_inp("class 2: Rd_Inp", kClass2Master));
  const bool in_ok = ctx.input_len() == 0 ? in.kind == Reply::Kind::Sc
                                          : in.ok_with_data() && in.data.size() == ctx.input_len();
  if (!in_ok)
    return run.fail("class 2: Rd_Inp answered " + in.describe() + ", expected " +
                    std::to_string(ctx.input_len()) + " input octets");
  const Reply outp = reply_of(run.rd_outp("class 2: Rd_Outp", kClass2Master));
  const bool out_ok = ctx.output_len() == 0 ? outp.kind == Reply::Kind::Sc
                                            : outp.ok_with_data() && outp.data == out;
  if (!out_ok)
    return run.fail("class 2: Rd_Outp answered " + outp.describe() +
                    ", expected the owner's outputs " + hex(out));
  run.pass("the class-2 master read Slave_Diag (Master_Add " + std::to_string(run.tester()) +
           "), Get_Cfg, Rd_Inp and Rd_Outp of the locked slave");
}

void foreign_set_prm(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const auto p2 = class2_params(ctx);
  run.set_prm(p2.set_prm_du(), "class 2: Set_Prm (Lock_Req) to the locked slave", kClass2Master);
  run.chk_cfg(p2.chk_cfg_du(), "class 2: Chk_Cfg", kClass2Master);
  const auto d = run.diag(why, "tester: Slave_Diag after the foreign Set_Prm");
  if (!d) return run.fail(why);
  if (d->master_add != run.tester() || !diag_ready(*d))
    return run.fail("after a class-2 master's Set_Prm the diagnosis reads " + hex(d->encode()) +
                    " (the lock must keep Master_Add = " + std::to_string(run.tester()) +
                    " and data exchange)");
  const Reply dx = reply_of(run.data_exchange(run.outputs(0x00), "tester: Data_Exchange"));
  if (!data_answer(ctx, dx))
    return run.fail("after the foreign Set_Prm the tester's Data_Exchange answered " +
                    dx.describe());
  const Reply dx2 = reply_of(
      run.data_exchange(run.outputs(0x00), "class 2: Data_Exchange", std::nullopt, kClass2Master));
  if (dx2.ok_with_data() || dx2.kind == Reply::Kind::Sc)
    return run.fail(
        "the class-2 master's Data_Exchange to a slave locked by the tester was answered " +
        dx2.describe());
  run.pass("the class-2 master's Set_Prm and Chk_Cfg had no effect: Master_Add stayed " +
           std::to_string(run.tester()) + ", its Data_Exchange got " + dx2.describe());
}

/// The class-2 master's start-up, then Master_Add = 2 and data exchange with it, not the tester.
void class2_takes_over(Run& run, const std::string& after) {
  std::string why;
  const auto p2 = class2_params(run.ctx());
  if (!run.start_up(why, &p2, kClass2Master))
    return run.fail("class 2 after " + after + ": " + why);
  const auto d = run.diag(why, "class 2: Slave_Diag", kClass2Master);
  if (!d) return run.fail(why);
  if (d->master_add != kClass2Master)
    return run.fail("after the class-2 master's start-up Master_Add = " +
                    hex(std::vector<std::uint8_t>{d->master_add}) + ", expected 02");
  const Reply dx = reply_of(
      run.data_exchange(run.outputs(0x00), "class 2: Data_Exchange", std::nullopt, kClass2Master));
  if (!data_answer(run.ctx(), dx))
    return run.fail("class 2: Data_Exchange answered " + dx.describe());
  const Reply dx1 =
      reply_of(run.data_exchange(run.outputs(0x00), "tester: Data_Exchange (no longer owner)"));
  if (dx1.ok_with_data() || dx1.kind == Reply::Kind::Sc)
    return run.fail("the former owner's Data_Exchange was still answered " + dx1.describe());
  run.pass("after " + after +
           " the class-2 master's Set_Prm and Chk_Cfg succeeded, Master_Add = 2");
}

void takes_control_after_unlock(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  dp::SlaveParams unlock = ctx.params();
  unlock.station_status = dp::kPrmUnlockReq;
  run.set_prm(unlock.set_prm_du(), "tester: Set_Prm with Unlock_Req");
  class2_takes_over(run, "the tester's unlock");
}

void takes_control_after_watchdog(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  // The run's watchdog (TimingPlan), as in the Interruption group.
  dp::SlaveParams p = with_plan_watchdog(ctx, ctx.params());
  p.station_status |= dp::kPrmWdOn;
  const bus::Ticks twd = watchdog_time(p);
  std::string why;
  if (!run.start_up(why, &p)) return run.not_ready(why, "the GSD's parameters and the run's watchdog (WD_On)");
  run.bus().idle(twd + twd / 2);
  class2_takes_over(run, "the tester's watchdog expired");
}

}  // namespace

void add_class2_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "C2-01", kClass2Group, "Class-2 reads of a locked slave",
      "While another master owns the slave, a class-2 master gets Slave_Diag (Master_Add = the "
      "owner), Get_Cfg, Rd_Inp and Rd_Outp answered (IEC 61158-6 DP; protocol-facts.md §D.8 "
      "Locking, §D.4, §D.7)",
      {SlaveMutant::WrongGetCfg, SlaveMutant::GetCfgSapsNotSwapped}, reads_while_locked));
  out.push_back(make_case(
      "C2-02", kClass2Group, "Class-2 Set_Prm has no effect while locked",
      "A Set_Prm or Chk_Cfg from a master other than the owner has no effect on a locked slave; "
      "its Data_Exchange is refused (IEC 61158-6 DP locking; protocol-facts.md §D.8, §D.2)",
      {SlaveMutant::IgnoreLock}, foreign_set_prm));
  out.push_back(make_case(
      "C2-03", kClass2Group, "Class 2 takes control after unlock",
      "After the owner's Set_Prm with Unlock_Req the slave accepts another master's Set_Prm and "
      "Chk_Cfg; Master_Add becomes that master (IEC 61158-6 DP; protocol-facts.md §D.2 "
      "Lock/Unlock, "
      "§D.8)",
      {}, takes_control_after_unlock));
  out.push_back(make_case(
      "C2-04", kClass2Group, "Class 2 takes control after the owner's watchdog",
      "After the owner's watchdog has expired the slave is unlocked and accepts another master's "
      "parameterisation (IEC 61158-6 DP response monitoring; protocol-facts.md §D.8)",
      {SlaveMutant::IgnoreWatchdog}, takes_control_after_watchdog));
}

}  // namespace pbvbus::conformance::detail
