// Group "GSD" (GSD-nn): what the slave reports and accepts agrees with its device description
// (PI 2.122 GSD keywords; protocol-facts.md §I.2 Ident_Number, Module, User_Prm_Data_Len,
// Max_Diag_Data_Len, DPV1_Slave, Sync_Mode_supp/Freeze_Mode_supp; §D.2–§D.4 for the telegrams).
//
// Decisions:
// - Get_Cfg is compared octet by octet with the concatenated Module identifiers of the chosen
//   modules (what a configuration tool sends as Chk_Cfg): a slave reports its real configuration
//   in the encoding its GSD gives.
// - User_Prm_Data length: the GSD-assembled length is accepted (no Prm_Fault); one octet more and
//   one octet less are refused (Prm_Fault). "One more" is n/a when the GSD allows structured
//   parameter blocks after it (Prm_Block_Structure_supp) or the 237-octet limit is reached; "one
//   less" when the assembled length is 0.
// - Max_Diag_Data_Len is checked on every diagnosis the test provokes: in Wait_Prm, after a
//   Chk_Cfg with one module too many (Cfg_Fault with an identifier-related block), in data
//   exchange, and (white box, DP-V1 model) with a process alarm outstanding.
// - "DP-V1 Set_Prm accepted iff DPV1_Slave": a DP-V1 slave accepts DPV1_Enable; a DP-V0 slave
//   refuses a Set_Prm whose User_Prm_Data is led by DPV1_Status `80 00 00` (Prm_Fault).
// - Sync/Freeze: Set_Prm with Sync_Req (Freeze_Req) is accepted when the GSD supports it and
//   answered with Not_Supported when it does not.
// - Min_Slave_Intervall (GSD-08) is judged on the file alone: PI 2.122 makes it mandatory for a
//   DP slave and IEC 61158-6 gives Min_Slave_Interval the range 1..65535 (x 100 us; protocol-facts
//   §C.2, §I.2). A missing keyword or 0 is a fault of the description, not of the device's timing:
//   TIM-02 then runs with the smallest legal value (group_timing.cpp).

#include <algorithm>
#include <string>

#include "group_support.hpp"

#include "pbvbus/dp/prm.hpp"

