// Group "Set_Slave_Add" (ADD-nn): changing the station address over the bus (IEC 61158-6 DP
// Set_Slave_Add service, SAP 55; protocol-facts.md §D.7, §D.8 Power_On/Wait_Prm).
//
// Request DU: New_Slave_Address, Ident_Number high, Ident_Number low, No_Add_Chg.
//
// Decisions:
// - n/a when the GSD says Set_Slave_Add_supp = 0.
// - The new address is 100 (101 if the DUT already sits at 100): clear of the tester (1), the
//   class-2 master (2) and the default 126.
// - "Refused" = any answer but SC (the slave engine answers RS; the standard does not name the
//   negative answer) AND the slave still answers at its old address and not at the new one.
// - An outside slave keeps its address for the rest of the run, so ADD-01 moves it back, and
//   ADD-02 (No_Add_Chg, which only a reset undoes) is n/a for it. A refusal test that finds the
//   outside slave moved anyway tries to move it back.

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kSetSlaveAddGroup = "Set_Slave_Add";

std::uint8_t other_address(std::uint8_t a) {
  return a == 100 ? 101 : 100;
}

/// The same before any session is opened (an n/a test needs no starting state).
bool supported(TestContext& ctx, TestResult& res) {
  if (!ctx.spec().gsd->slave_features().set_slave_add_supp) {
    not_applicable(res, "the GSD says Set_Slave_Add_supp = 0");
    return false;
  }
  return true;
}

bool supported(Run& run) {
  if (!run.ctx().spec().gsd->slave_features().set_slave_add_supp) {
    run.na("the GSD says Set_Slave_Add_supp = 0");
    return false;
  }
  return true;
}

/// Slave_Diag to `addr`: answered with a diagnosis?
bool answers_at(Run& run, std::uint8_t addr, const std::string& note) {
  const std::uint8_t keep = run.dut();
  run.set_dut(addr);
  const Reply r = reply_of(run.slave_diag(note));
  run.set_dut(keep);
  return standard_diag(r).has_value();
}

/// After a refusal test: an outside slave that moved anyway is moved back.
void restore(Run& run, std::uint8_t from, std::uint8_t to) {
  if (!run.model())
    run.set_slave_add(from, to, run.ctx().params().ident, false, "restore the address");
}

