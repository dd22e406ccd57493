// The DP services as the battery sends them (steps.hpp).

#include "steps.hpp"

#include "report_util.hpp"

#include <cstdio>

#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"
#include "pbvbus/dp/sap.hpp"

namespace pbvbus::conformance::detail {

std::string hex(std::span<const std::uint8_t> b) { return hex_octets(b); }

std::uint8_t tester_address(Session& s) { return s.bus().options().tester_address; }

Reply service(Session& s, std::optional<std::uint8_t> dsap, std::span<const std::uint8_t> du,
              std::string note, std::optional<std::uint8_t> sa, bool fcv, bool fcb) {
  const std::uint8_t from = sa.value_or(tester_address(s));
  std::optional<std::uint8_t> ssap;
  if (dsap) ssap = dp::kSapMs0;
  const auto t = srd(s.dut_address(), from, dsap, ssap, du, fcv, fcb);
  return reply_of(s.bus().request(t, std::move(note)));
}

Reply slave_diag(Session& s, std::string note, std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapSlaveDiag, {}, std::move(note), sa);
}
Reply set_prm(Session& s, std::span<const std::uint8_t> du, std::string note,
              std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapSetPrm, du, std::move(note), sa);
}
Reply chk_cfg(Session& s, std::span<const std::uint8_t> du, std::string note,
              std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapChkCfg, du, std::move(note), sa);
}
Reply get_cfg(Session& s, std::string note, std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapGetCfg, {}, std::move(note), sa);
}
Reply rd_inp(Session& s, std::string note, std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapRdInp, {}, std::move(note), sa);
}
Reply rd_outp(Session& s, std::string note, std::optional<std::uint8_t> sa) {
  return service(s, dp::kSapRdOutp, {}, std::move(note), sa);
}
namespace {
/// A Data_Exchange request (SRD without address extension) from `sa`.
bool is_data_exchange_from(const Exchange& e, std::uint8_t sa) {
  fdl::Telegram t;
  if (fdl::decode(e.request, t) != fdl::DecodeError::None || !t.is_request()) return false;
  const auto fn = fdl::fc_request_fn(t.fc);
  return t.sa == sa && !t.dsap && (fn == fdl::RequestFn::SrdHigh || fn == fdl::RequestFn::SrdLow);
}
}  // namespace

Reply data_exchange(Session& s, std::span<const std::uint8_t> outputs, std::string note,
                    std::optional<std::uint8_t> sa, bool fcv, bool fcb) {
  const std::uint8_t from = sa.value_or(tester_address(s));
  std::optional<bus::Ticks> not_before;
  const bus::Ticks interval = s.bus().options().dx_interval;
  if (interval > 0) {
    const auto& t = s.bus().transcript();
    for (auto it = t.rbegin(); it != t.rend(); ++it)
      if (is_data_exchange_from(*it, from)) {
        not_before = it->request_end + interval;
        break;
      }
  }
  const auto req = srd(s.dut_address(), from, std::nullopt, std::nullopt, outputs, fcv, fcb);
  return reply_of(s.bus().request(req, std::move(note), not_before));
}

void global_control(Session& s, std::uint8_t control, std::uint8_t group_select, std::string note,
                    std::uint8_t da, std::optional<std::uint8_t> sa) {
  const std::uint8_t du[2] = {control, group_select};
  const auto t = sdn(da, sa.value_or(tester_address(s)), dp::kSapGlobalControl, dp::kSapMs0, du);
  s.bus().send_no_reply(t, std::move(note));
}

std::vector<std::uint8_t> prm_du(const dp::SlaveParams& p) { return p.set_prm_du(); }
std::vector<std::uint8_t> cfg_du(const dp::SlaveParams& p) { return p.chk_cfg_du(); }

namespace {
/// A service without response data acknowledged as a master judges it: SC, or a response
/// without data with status OK or DL (the same rule as Run::start_up in group_support.cpp).
bool acknowledged_without_data(const Reply& r) {
  if (r.kind == Reply::Kind::Sc) return true;
  return r.kind == Reply::Kind::Telegram && r.data.empty() &&
         (r.status == fdl::ResponseStatus::OK || r.status == fdl::ResponseStatus::DL);
}
}  // namespace

