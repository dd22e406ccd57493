// Group "Set_Prm" (PRM-nn): parameterisation checks (protocol-facts §D.2, §D.4, §D.8).
//
// Decisions:
// - Set_Prm is answered SC whatever its content; faults show in the next Slave_Diag (§D.2). A
//   refused Set_Prm leaves the slave in Wait_Prm: Prm_Fault (octet 1 bit 6), Station_Not_Ready
//   and Prm_Req.
// - Wrong content: the first Ext_User_Prm_Data_Ref parameter (global area, then the modules'
//   areas) whose field can hold a value its ExtUserPrmData does not allow gets that value. A GSD
//   whose every parameter allows every value of its field has no wrong content: n/a.
// - Watchdog: TWD and the margin of the checks from the run's TimingPlan (timing_plan.cpp: at
//   least 100 ms and 4 × the longest exchange, so no normal exchange looks like a silence at any
//   baud). The slave is checked the plan's margin (a model: 1 % of TWD, at least 1 ms) before
//   and after the expiry, counted from the end of the owner's last request (the frame that
//   restarted the watchdog): each check on a fresh session, because the checking Slave_Diag
//   from the owner would itself restart the watchdog.
// - Min TSDR: Set_Prm with min TSDR 60 (or the line's max TSDR − 1 if that is lower); every reply
//   after it (Chk_Cfg, Slave_Diag, Data_Exchange) must start at least that many bit times after
//   its request.

#include <algorithm>
#include <cstdio>

#include "groups.hpp"
#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"
#include "steps.hpp"

