// Group "Global_Control" (GC-nn): Clear_Data, Sync/Unsync, Freeze/Unfreeze, Group_Select and
// the enabling of Sync/Freeze by Set_Prm (IEC 61158-6 DP Global_Control service;
// protocol-facts.md §D.6, §D.2 Station_Status, §D.4 Not_Supported).
//
// Global_Control goes as the master sends it: SDN (FC 0x46) to the broadcast address 127,
// DSAP 58, SSAP 62, DU = Control_Command, Group_Select.
//
// Decisions:
// - What Clear_Data and Sync do is visible only on the device side (the outputs it applies to
//   the process): those tests look at the model's application (white box) and are n/a for an
//   outside slave. Rd_Outp is no substitute: it shows the outputs RECEIVED (docs/dp-slave.md).
// - Freeze is visible on the wire when the inputs change by themselves: for a model every input
//   module gets a COUNTER of DP cycles; for an outside slave the test first watches its inputs
//   over four Data_Exchanges and is n/a if they never change.
// - Unsync/Unfreeze: the test does not judge the instant of the Unsync (the standard only says
//   the slave "returns to immediate output"); it checks that the next Data_Exchange's outputs
//   are applied at once.

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kGlobalControlGroup = "Global_Control";
constexpr std::uint8_t kClearData = 0x02;
constexpr std::uint8_t kUnfreeze = 0x04;
constexpr std::uint8_t kFreeze = 0x08;
constexpr std::uint8_t kUnsync = 0x10;
constexpr std::uint8_t kSync = 0x20;

/// Common precondition of the white-box output tests.
/// need_model_outputs() before any session is opened: an n/a test needs no starting state
/// (so a DUT whose starting state cannot be established does not turn it into an error).
bool model_outputs_visible(TestContext& ctx, TestResult& res) {
  if (ctx.outside()) {
    not_applicable(res,
                   "what the slave applies to its outputs is not visible on the bus (an outside "
                   "slave); Rd_Outp shows the received outputs, not the applied ones");
    return false;
  }
  if (ctx.output_len() == 0) {
    not_applicable(res, "the configuration has no outputs");
    return false;
  }
  return true;
}

bool need_model_outputs(Run& run) {
  if (!run.model()) {
    run.na(
        "what the slave applies to its outputs is not visible on the bus (an outside slave); "
        "Rd_Outp shows the received outputs, not the applied ones");
    return false;
  }
  if (run.ctx().output_len() == 0) {
    run.na("the configuration has no outputs");
    return false;
  }
  return true;
}

/// Sends Data_Exchange with `out`; false (and a Fail) unless it is answered with data or SC.
bool exchange_ok(Run& run, std::span<const std::uint8_t> out, const std::string& note) {
  const Reply r = reply_of(run.data_exchange(out, note));
  const bool ok = r.ok_with_data() || (r.kind == Reply::Kind::Sc && run.ctx().input_len() == 0);
  if (!ok) run.fail(note + ": Data_Exchange answered " + r.describe() + " instead of the inputs");
  return ok;
}

/// White box: the applied outputs equal `want`; else Fail with `when`.
bool outputs_are(Run& run, std::span<const std::uint8_t> want, const std::string& when) {
  const auto got = applied_outputs(*run.model());
  if (std::equal(got.begin(), got.end(), want.begin(), want.end())) return true;
  run.fail(when + ": " + outputs_text(got, want));
  return false;
}