std::string start_up(Session& s, TestContext& ctx, const std::optional<dp::SlaveParams>& params) {
  const dp::SlaveParams& p = params ? *params : ctx.params();
  const Reply d0 = slave_diag(s, "start-up: Slave_Diag");
  if (!d0.ok_with_data() || d0.data.size() < 6)
    return "Slave_Diag before Set_Prm: " + d0.describe() + ", not a diagnosis of six or more octets";
  const auto prm = prm_du(p);
  const Reply r1 = set_prm(s, prm, "start-up: Set_Prm");
  if (!acknowledged_without_data(r1)) return "Set_Prm: expected SC, got " + r1.describe();
  const auto cfg = cfg_du(p);
  const Reply r2 = chk_cfg(s, cfg, "start-up: Chk_Cfg");
  if (!acknowledged_without_data(r2)) return "Chk_Cfg: expected SC, got " + r2.describe();
  const Reply d1 = slave_diag(s, "start-up: Slave_Diag after Chk_Cfg");
  if (!d1.ok_with_data() || d1.data.size() < 6) return "Slave_Diag after Chk_Cfg: " + d1.describe();
  // Ready for data exchange (§D.4, S1): no Non_Existent/Not_Ready/Cfg_Fault/Prm_Fault, no Prm_Req.
  const std::uint8_t bad1 = dp::kDiagStationNonExistent | dp::kDiagStationNotReady |
                            dp::kDiagCfgFault | dp::kDiagPrmFault;
  if ((d1.data[0] & bad1) != 0 || (d1.data[1] & dp::kDiagPrmReq) != 0)
    return "not ready for data exchange after start-up: diag " + hex(d1.data);
  return {};
}

std::vector<std::uint8_t> output_pattern(std::size_t len, std::uint8_t seed) {
  std::vector<std::uint8_t> v(len);
  for (std::size_t i = 0; i < len; ++i)
    v[i] = static_cast<std::uint8_t>(seed + 0x11 * (i + 1));
  if (len > 0 && v[0] == 0) v[0] = 0x5A;
  return v;
}

std::vector<std::uint8_t> expected_diag(std::uint8_t status1, std::uint8_t status2,
                                        std::uint8_t status3, std::uint8_t master_add,
                                        std::uint16_t ident) {
  return {status1, status2, status3, master_add, static_cast<std::uint8_t>(ident >> 8),
          static_cast<std::uint8_t>(ident & 0xFF)};
}

std::string expect_data(const Reply& r, std::span<const std::uint8_t> expected, bool exact) {
  if (!r.ok_with_data()) return "expected DL/DH " + hex(expected) + ", got " + r.describe();
  const bool same = exact ? (r.data.size() == expected.size() &&
                             std::equal(expected.begin(), expected.end(), r.data.begin()))
                          : (r.data.size() >= expected.size() &&
                             std::equal(expected.begin(), expected.end(), r.data.begin()));
  if (!same) return "expected " + hex(expected) + (exact ? "" : " ...") + ", got " + hex(r.data);
  return {};
}

std::string expect_sc(const Reply& r) {
  return r.kind == Reply::Kind::Sc ? std::string{} : "expected SC, got " + r.describe();
}

std::string expect_rs(const Reply& r) {
  return r.rs() ? std::string{} : "expected RS, got " + r.describe();
}

namespace {

constexpr const char* kStatus1Bits[8] = {"Station_Non_Existent", "Station_Not_Ready", "Cfg_Fault",
                                         "Ext_Diag", "Not_Supported", "Invalid_Slave_Response",
                                         "Prm_Fault", "Master_Lock"};
constexpr const char* kStatus2Bits[8] = {"Prm_Req", "Stat_Diag", "bit 2 (always 1)", "WD_On",
                                         "Freeze_Mode", "Sync_Mode", "bit 6 (reserved)",
                                         "Deactivated"};

/// "Station_Not_Ready=1 Cfg_Fault=0" for the bits under `mask` of `value`.
std::string bits_text(const char* const (&names)[8], std::uint8_t mask, std::uint8_t value) {
  std::string s;
  for (int b = 0; b < 8; ++b) {
    if ((mask & (1u << b)) == 0) continue;
    if (!s.empty()) s += " ";
    s += std::string(names[b]) + "=" + ((value >> b) & 1u ? "1" : "0");
  }
  return s;
}

std::string ident_text(std::uint16_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04X", v);
  return b;
}

}  // namespace

std::string check_diag(const Reply& r, const DiagExpect& e) {
  if (!r.ok_with_data() || r.data.size() < 6)
    return "expected Slave_Diag data (6+ octets), got " + r.describe();
  const auto& d = r.data;
  std::string why;
  auto add = [&](const std::string& t) { why += (why.empty() ? "" : "; ") + t; };
  if ((d[0] & e.s1_mask) != e.s1)
    add("Station_Status_1 (octet 1) expected " + bits_text(kStatus1Bits, e.s1_mask, e.s1) +
        ", received " + bits_text(kStatus1Bits, e.s1_mask, d[0]));
  if ((d[1] & e.s2_mask) != e.s2)
    add("Station_Status_2 (octet 2) expected " + bits_text(kStatus2Bits, e.s2_mask, e.s2) +
        ", received " + bits_text(kStatus2Bits, e.s2_mask, d[1]));
  if (e.master && d[3] != *e.master)
    add("Master_Add (octet 4) expected " + std::to_string(*e.master) +
        (*e.master == 0xFF ? " (none)" : "") + ", received " + std::to_string(d[3]) +
        (d[3] == 0xFF ? " (none)" : ""));
  const std::uint16_t ident = static_cast<std::uint16_t>(d[4] << 8 | d[5]);
  if (e.ident && ident != *e.ident)
    add("Ident_Number (octets 5..6) expected " + ident_text(*e.ident) + ", received " + ident_text(ident));
  if (why.empty()) return {};
  return "diag " + hex(d) + ": " + why;
}