namespace pbvbus::conformance::detail {

namespace {

using devices::SlaveMutant;

constexpr const char* kSetPrmGroup = "Set_Prm";

/// Wait_Prm after a refused Set_Prm: Prm_Fault + Station_Not_Ready (Wait_Prm itself is shown by
/// the Data_Exchange that follows getting RS; Prm_Req and the ident are the Start-up group's).
DiagExpect prm_fault(TestContext& ctx) {
  DiagExpect e;
  e.s1_mask = dp::kDiagPrmFault | dp::kDiagStationNotReady;
  e.s1 = dp::kDiagPrmFault | dp::kDiagStationNotReady;
  (void)ctx;
  return e;
}

/// Wait_Prm, released: 02 05 00 FF (Station_Status_1 without faults).
DiagExpect wait_prm(TestContext& ctx) {
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady | dp::kDiagPrmFault | dp::kDiagCfgFault;
  e.s1 = dp::kDiagStationNotReady;
  e.s2_mask = dp::kDiagPrmReq | dp::kDiagAlways1;
  e.s2 = dp::kDiagPrmReq | dp::kDiagAlways1;
  e.master = dp::kNoMaster;
  (void)ctx;
  return e;
}

/// Data_Exch, owned by `master`.
DiagExpect data_exch(TestContext& ctx, std::uint8_t master) {
  DiagExpect e;
  e.s1_mask = dp::kDiagStationNotReady | dp::kDiagPrmFault | dp::kDiagCfgFault;
  e.s1 = 0;
  e.s2_mask = dp::kDiagPrmReq | dp::kDiagAlways1;
  e.s2 = dp::kDiagAlways1;
  e.master = master;
  (void)ctx;
  return e;
}

/// Sends `p`'s Set_Prm (expects SC) and the slave must then refuse it (Prm_Fault, Wait_Prm):
/// Chk_Cfg afterwards must not bring it to data exchange either.
void expect_refused(TestContext& ctx, TestResult& r, const dp::SlaveParams& p, const std::string& what) {
  auto s = open_session(ctx, r);
  if (!s) return;
  if (check(r, "Slave_Diag", slave_diag(*s).ok_with_data() ? "" : "no diagnosis")) return;
  const auto du = prm_du(p);
  const Reply sr = set_prm(*s, du, "Set_Prm, " + what);
  if (check(r, "Set_Prm, " + what, expect_sc(sr))) return;
  if (check(r, "Slave_Diag after Set_Prm with " + what, check_diag(slave_diag(*s), prm_fault(ctx)))) return;
  // Still Wait_Prm: Chk_Cfg is refused (RS) or has no effect, Data_Exchange gets RS.
  const auto cfg = cfg_du(ctx.params());
  chk_cfg(*s, cfg, "Chk_Cfg after the refused Set_Prm");
  const auto out = output_pattern(ctx.output_len(), 0x44);
  check(r, "Data_Exchange after the refused Set_Prm", expect_rs(data_exchange(*s, out)));
}

void wrong_ident(TestContext& ctx, TestResult& r) {
  dp::SlaveParams p = ctx.params();
  p.ident = static_cast<std::uint16_t>(p.ident ^ 0x0100);
  expect_refused(ctx, r, p, "wrong Ident_Number");
}

void wrong_prm_length(TestContext& ctx, TestResult& r) {
  dp::SlaveParams p = ctx.params();
  if (!p.user_prm.empty()) p.user_prm.pop_back();
  else p.user_prm.push_back(0x00);
  expect_refused(ctx, r, p, "wrong User_Prm_Data length");
}

/// Bits a parameter's field has (Bit/BitArea) or octets × 8.
unsigned field_bits(const devices::GsdExtUserPrmData& d) {
  switch (d.type) {
    case devices::GsdDataType::Bit: return 1;
    case devices::GsdDataType::BitArea: return static_cast<unsigned>(d.bit_last - d.bit_first + 1);
    case devices::GsdDataType::Unsigned8:
    case devices::GsdDataType::Signed8: return 8;
    case devices::GsdDataType::Unsigned16:
    case devices::GsdDataType::Signed16: return 16;
    case devices::GsdDataType::Unsigned32:
    case devices::GsdDataType::Signed32: return 32;
  }
  return 8;
}

/// A value the field can hold that `d` does not allow.
std::optional<std::int64_t> forbidden_value(const devices::GsdExtUserPrmData& d) {
  const unsigned bits = field_bits(d);
  const bool is_signed = d.type == devices::GsdDataType::Signed8 || d.type == devices::GsdDataType::Signed16 ||
                         d.type == devices::GsdDataType::Signed32;
  const std::int64_t lo = is_signed ? -(std::int64_t{1} << (bits - 1)) : 0;
  const std::int64_t hi = is_signed ? (std::int64_t{1} << (bits - 1)) - 1 : (std::int64_t{1} << bits) - 1;
  std::vector<std::int64_t> candidates = {d.min_value - 1, d.max_value + 1, lo, hi};
  for (std::int64_t v = lo; v <= std::min(hi, lo + 255); ++v) candidates.push_back(v);
  for (std::int64_t v : candidates)
    if (v >= lo && v <= hi && !d.accepts(v)) return v;
  return std::nullopt;
}

void put_value(std::vector<std::uint8_t>& prm, std::size_t offset, const devices::GsdExtUserPrmData& d,
               std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  if (d.type == devices::GsdDataType::Bit || d.type == devices::GsdDataType::BitArea) {
    const unsigned n = field_bits(d);
    const auto mask = static_cast<std::uint8_t>(((1u << n) - 1) << d.bit_first);
    prm[offset] = static_cast<std::uint8_t>((prm[offset] & ~mask) | ((u << d.bit_first) & mask));
    return;
  }
  const std::size_t n = field_bits(d) / 8;
  for (std::size_t i = 0; i < n && offset + i < prm.size(); ++i)  // big-endian (§I)
    prm[offset + i] = static_cast<std::uint8_t>(u >> (8 * (n - 1 - i)));
}

void wrong_content(TestContext& ctx, TestResult& r) {
  const auto& gsd = *ctx.spec().gsd;
  dp::SlaveParams p = ctx.params();
  // Areas in User_Prm_Data order: global, then each configured module's.
  std::vector<std::pair<std::size_t, const devices::GsdPrmArea*>> areas = {{0, &gsd.global_prm()}};
  std::size_t at = gsd.global_prm().length(gsd.ext_user_prm_data());
  std::vector<devices::ModuleChoice> mods = ctx.spec().modules;
  if (mods.empty() && !gsd.modules().empty()) mods.push_back(devices::ModuleChoice::at(0));
  if (auto idx = devices::resolve_modules(gsd, mods); idx.ok()) {
    for (std::size_t m : *idx.value) {
      areas.push_back({at, &gsd.modules()[m].prm});
      at += gsd.module_prm_length(gsd.modules()[m]);
    }
  }
  for (const auto& [base, area] : areas) {
    for (const auto& ref : area->refs) {
      const auto it = gsd.ext_user_prm_data().find(ref.ref);
      if (it == gsd.ext_user_prm_data().end()) continue;
      const auto v = forbidden_value(it->second);
      const std::size_t off = base + ref.offset;
      if (!v || off + std::max<std::size_t>(1, field_bits(it->second) / 8) > p.user_prm.size()) continue;
      put_value(p.user_prm, off, it->second, *v);
      expect_refused(ctx, r, p,
                     "\"" + it->second.name + "\" = " + std::to_string(*v) + " (outside its ExtUserPrmData)");
      return;
    }
  }
  not_applicable(r, "every ExtUserPrmData of the GSD allows every value of its field: no wrong content exists");
}

void lock_against_other_master(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  if (precondition(r, start_up(*s, ctx))) return;
  const std::uint8_t me = tester_address(*s);
  dp::SlaveParams other = ctx.params();
  const auto du = prm_du(other);
  const Reply sr = set_prm(*s, du, "Set_Prm (Lock_Req) from master 2", kOtherMaster);
  if (check(r, "Set_Prm from master 2 (answered SC without effect)", expect_sc(sr))) return;
  if (check(r, "Slave_Diag (Master_Add stays the tester, still Data_Exch)",
            check_diag(slave_diag(*s), data_exch(ctx, me))))
    return;
  const auto out = output_pattern(ctx.output_len(), 0x55);
  const Reply dx = data_exchange(*s, out, "Data_Exchange from the owner");
  if (ctx.input_len() == 0) check(r, "Data_Exchange from the owner", expect_sc(dx));
  else if (!dx.ok_with_data()) fail(r, "Data_Exchange from the owner: " + dx.describe());
}

void unlock(TestContext& ctx, TestResult& r) {
  auto s = open_session(ctx, r);
  if (!s) return;
  if (precondition(r, start_up(*s, ctx))) return;
  dp::SlaveParams p = ctx.params();
  p.station_status = dp::kPrmUnlockReq;
  const auto du = prm_du(p);
  if (check(r, "Set_Prm (Lock_Req 0, Unlock_Req 1)", expect_sc(set_prm(*s, du, "Set_Prm, unlock")))) return;
  if (check(r, "Slave_Diag after unlock", check_diag(slave_diag(*s), wait_prm(ctx)))) return;
  const auto out = output_pattern(ctx.output_len(), 0x66);
  check(r, "Data_Exchange after unlock", expect_rs(data_exchange(*s, out)));
}

/// Start-up with `p`, one Data_Exchange, silence until `offset` from the end of that request
/// (the watchdog's last restart), then Slave_Diag.
Reply after_silence(TestContext& ctx, TestResult& r, Session& s, const dp::SlaveParams& p, bus::Ticks offset,
                    const std::string& note) {
  if (precondition(r, start_up(s, ctx, p), "the GSD's parameters and the run's watchdog settings"))
    return {};
  const auto out = output_pattern(ctx.output_len(), 0x77);
  const Reply dx = data_exchange(s, out, "Data_Exchange (last frame from the owner)");
  if (!dx.ok_with_data() && !(dx.kind == Reply::Kind::Sc && ctx.input_len() == 0)) {
    error(r, "precondition not established: the Data_Exchange that starts the silence was answered " +
                 dx.describe() + ", not with the inputs (the slave is not in Data_Exch)");
    return {};
  }
  const Exchange& last = s.bus().transcript().back();
  const bus::Ticks at = last.request_end + offset;
  const auto diag = srd(s.dut_address(), tester_address(s), dp::kSapSlaveDiag, dp::kSapMs0, {});
  return reply_of(s.bus().request(diag, note, at));
}

std::string ms(bus::Ticks t) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f ms", static_cast<double>(t) / static_cast<double>(bus::kTicksPerMs));
  return b;
}

/// The Set_Prm of the watchdog tests: the battery's with the run's watchdog (TimingPlan).
dp::SlaveParams watchdog_params(TestContext& ctx) { return with_plan_watchdog(ctx, ctx.params()); }

void watchdog_expiry(TestContext& ctx, TestResult& r) {
  r.timing_not_meaningful = ctx.outside();
  dp::SlaveParams p = watchdog_params(ctx);
  p.station_status = static_cast<std::uint8_t>(p.station_status | dp::kPrmWdOn | dp::kPrmLockReq);
  const bus::Ticks twd = watchdog_time(p);
  {
    auto s = open_session(ctx, r);
    if (!s) return;
    const bus::Ticks margin = ctx.timing().wd_margin;
    const Reply before = after_silence(ctx, r, *s, p, twd - margin, "Slave_Diag " + ms(margin) + " before TWD");
    if (r.verdict != Verdict::Pass) return;
    if (check(r, "just before the watchdog expires", check_diag(before, data_exch(ctx, tester_address(*s)))))
      return;
  }
  auto s = open_session(ctx, r);
  if (!s) return;
  const bus::Ticks margin = ctx.timing().wd_margin;
  const Reply after = after_silence(ctx, r, *s, p, twd + margin, "Slave_Diag " + ms(margin) + " after TWD");
  if (r.verdict != Verdict::Pass) return;
  check(r, "just after the watchdog expired (back to Wait_Prm)", check_diag(after, wait_prm(ctx)));
}

void watchdog_off(TestContext& ctx, TestResult& r) {
  r.timing_not_meaningful = ctx.outside();
  dp::SlaveParams p = watchdog_params(ctx);
  const bus::Ticks twd = watchdog_time(p);
  p.station_status = static_cast<std::uint8_t>((p.station_status | dp::kPrmLockReq) & ~dp::kPrmWdOn);
  auto s = open_session(ctx, r);
  if (!s) return;
  const Reply d = after_silence(ctx, r, *s, p, twd + ctx.timing().wd_margin,
                                "Slave_Diag after TWD of silence, WD off");
  if (r.verdict != Verdict::Pass) return;
  DiagExpect e = data_exch(ctx, tester_address(*s));
  e.s2_mask |= dp::kDiagWdOn;  // WD_On must be clear
  check(r, "watchdog off: still Data_Exch", check_diag(d, e));
}

void min_tsdr_honoured(TestContext& ctx, TestResult& r) {
  r.timing_not_meaningful = ctx.outside();
  if (ctx.outside())
    return not_applicable(r, "behind a pty the interface puts the program's reply on the line as "
                             "soon as it is written and the line is free: the reply's start is the "
                             "pty's and the operating system's, not the device's min TSDR");
  auto s = open_session(ctx, r);
  if (!s) return;
  dp::SlaveParams p = ctx.params();
  const std::uint32_t max_tsdr = s->bus().options().params.max_tsdr;
  p.min_tsdr = static_cast<std::uint8_t>(std::min<std::uint32_t>(60, std::min<std::uint32_t>(255, max_tsdr - 1)));
  const std::size_t mark = s->bus().mark();
  if (check(r, "start-up with min TSDR " + std::to_string(p.min_tsdr), start_up(*s, ctx, p))) return;
  const auto out = output_pattern(ctx.output_len(), 0x12);
  data_exchange(*s, out);
  slave_diag(*s, "Slave_Diag after the min TSDR change");
  // Every reply after the Set_Prm's own SC (the change takes effect after it).
  const auto ex = s->bus().since(mark);
  bool after_prm = false;
  for (const Exchange& e : ex) {
    if (!after_prm) {
      after_prm = e.note.find("Set_Prm") != std::string::npos;
      continue;
    }
    if (!e.answered) {
      fail(r, e.note + ": no reply");
      return;
    }
    if (e.tsdr_bits < p.min_tsdr) {
      fail(r, e.note + ": reply after " + std::to_string(e.tsdr_bits) + " bit times, min TSDR is " +
                  std::to_string(p.min_tsdr));
      return;
    }
  }
}

}  // namespace