namespace pbvbus::conformance::detail {
namespace {

constexpr const char* kGsdGroup = "GSD";

std::vector<std::uint8_t> ident_octets(std::uint16_t id) {
  return {static_cast<std::uint8_t>(id >> 8), static_cast<std::uint8_t>(id & 0xFF)};
}

void diag_ident(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  const std::uint16_t want = ctx.spec().gsd->ident_number();
  std::string why;
  auto d = run.diag(why, "Slave_Diag in Wait_Prm");
  if (!d) return run.fail(why);
  if (d->ident != want)
    return run.fail("Slave_Diag octets 5..6 read " + hex(ident_octets(d->ident)) +
                    " in Wait_Prm, the GSD "
                    "says Ident_Number " +
                    hex(ident_octets(want)));
  if (!run.start_up(why)) return run.not_ready(why);
  d = run.diag(why, "Slave_Diag in Data_Exch");
  if (!d) return run.fail(why);
  if (d->ident != want)
    return run.fail("Slave_Diag octets 5..6 read " + hex(ident_octets(d->ident)) +
                    " in Data_Exch, the GSD "
                    "says Ident_Number " +
                    hex(ident_octets(want)));
  run.pass("Slave_Diag carries Ident_Number " + hex(ident_octets(want)) +
           " before and after the start-up");
}

void get_cfg_is_gsd_cfg(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const auto want = ctx.params().chk_cfg_du();
  const Reply r = reply_of(run.get_cfg());
  if (!r.ok_with_data() || r.data != want)
    return run.fail("Get_Cfg answered " + r.describe() + ", the GSD modules give " + hex(want));
  run.pass("Get_Cfg = " + hex(want) + " (the GSD modules' identifiers)");
}

void io_lengths(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  std::string err;
  const auto len = devices::gsd_cfg_lengths(ctx.params().chk_cfg_du(), &err);
  if (!len) return run.fail("the GSD module identifiers cannot be read: " + err);
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  const std::vector<std::uint8_t> out(len->output_len, 0);
  const Reply r = reply_of(run.data_exchange(
      out, "Data_Exchange with " + std::to_string(len->output_len) + " output octets"));
  const bool ok = len->input_len == 0 ? r.kind == Reply::Kind::Sc
                                      : r.ok_with_data() && r.data.size() == len->input_len;
  if (!ok)
    return run.fail("Data_Exchange with the " + std::to_string(len->output_len) +
                    " output octets of the identifiers answered " + r.describe() + ", expected " +
                    std::to_string(len->input_len) + " input octets");
  run.pass("Data_Exchange: " + std::to_string(len->output_len) + " octets out accepted, " +
           std::to_string(len->input_len) + " in, as the identifiers say");
}

/// Set_Prm with `p`, then the diagnosis: true if Prm_Fault is set.
std::optional<bool> prm_fault_after(Run& run, const dp::SlaveParams& p, const std::string& note) {
  run.set_prm(p.set_prm_du(), note);
  std::string why;
  const auto d = run.diag(why, "Slave_Diag after " + note);
  if (!d) {
    run.fail(why);
    return std::nullopt;
  }
  return (d->status_1 & dp::kDiagPrmFault) != 0;
}

void user_prm_len(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  const auto& gsd = *ctx.spec().gsd;
  const std::size_t n = ctx.params().user_prm.size();
  std::string why;
  if (!run.start_up(why))
    return run.fail("with the " + std::to_string(n) + " assembled User_Prm_Data octets: " + why);
  std::string msg = std::to_string(n) + " octets accepted";
  const bool longer_ok = gsd.dpv1().prm_block_structure_supp || n + 1 > dp::kMaxUserPrmLen;
  if (!longer_ok) {
    dp::SlaveParams p = ctx.params();
    p.user_prm.push_back(0x00);
    const auto f =
        prm_fault_after(run, p, "Set_Prm with " + std::to_string(n + 1) + " User_Prm_Data octets");
    if (!f) return;
    if (!*f)
      return run.fail("Set_Prm with " + std::to_string(n + 1) +
                      " User_Prm_Data octets (GSD: " + std::to_string(n) + ") gave no Prm_Fault");
    msg += ", " + std::to_string(n + 1) + " refused";
  } else {
    msg += gsd.dpv1().prm_block_structure_supp
               ? ", " + std::to_string(n + 1) + " not tried (Prm_Block_Structure_supp: blocks may follow)"
               : ", " + std::to_string(n + 1) + " not tried (the Set_Prm would exceed 244 octets)";
  }
  if (n > 0) {
    // A fresh starting state, so that the Prm_Fault of the probe above cannot be read again.
    if (std::string err; !longer_ok && !run.reopen(std::nullopt, err))
      return run.error("no session for the shorter probe: " + err);
    dp::SlaveParams p = ctx.params();
    p.user_prm.pop_back();
    const auto f =
        prm_fault_after(run, p, "Set_Prm with " + std::to_string(n - 1) + " User_Prm_Data octets");
    if (!f) return;
    if (!*f)
      return run.fail("Set_Prm with " + std::to_string(n - 1) +
                      " User_Prm_Data octets (GSD: " + std::to_string(n) + ") gave no Prm_Fault");
    msg += ", " + std::to_string(n - 1) + " refused";
  }
  if (n == 0) msg += ", no shorter length exists";
  run.pass(msg + " (Prm_Fault)");
}

void max_diag_len(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  const std::size_t max = ctx.spec().gsd->slave_features().max_diag_data_len;
  std::size_t longest = 0;
  auto check = [&](const std::string& note) -> bool {
    const Reply r = reply_of(run.slave_diag(note));
    if (!r.ok_with_data()) {
      run.fail(note + " answered " + r.describe());
      return false;
    }
    longest = std::max(longest, r.data.size());
    if (r.data.size() > max) {
      run.fail(note + ": " + std::to_string(r.data.size()) + " octets " + hex(r.data) +
               ", more than Max_Diag_Data_Len = " + std::to_string(max));
      return false;
    }
    return true;
  };
  if (!check("Slave_Diag in Wait_Prm")) return;
  const auto& p = ctx.params();
  run.set_prm(p.set_prm_du());
  auto cfg = p.chk_cfg_du();
  cfg.push_back(0x10);  // one 1-octet input module too many
  run.chk_cfg(cfg, "Chk_Cfg with one module too many");
  {
    // The diagnosis after the wrong Chk_Cfg must be the Cfg_Fault one (with its identifier
    // block where the slave gives one); otherwise the long case was not provoked.
    const Reply r = reply_of(run.slave_diag("Slave_Diag after a wrong Chk_Cfg"));
    if (!r.ok_with_data() || r.data.size() < 6 || (r.data[0] & dp::kDiagCfgFault) == 0)
      return run.error("the wrong Chk_Cfg did not give a Cfg_Fault diagnosis (" + r.describe() +
                       "), so the long diagnosis could not be provoked; CFG-03 says why");
    longest = std::max(longest, r.data.size());
    if (r.data.size() > max)
      return run.fail("Slave_Diag after a wrong Chk_Cfg: " + std::to_string(r.data.size()) +
                      " octets " + hex(r.data) + ", more than Max_Diag_Data_Len = " +
                      std::to_string(max));
  }
  std::string why;
  if (!run.start_up(why)) return run.not_ready(why);
  if (!check("Slave_Diag in Data_Exch")) return;
  if (run.model() && ctx.spec().gsd->dpv1().dpv1_slave && p.dpv1()) {
    if (run.model()->apply(devices::SlaveFault::process_alarm(0, {0x01})).empty() &&
        !check("Slave_Diag with a process alarm outstanding"))
      return;
  }
  run.pass("every diagnosis was within Max_Diag_Data_Len = " + std::to_string(max) + " (longest " +
           std::to_string(longest) + ")");
}

void dpv1_prm(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  dp::SlaveParams p = ctx.params();
  std::string why;
  if (ctx.spec().gsd->dpv1().dpv1_slave) {
    if (p.user_prm.size() < 3) p.user_prm.resize(3, 0);
    p.user_prm[0] |= dp::kDpv1Enable;
    if (!run.start_up(why, &p))
      return run.fail("DPV1_Slave = 1 but Set_Prm with DPV1_Enable: " + why);
    return run.pass("DPV1_Slave = 1: Set_Prm with DPV1_Enable accepted");
  }
  p.user_prm.insert(p.user_prm.begin(), {dp::kDpv1Enable, 0x00, 0x00});
  const auto f = prm_fault_after(run, p, "Set_Prm led by DPV1_Status 80 00 00");
  if (!f) return;
  if (!*f)
    return run.fail("DPV1_Slave = 0 but a Set_Prm led by DPV1_Status 80 00 00 gave no Prm_Fault");
  run.pass("DPV1_Slave = 0: a Set_Prm led by DPV1_Status 80 00 00 was refused (Prm_Fault)");
}

void sync_freeze(TestContext& ctx, TestResult& res) {
  Run run(ctx, res);
  if (!run) return;
  const auto& f = ctx.spec().gsd->slave_features();
  std::string msg;
  const struct {
    std::uint8_t bit;
    bool supp;
    const char* name;
  } cases[] = {{dp::kPrmSyncReq, f.sync_mode_supp, "Sync_Req"},
               {dp::kPrmFreezeReq, f.freeze_mode_supp, "Freeze_Req"}};
  bool first = true;
  for (const auto& c : cases) {
    // Each probe from a fresh starting state: a Not_Supported or Prm_Fault of the one before
    // must not be read again.
    if (std::string err; !first && !run.reopen(std::nullopt, err))
      return run.error(std::string("no session for the ") + c.name + " probe: " + err);
    first = false;
    dp::SlaveParams p = ctx.params();
    p.station_status |= c.bit;
    run.set_prm(p.set_prm_du(), std::string("Set_Prm with ") + c.name);
    std::string why;
    const auto d = run.diag(why, std::string("Slave_Diag after Set_Prm with ") + c.name);
    if (!d) return run.fail(why);
    const bool ns = (d->status_1 & dp::kDiagNotSupported) != 0;
    const bool pf = (d->status_1 & dp::kDiagPrmFault) != 0;
    if (c.supp && (ns || pf))
      return run.fail(std::string("the GSD supports it, but Set_Prm with ") + c.name +
                      " gave the diagnosis " + hex(d->encode()));
    if (c.supp && d->master_add != run.tester())
      return run.fail(std::string("the GSD supports it, but the Set_Prm with ") + c.name +
                      " was not taken: the diagnosis " + hex(d->encode()) + " names master " +
                      std::to_string(d->master_add) + ", not the tester " +
                      std::to_string(run.tester()));
    if (!c.supp && !ns)
      return run.fail(std::string("the GSD does not support it, but Set_Prm with ") + c.name +
                      " gave no Not_Supported: " + hex(d->encode()));
    msg +=
        std::string(msg.empty() ? "" : "; ") + c.name + (c.supp ? " accepted" : " Not_Supported");
  }
  run.pass(msg + ", as the GSD says");
}

void min_slave_intervall_stated(TestContext& ctx, TestResult& res) {
  const auto& gsd = *ctx.spec().gsd;
  const std::uint16_t msi = gsd.slave_features().min_slave_intervall;
  res.verdict = Verdict::Fail;
  if (msi == 0) {
    // keywords() keeps the spelling as written; the reader also takes the one-l misspelling.
    const bool written = gsd.keyword("Min_Slave_Intervall") || gsd.keyword("Min_Slave_Interval");
    res.message = written ? "the GSD gives Min_Slave_Intervall = 0, outside 1..65535 (x 100 us)"
                          : "the GSD lacks the mandatory Min_Slave_Intervall";
    return;
  }
  res.verdict = Verdict::Pass;
  res.message = "Min_Slave_Intervall = " + std::to_string(msi) + " (" + std::to_string(msi * 100) + " us)";
}

}  // namespace

void add_gsd_tests(std::vector<TestCase>& out) {
  using devices::SlaveMutant;
  out.push_back(make_case(
      "GSD-01", kGsdGroup, "Diagnosis ident = Ident_Number",
      "Slave_Diag octets 5..6 carry the GSD's Ident_Number in every state (PI 2.122 Ident_Number; "
      "protocol-facts.md §D.4, §I.2)",
      {SlaveMutant::WrongDiagIdent}, diag_ident));
  out.push_back(make_case(
      "GSD-02", kGsdGroup, "Get_Cfg = the modules' identifiers",
      "Get_Cfg returns the real configuration: the identifiers of the configured GSD modules "
      "(PI 2.122 Module; protocol-facts.md §D.3, §I.1)",
      {SlaveMutant::WrongGetCfg, SlaveMutant::GetCfgSapsNotSwapped}, get_cfg_is_gsd_cfg));
  out.push_back(
      make_case("GSD-03", kGsdGroup, "Data_Exchange lengths",
                "Data_Exchange takes as many output octets and returns as many input octets as the "
                "configuration identifiers add up to (protocol-facts.md §D.3, §D.7)",
                {}, io_lengths));
  out.push_back(make_case(
      "GSD-04", kGsdGroup, "User_Prm_Data length",
      "The slave accepts exactly the User_Prm_Data the GSD assembles (User_Prm_Data_Len plus the "
      "modules' parameters) and sets Prm_Fault for any other length (PI 2.122; protocol-facts.md "
      "§I.1, §D.2, §D.4)",
      {}, user_prm_len));
  out.push_back(make_case(
      "GSD-05", kGsdGroup, "Max_Diag_Data_Len",
      "No diagnosis is longer than the GSD's Max_Diag_Data_Len (PI 2.122; protocol-facts.md §I.2, "
      "§D.4 Ext_Diag_Overflow)",
      {}, max_diag_len));
  out.push_back(
      make_case("GSD-06", kGsdGroup, "DP-V1 Set_Prm iff DPV1_Slave",
                "A Set_Prm with DPV1_Status (DPV1_Enable) is accepted exactly when the GSD says "
                "DPV1_Slave = 1 (PI 2.122; protocol-facts.md §D.2, §I.2)",
                {}, dpv1_prm));
  out.push_back(make_case(
      "GSD-07", kGsdGroup, "Sync/Freeze iff supported",
      "Set_Prm with Sync_Req/Freeze_Req is accepted when the GSD says Sync_Mode_supp/"
      "Freeze_Mode_supp = 1 and answered with Not_Supported otherwise (PI 2.122; protocol-facts.md "
      "§D.6, §D.4)",
      {}, sync_freeze));
  out.push_back(make_case(
      "GSD-08", kGsdGroup, "Min_Slave_Intervall stated",
      "The GSD of a DP slave states the mandatory Min_Slave_Intervall, 1..65535 x 100 us, the "
      "shortest time a master may leave between two polls of the slave (PI 2.122 "
      "Min_Slave_Intervall; IEC 61158-6 Min_Slave_Interval; protocol-facts.md §C.2, §I.2)",
      {}, min_slave_intervall_stated));
}

}  // namespace pbvbus::conformance::detail