void clear_data(TestContext& ctx, TestResult& res) {
  if (!model_outputs_visible(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !need_model_outputs(run)) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const auto a = run.outputs(0xA5);
  const auto zero = run.outputs(0x00);
  if (!exchange_ok(run, a, "outputs A5")) return;
  if (!outputs_are(run, a, "after Data_Exchange in Operate")) return;
  run.global_control(kClearData, 0x00, "Global_Control Clear_Data (02 00)");
  if (!outputs_are(run, zero, "after Clear_Data")) return;
  if (!exchange_ok(run, a, "outputs A5 while Clear_Data holds")) return;
  if (!outputs_are(run, zero, "after a Data_Exchange while Clear_Data holds")) return;
  run.global_control(0x00, 0x00, "Global_Control Operate (00 00)");
  if (!exchange_ok(run, a, "outputs A5 in Operate again")) return;
  if (!outputs_are(run, a, "after Operate (00 00) and a new Data_Exchange")) return;
  run.pass(
      "Clear_Data set the applied outputs to 00 and held them through a Data_Exchange; "
      "Operate released them");
}

void sync_unsync(TestContext& ctx, TestResult& res) {
  if (!ctx.spec().gsd->slave_features().sync_mode_supp)
    return not_applicable(res, "the GSD says Sync_Mode_supp = 0");
  if (!model_outputs_visible(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !need_model_outputs(run)) return;
  dp::SlaveParams p = ctx.params();
  p.station_status |= dp::kPrmSyncReq;
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("Set_Prm with Sync_Req: " + why);
  const auto a = run.outputs(0x11), b = run.outputs(0x22), c = run.outputs(0x33),
             d = run.outputs(0x44);
  if (!exchange_ok(run, a, "outputs 11")) return;
  if (!outputs_are(run, a, "before the first Sync")) return;
  run.global_control(kSync, 0x00, "Global_Control Sync (20 00)");
  if (!exchange_ok(run, b, "outputs 22 after Sync")) return;
  if (!outputs_are(run, a,
                   "after Sync and a Data_Exchange with 22 (must be held until the next "
                   "Sync)"))
    return;
  if (auto dg = run.diag(why, "Slave_Diag in sync mode"); !dg) {
    return run.fail(why);
  } else if ((dg->status_2 & dp::kDiagSyncMode) == 0) {
    return run.fail("the diagnosis after Sync lacks Sync_Mode (octet 2 bit 5): " +
                    hex(dg->encode()));
  }
  run.global_control(kSync, 0x00, "Global_Control Sync (20 00) again");
  if (!outputs_are(run, b, "after the second Sync (latches 22)")) return;
  if (!exchange_ok(run, c, "outputs 33")) return;
  if (!outputs_are(run, b, "after a Data_Exchange with 33 in sync mode")) return;
  run.global_control(kUnsync, 0x00, "Global_Control Unsync (10 00)");
  if (!exchange_ok(run, d, "outputs 44 after Unsync")) return;
  if (!outputs_are(run, d, "after Unsync and a Data_Exchange with 44 (immediate output)")) return;
  run.pass(
      "Sync latched the outputs, later outputs were held until the next Sync, Unsync "
      "returned to immediate output");
}

/// The inputs of `n` Data_Exchanges (empty vector for an SC answer); nullopt = a Fail was set.
std::optional<std::vector<std::vector<std::uint8_t>>> inputs_of(Run& run, int n,
                                                                const std::string& note) {
  std::vector<std::vector<std::uint8_t>> v;
  const auto out = run.outputs(0x00);
  for (int i = 0; i < n; ++i) {
    const Reply r = reply_of(run.data_exchange(out, note));
    if (!r.ok_with_data()) {
      run.fail(note + ": Data_Exchange answered " + r.describe() + " instead of the inputs");
      return std::nullopt;
    }
    v.push_back(r.data);
  }
  return v;
}

bool all_equal(const std::vector<std::vector<std::uint8_t>>& v) {
  for (const auto& x : v)
    if (x != v.front()) return false;
  return true;
}

/// Makes the model's inputs change every DP cycle (a counter per input module).
void counting_inputs(Run& run) {
  auto* m = run.model();
  if (!m) return;
  for (std::size_t i = 0; i < m->module_count(); ++i)
    if (m->application().module(i).in_len > 0)
      m->set_behaviour(i, devices::IoBehaviour::counter_per_cycle());
}

void freeze_unfreeze(TestContext& ctx, TestResult& res) {
  if (!ctx.spec().gsd->slave_features().freeze_mode_supp)
    return not_applicable(res, "the GSD says Freeze_Mode_supp = 0");
  if (ctx.input_len() == 0) return not_applicable(res, "the configuration has no inputs");
  Run run(ctx, res);
  if (!run) return;
  counting_inputs(run);
  dp::SlaveParams p = ctx.params();
  p.station_status |= dp::kPrmFreezeReq;
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("Set_Prm with Freeze_Req: " + why);
  const auto live = inputs_of(run, 4, "inputs before Freeze");
  if (!live) return;
  if (all_equal(*live))
    return run.na(
        "the inputs did not change over four Data_Exchanges without Freeze, so frozen "
        "inputs cannot be told from live ones");
  run.global_control(kFreeze, 0x00, "Global_Control Freeze (08 00)");
  const auto frozen = inputs_of(run, 4, "inputs after Freeze");
  if (!frozen) return;
  if (!all_equal(*frozen))
    return run.fail("the inputs changed after Freeze: " + hex(frozen->front()) + " then " +
                    hex(frozen->back()) + " (must stay frozen until the next Freeze or Unfreeze)");
  if (auto dg = run.diag(why, "Slave_Diag in freeze mode"); !dg) {
    return run.fail(why);
  } else if ((dg->status_2 & dp::kDiagFreezeMode) == 0) {
    return run.fail("the diagnosis after Freeze lacks Freeze_Mode (octet 2 bit 4): " +
                    hex(dg->encode()));
  }
  run.global_control(kUnfreeze, 0x00, "Global_Control Unfreeze (04 00)");
  const auto after = inputs_of(run, 4, "inputs after Unfreeze");
  if (!after) return;
  if (all_equal(*after))
    return run.fail("the inputs stayed at " + hex(after->front()) +
                    " over four Data_Exchanges after Unfreeze (must be live again)");
  run.pass("Freeze held the inputs (" + hex(frozen->front()) +
           ") over four Data_Exchanges; Unfreeze made them live again");
}

/// GC-04 for an outside slave (no view of its applied outputs): Group_Select seen through the
/// Sync_Mode bit of the diagnosis (§D.4 octet 2 bit 5) after Sync to another group (ignored)
/// and to its own (obeyed).
void group_select_black_box(Run& run) {
  if (!run.ctx().spec().gsd->slave_features().sync_mode_supp)
    return run.na("an outside slave's Group_Select is seen through Sync_Mode, and the GSD says "
                  "Sync_Mode_supp = 0");
  dp::SlaveParams p = run.ctx().params();
  p.group_ident = 0x01;  // group 1
  p.station_status |= dp::kPrmSyncReq;
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("Set_Prm with Group_Ident 01 and Sync_Req: " + why);
  if (!exchange_ok(run, run.outputs(0x5A), "outputs 5A")) return;
  run.global_control(kSync, 0x02, "Global_Control Sync to group 2 (20 02)");
  auto d = run.diag(why, "Slave_Diag after Sync to group 2");
  if (!d) return run.fail(why);
  if ((d->status_2 & dp::kDiagSyncMode) != 0)
    return run.fail("after Sync to group 2 only (the slave is in group 1: must be ignored) the "
                    "diagnosis " + hex(d->encode()) + " has Sync_Mode=1 (expected Sync_Mode=0)");
  run.global_control(kSync, 0x01, "Global_Control Sync to group 1 (20 01)");
  d = run.diag(why, "Slave_Diag after Sync to group 1");
  if (!d) return run.fail(why);
  if ((d->status_2 & dp::kDiagSyncMode) == 0)
    return run.fail("after Sync to its own group 1 the diagnosis " + hex(d->encode()) +
                    " has Sync_Mode=0 (expected Sync_Mode=1)");
  run.pass("Sync to another group was ignored (Sync_Mode=0), to its own group obeyed (Sync_Mode=1)");
}

void group_select(TestContext& ctx, TestResult& res) {
  if (ctx.outside() && !ctx.spec().gsd->slave_features().sync_mode_supp)
    return not_applicable(res, "an outside slave's Group_Select is seen through Sync_Mode, and "
                               "the GSD says Sync_Mode_supp = 0");
  if (!ctx.outside() && ctx.output_len() == 0)
    return not_applicable(res, "the configuration has no outputs");
  Run run(ctx, res);
  if (!run) return;
  if (!run.model()) return group_select_black_box(run);
  if (!need_model_outputs(run)) return;
  dp::SlaveParams p = ctx.params();
  p.group_ident = 0x01;  // group 1
  std::string why;
  if (!run.start_up(why, &p)) return run.fail("Set_Prm with Group_Ident 01: " + why);
  const auto a = run.outputs(0x5A);
  const auto zero = run.outputs(0x00);
  if (!exchange_ok(run, a, "outputs 5A")) return;
  if (!outputs_are(run, a, "in Operate")) return;
  run.global_control(kClearData, 0x02, "Global_Control Clear_Data to group 2 (02 02)");
  if (!outputs_are(run, a,
                   "after Clear_Data to group 2 only (the slave is in group 1: must be "
                   "ignored)"))
    return;
  run.global_control(kClearData, 0x01, "Global_Control Clear_Data to group 1 (02 01)");
  if (!outputs_are(run, zero, "after Clear_Data to its own group 1")) return;
  run.pass("Clear_Data to another group was ignored, to its own group obeyed");
}

void sync_freeze_not_enabled(TestContext& ctx, TestResult& res) {
  const auto& f = ctx.spec().gsd->slave_features();
  if (!f.sync_mode_supp && !f.freeze_mode_supp)
    return not_applicable(res, "the GSD supports neither Sync nor Freeze (GC-06 covers the refusal)");
  if (!model_outputs_visible(ctx, res)) return;
  Run run(ctx, res);
  if (!run || !need_model_outputs(run)) return;
  counting_inputs(run);
  dp::SlaveParams p = ctx.params();
  p.station_status &= static_cast<std::uint8_t>(~(dp::kPrmSyncReq | dp::kPrmFreezeReq));
  std::string why;
  if (!run.start_up(why, &p)) return run.not_ready(why);
  const auto a = run.outputs(0x11), b = run.outputs(0x22);
  if (!exchange_ok(run, a, "outputs 11")) return;
  run.global_control(kSync | kFreeze, 0x00, "Global_Control Sync+Freeze (28 00), not enabled");
  if (!exchange_ok(run, b, "outputs 22")) return;
  if (!outputs_are(run, b,
                   "after Sync without Sync_Req in Set_Prm (must be ignored: immediate "
                   "output)"))
    return;
  if (ctx.input_len() > 0) {
    const auto in = inputs_of(run, 3, "inputs after Freeze without Freeze_Req");
    if (!in) return;
    if (all_equal(*in))
      return run.fail("the inputs stayed at " + hex(in->front()) +
                      " after Freeze without Freeze_Req in Set_Prm (must be ignored)");
  }
  if (auto dg = run.diag(why, "Slave_Diag"); !dg) {
    return run.fail(why);
  } else if ((dg->status_2 & (dp::kDiagSyncMode | dp::kDiagFreezeMode)) != 0) {
    return run.fail(
        "the diagnosis shows Sync_Mode/Freeze_Mode although Set_Prm did not enable "
        "them: " +
        hex(dg->encode()));
  }
  run.pass("Sync and Freeze without Sync_Req/Freeze_Req in Set_Prm had no effect");
}

void sync_freeze_unsupported(TestContext& ctx, TestResult& res) {
  const auto& f = ctx.spec().gsd->slave_features();
  if (f.sync_mode_supp && f.freeze_mode_supp)
    return not_applicable(res, "the GSD supports both Sync and Freeze (Sync_Mode_supp = Freeze_Mode_supp = 1)");
  Run run(ctx, res);
  if (!run) return;
  dp::SlaveParams p = ctx.params();
  std::string asked;
  if (!f.sync_mode_supp) {
    p.station_status |= dp::kPrmSyncReq;
    asked = "Sync_Req";
  }
  if (!f.freeze_mode_supp) {
    p.station_status |= dp::kPrmFreezeReq;
    asked += asked.empty() ? "Freeze_Req" : " and Freeze_Req";
  }
  std::string why;
  if (!run.diag(why, "Slave_Diag")) return run.fail(why);
  run.set_prm(p.set_prm_du(), "Set_Prm with " + asked + " (unsupported)");
  const auto dg = run.diag(why, "Slave_Diag after Set_Prm");
  if (!dg) return run.fail(why);
  if ((dg->status_1 & dp::kDiagNotSupported) == 0)
    return run.fail("Set_Prm with " + asked +
                    " that the GSD does not support: the diagnosis lacks "
                    "Not_Supported (octet 1 bit 4): " +
                    hex(dg->encode()));
  run.pass("Set_Prm with " + asked + " gave Not_Supported in the diagnosis: " + hex(dg->encode()));
}

}  // namespace

void add_global_control_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "GC-01", kGlobalControlGroup, "Clear_Data sets the outputs safe",
      "Global_Control with Clear_Data (Control_Command bit 1) sets the outputs to the safe state "
      "and holds them there until a Global_Control without Clear_Data; outputs received meanwhile "
      "are not applied (IEC 61158-6 DP Global_Control; protocol-facts.md §D.6, §D.9 Clear)",
      {SlaveMutant::IgnoreClearData}, clear_data));
  out.push_back(make_case(
      "GC-02", kGlobalControlGroup, "Sync holds the outputs, Unsync releases them",
      "With Sync_Req in Set_Prm, Sync applies the last received outputs and holds later ones "
      "until the next Sync; the diagnosis shows Sync_Mode; Unsync returns to immediate output "
      "(IEC 61158-6 DP Global_Control; protocol-facts.md §D.6, §D.4)",
      {SlaveMutant::IgnoreSync}, sync_unsync));
  out.push_back(make_case(
      "GC-03", kGlobalControlGroup, "Freeze holds the inputs, Unfreeze releases them",
      "With Freeze_Req in Set_Prm, Freeze samples the inputs and Data_Exchange returns that "
      "sample until the next Freeze or Unfreeze; the diagnosis shows Freeze_Mode (IEC 61158-6 DP "
      "Global_Control; protocol-facts.md §D.6, §D.4)",
      {SlaveMutant::IgnoreFreeze}, freeze_unfreeze));
  out.push_back(make_case(
      "GC-04", kGlobalControlGroup, "Group_Select",
      "A Global_Control applies only if Group_Select & Group_Ident != 0 or Group_Select = 0; a "
      "command to another group is ignored (IEC 61158-6 DP Global_Control; protocol-facts.md "
      "§D.6, §D.2 octet 7)",
      {}, group_select));
  out.push_back(make_case(
      "GC-05", kGlobalControlGroup, "Sync and Freeze need enabling in Set_Prm",
      "Sync and Freeze act only when Set_Prm enabled them with Sync_Req/Freeze_Req; otherwise "
      "they have no effect (IEC 61158-6 DP Set_Prm Station_Status; protocol-facts.md §D.6 "
      "\"Prior enabling\")",
      {}, sync_freeze_not_enabled));
  out.push_back(make_case(
      "GC-06", kGlobalControlGroup, "Unsupported Sync/Freeze refused with Not_Supported",
      "A slave that does not support Sync or Freeze (GSD Sync_Mode_supp/Freeze_Mode_supp = 0) "
      "answers a Set_Prm with Sync_Req/Freeze_Req by setting Not_Supported (diag octet 1 bit 4) "
      "(IEC 61158-6 DP Slave_Diag; protocol-facts.md §D.6, §D.4)",
      {}, sync_freeze_unsupported));
}

}  // namespace pbvbus::conformance::detail