void new_address_taken(TestContext& ctx, TestResult& res) {
  if (!supported(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !supported(run)) return;
  const std::uint8_t old_a = run.dut(), new_a = other_address(old_a);
  const std::uint16_t ident = ctx.params().ident;
  const std::string to = " (" + std::to_string(old_a) + " -> " + std::to_string(new_a) + ")";
  const Reply r = reply_of(run.set_slave_add(old_a, new_a, ident, false, "Set_Slave_Add" + to));
  if (r.kind != Reply::Kind::Sc)
    return run.fail("Set_Slave_Add" + to + " in Wait_Prm answered " + r.describe() +
                    " instead of SC");
  if (!answers_at(run, new_a, "Slave_Diag at the new address"))
    return run.fail("no diagnosis at the new address " + std::to_string(new_a));
  if (answers_at(run, old_a, "Slave_Diag at the old address"))
    return run.fail("the slave still answers at the old address " + std::to_string(old_a));
  run.set_dut(new_a);
  dp::SlaveParams p = ctx.params();
  p.address = new_a;
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("at the new address: " + why);
  // No_Add_Chg was 0: the address may be changed again — after leaving data exchange.
  p.station_status = dp::kPrmUnlockReq;
  run.set_prm(p.set_prm_du(), "Set_Prm with Unlock_Req (back to Wait_Prm)");
  // Set_Slave_Add is accepted only in Wait_Prm (§D.7): the unlock must have taken.
  if (const auto d = run.diag(why, "Slave_Diag after the unlock (Wait_Prm expected)");
      !d || !wait_prm_diag(*d))
    return run.error("the slave is not back in Wait_Prm after the unlocking Set_Prm (" +
                     (d ? hex(d->encode()) : why) +
                     "), so moving it back could not be tried; the Set_Prm group's PRM-05 says why");
  const Reply back = reply_of(run.set_slave_add(new_a, old_a, ident, false, "Set_Slave_Add back"));
  if (back.kind != Reply::Kind::Sc)
    return run.fail("Set_Slave_Add back to " + std::to_string(old_a) +
                    " after No_Add_Chg = 0 answered " + back.describe() + " instead of SC");
  run.set_dut(old_a);
  if (!answers_at(run, old_a, "Slave_Diag at the original address"))
    return run.fail("no diagnosis at the original address after changing back");
  run.pass("the slave took address " + std::to_string(new_a) +
           " (answered there, not at the old one, and started up), and changed back");
}

void no_add_chg(TestContext& ctx, TestResult& res) {
  if (!supported(ctx, res)) return;
  if (ctx.outside())
    return not_applicable(
        res,
        "No_Add_Chg can be undone only by a reset of the device: an outside slave would "
        "stay at another address for the rest of the run");
  Run run(ctx, res);
  if (!run || !supported(run)) return;
  const std::uint8_t old_a = run.dut(), new_a = other_address(old_a);
  const std::uint8_t third = old_a == 102 ? 103 : 102;
  const std::uint16_t ident = ctx.params().ident;
  const Reply r =
      reply_of(run.set_slave_add(old_a, new_a, ident, true, "Set_Slave_Add, No_Add_Chg = 1"));
  if (r.kind != Reply::Kind::Sc)
    return run.fail("Set_Slave_Add with No_Add_Chg = 1 answered " + r.describe() +
                    " instead of SC");
  if (!answers_at(run, new_a, "Slave_Diag at the new address"))
    return run.fail("no diagnosis at the new address " + std::to_string(new_a));
  const Reply r2 = reply_of(
      run.set_slave_add(new_a, third, ident, false, "second Set_Slave_Add (after No_Add_Chg)"));
  if (r2.kind == Reply::Kind::Sc)
    return run.fail("a second Set_Slave_Add after No_Add_Chg = 1 was acknowledged (SC)");
  if (answers_at(run, third, "Slave_Diag at the refused address"))
    return run.fail("the slave answers at " + std::to_string(third) + " after a refused change");
  if (!answers_at(run, new_a, "Slave_Diag at the kept address"))
    return run.fail("the slave no longer answers at " + std::to_string(new_a));
  run.pass("after No_Add_Chg = 1 a second change was refused (" + r2.describe() + ")");
}

void wrong_ident_refused(TestContext& ctx, TestResult& res) {
  if (!supported(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !supported(run)) return;
  const std::uint8_t old_a = run.dut(), new_a = other_address(old_a);
  const std::uint16_t wrong = static_cast<std::uint16_t>(ctx.params().ident ^ 0x5555);
  const Reply r =
      reply_of(run.set_slave_add(old_a, new_a, wrong, false, "Set_Slave_Add, wrong ident"));
  const bool moved = answers_at(run, new_a, "Slave_Diag at the new address");
  if (moved) restore(run, new_a, old_a);
  if (r.kind == Reply::Kind::Sc)
    return run.fail("Set_Slave_Add with a wrong Ident_Number was acknowledged (SC)");
  if (moved)
    return run.fail("the slave answers at " + std::to_string(new_a) + " after a wrong ident");
  if (!answers_at(run, old_a, "Slave_Diag at the old address"))
    return run.fail("the slave no longer answers at " + std::to_string(old_a));
  run.pass("Set_Slave_Add with Ident_Number " +
           hex(std::vector<std::uint8_t>{static_cast<std::uint8_t>(wrong >> 8),
                                         static_cast<std::uint8_t>(wrong & 0xFF)}) +
           " refused (" + r.describe() + "), address kept");
}

void in_data_exchange(TestContext& ctx, TestResult& res) {
  if (!supported(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !supported(run)) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const std::uint8_t old_a = run.dut(), new_a = other_address(old_a);
  const Reply r = reply_of(
      run.set_slave_add(old_a, new_a, ctx.params().ident, false, "Set_Slave_Add in Data_Exch"));
  const bool moved = answers_at(run, new_a, "Slave_Diag at the new address");
  if (moved) restore(run, new_a, old_a);
  if (r.kind == Reply::Kind::Sc)
    return run.fail("Set_Slave_Add in Data_Exch was acknowledged (SC)");
  if (moved)
    return run.fail("the slave answers at " + std::to_string(new_a) +
                    " after Set_Slave_Add in Data_Exch");
  const Reply dx =
      reply_of(run.data_exchange(run.outputs(0x00), "Data_Exchange at the old address"));
  if (!dx.ok_with_data() && !(dx.kind == Reply::Kind::Sc && ctx.input_len() == 0))
    return run.fail(
        "after the refused Set_Slave_Add the slave is not in Data_Exch: Data_Exchange "
        "answered " +
        dx.describe());
  run.pass("Set_Slave_Add in Data_Exch refused (" + r.describe() + "), data exchange went on");
}

}  // namespace

void add_set_slave_add_tests(std::vector<TestCase>& out) {
  out.push_back(make_case(
      "ADD-01", kSetSlaveAddGroup, "New address taken",
      "Set_Slave_Add in Wait_Prm with the right Ident_Number changes the station address: the "
      "slave answers at the new address and no longer at the old one; with No_Add_Chg = 0 it may "
      "be changed again (IEC 61158-6 DP Set_Slave_Add; protocol-facts.md §D.7, §D.8)",
      {}, new_address_taken));
  out.push_back(make_case(
      "ADD-02", kSetSlaveAddGroup, "No_Add_Chg forbids a second change",
      "After Set_Slave_Add with No_Add_Chg != 0 a further Set_Slave_Add is refused until a reset "
      "(IEC 61158-6 DP Set_Slave_Add; protocol-facts.md §D.7)",
      {}, no_add_chg));
  out.push_back(
      make_case("ADD-03", kSetSlaveAddGroup, "Wrong ident refused",
                "Set_Slave_Add whose Ident_Number is not the slave's is refused; the address stays "
                "(IEC 61158-6 DP Set_Slave_Add; protocol-facts.md §D.7)",
                {}, wrong_ident_refused));
  out.push_back(make_case(
      "ADD-04", kSetSlaveAddGroup, "Refused in Data_Exch",
      "Set_Slave_Add is accepted only in Power_On/Wait_Prm; in Data_Exch it is refused and data "
      "exchange goes on (IEC 61158-6 DP slave state machine; protocol-facts.md §D.7, §D.8)",
      {}, in_data_exchange));
}

}  // namespace pbvbus::conformance::detail