void add_set_prm_tests(std::vector<TestCase>& out) {
  out.push_back({"PRM-01", kSetPrmGroup, "Wrong Ident_Number refused",
                 "A Set_Prm whose Ident_Number is not the slave's is refused: Prm_Fault (diag octet 1 "
                 "bit 6), the slave stays in Wait_Prm (§D.2, §D.4, §D.8)",
                 wrong_ident, {SlaveMutant::AcceptWrongIdent}});
  out.push_back({"PRM-02", kSetPrmGroup, "Wrong User_Prm_Data length refused",
                 "A Set_Prm whose User_Prm_Data length differs from the GSD's is refused with Prm_Fault",
                 wrong_prm_length, {}});
  out.push_back({"PRM-03", kSetPrmGroup, "Wrong User_Prm_Data content refused",
                 "A parameter value outside its ExtUserPrmData range is refused with Prm_Fault (GSD "
                 "PI 2.122; §D.2)",
                 wrong_content, {}});
  out.push_back({"PRM-04", kSetPrmGroup, "Lock against another master",
                 "A slave locked by its master ignores a Set_Prm from another master (SC without "
                 "effect); Diag.Master_Add stays its master and data exchange goes on (§D.8)",
                 lock_against_other_master, {SlaveMutant::IgnoreLock}});
  out.push_back({"PRM-05", kSetPrmGroup, "Unlock",
                 "Set_Prm with Lock_Req 0, Unlock_Req 1 from the master releases the slave: back to "
                 "Wait_Prm, Master_Add 0xFF (§D.2)",
                 unlock, {SlaveMutant::NoPrmReqBit}});
  out.push_back({"PRM-06", kSetPrmGroup, "Watchdog expiry",
                 "With WD_On, a slave that hears nothing from its master for TWD = WD_Fact_1 × "
                 "WD_Fact_2 × 10 ms goes back to Wait_Prm (Prm_Req, no master); before TWD it stays in "
                 "Data_Exch (§D.2, §D.8)",
                 watchdog_expiry, {SlaveMutant::IgnoreWatchdog, SlaveMutant::NoPrmReqBit}});
  out.push_back({"PRM-07", kSetPrmGroup, "Watchdog off",
                 "Without WD_On the slave stays in Data_Exch however long its master is silent, and "
                 "WD_On is clear in its diagnosis (§D.2)",
                 watchdog_off, {}});
  out.push_back({"PRM-08", kSetPrmGroup, "Min TSDR honoured",
                 "After a Set_Prm with min TSDR 60 every reply starts at least 60 bit times after the "
                 "end of its request (Set_Prm octet 4; §C.1, §D.2)",
                 min_tsdr_honoured, {SlaveMutant::IgnoreMinTsdr}});
}

}  // namespace pbvbus::conformance::detail