std::string expect_std_diag(const Reply& r, std::span<const std::uint8_t> expected) {
  if (!r.ok_with_data() || r.data.size() < 6)
    return "expected Slave_Diag " + hex(expected) + ", got " + r.describe();
  std::vector<std::uint8_t> got(r.data.begin(), r.data.begin() + 6);
  std::vector<std::uint8_t> want(expected.begin(), expected.end());
  if (r.data.size() > 6) {
    got[0] &= static_cast<std::uint8_t>(~dp::kDiagExtDiag);
    want[0] &= static_cast<std::uint8_t>(~dp::kDiagExtDiag);
    got[2] &= 0x7F;
    want[2] &= 0x7F;
  }
  if (got != want) {
    std::string diff;
    auto add = [&](const std::string& t) { diff += (diff.empty() ? "" : "; ") + t; };
    if (const std::uint8_t x = got[0] ^ want[0])
      add("octet 1 expected " + bits_text(kStatus1Bits, x, want[0]) + ", received " +
          bits_text(kStatus1Bits, x, got[0]));
    if (const std::uint8_t x = got[1] ^ want[1])
      add("octet 2 expected " + bits_text(kStatus2Bits, x, want[1]) + ", received " +
          bits_text(kStatus2Bits, x, got[1]));
    if (got[2] != want[2]) add("octet 3 (Ext_Diag_Overflow) differs");
    if (got[3] != want[3])
      add("Master_Add expected " + std::to_string(want[3]) + ", received " + std::to_string(got[3]));
    if (got[4] != want[4] || got[5] != want[5])
      add("Ident_Number expected " + ident_text(static_cast<std::uint16_t>(want[4] << 8 | want[5])) +
          ", received " + ident_text(static_cast<std::uint16_t>(got[4] << 8 | got[5])));
    return "expected diag " + hex(expected) + ", got " + hex(r.data) + " (" + diff + ")";
  }
  return {};
}

std::unique_ptr<Session> open_session(TestContext& ctx, TestResult& r, std::optional<bus::Baud> baud) {
  std::string err;
  auto s = ctx.open(baud, err);
  if (!s) error(r, "no session with the device under test: " + err);
  return s;
}

dp::SlaveParams with_plan_watchdog(const TestContext& ctx, dp::SlaveParams p) {
  const bool base_1ms = p.dpv1() && (p.user_prm[0] & dp::kDpv1WdBase1ms) != 0;
  const bus::Ticks unit = base_1ms ? bus::kTicksPerMs : 10 * bus::kTicksPerMs;
  const bus::Ticks want = std::max(ctx.timing().twd, 100 * bus::kTicksPerMs);
  const std::int64_t n = std::min<std::int64_t>((want + unit - 1) / unit, 255 * 255);
  const std::int64_t f2 = (n + 254) / 255;
  const std::int64_t f1 = (n + f2 - 1) / f2;
  p.wd_fact_1 = static_cast<std::uint8_t>(f1);
  p.wd_fact_2 = static_cast<std::uint8_t>(f2);
  return p;
}

bus::Ticks watchdog_time(const dp::SlaveParams& p) {
  const bool base_1ms = p.dpv1() && (p.user_prm[0] & dp::kDpv1WdBase1ms) != 0;
  return dp::watchdog_ticks(p.wd_fact_1, p.wd_fact_2, base_1ms);
}

void fail(TestResult& r, const std::string& why) {
  if (r.verdict != Verdict::Fail) {
    r.verdict = Verdict::Fail;
    r.message = why;
  }
}

void not_applicable(TestResult& r, const std::string& why) {
  if (r.verdict == Verdict::Pass) {
    r.verdict = Verdict::NotApplicable;
    r.message = why;
  }
}

void error(TestResult& r, const std::string& why) {
  if (r.verdict != Verdict::Fail && r.verdict != Verdict::Error) {
    r.verdict = Verdict::Error;
    r.message = why;
  }
}

bool precondition(TestResult& r, const std::string& start_up_why, const std::string& with) {
  if (start_up_why.empty()) return false;
  error(r, "precondition not established: the device did not reach Data_Exch with " + with + " (" +
               start_up_why + "); the Start-up group's tests say why");
  return true;
}

bool check(TestResult& r, const std::string& what, const std::string& why) {
  if (why.empty()) return false;
  fail(r, what + ": " + why);
  return true;
}

}  // namespace pbvbus::conformance::detail
