#include "group_support.hpp"

#include <algorithm>
#include <cstdio>

#include "pbvbus/dp/sap.hpp"

namespace pbvbus::conformance::detail {

std::optional<dp::StandardDiag> standard_diag(const Reply& r) {
  if (!r.ok_with_data()) return std::nullopt;
  dp::StandardDiag d;
  if (!dp::StandardDiag::decode(r.data, d)) return std::nullopt;
  return d;
}

bool diag_ready(const dp::StandardDiag& d) {
  constexpr std::uint8_t kNotReady = dp::kDiagStationNonExistent | dp::kDiagStationNotReady |
                                     dp::kDiagCfgFault | dp::kDiagPrmFault;
  return (d.status_1 & kNotReady) == 0 && (d.status_2 & dp::kDiagPrmReq) == 0;
}

std::vector<std::uint8_t> applied_outputs(devices::SlaveModel& model) {
  auto& app = model.application();
  std::size_t total = 0;
  for (std::size_t m = 0; m < app.modules(); ++m)
    total = std::max(total, app.module(m).out_offset + app.module(m).out_len);
  std::vector<std::uint8_t> out(total, 0);
  for (std::size_t m = 0; m < app.modules(); ++m) {
    const auto& ml = app.module(m);
    if (ml.out_len == 0) continue;
    app.read_outputs(m, std::span<std::uint8_t>(out).subspan(ml.out_offset, ml.out_len));
  }
  return out;
}

std::string outputs_text(std::span<const std::uint8_t> got, std::span<const std::uint8_t> want) {
  return "the outputs the slave applies read " + hex(got) + " (expected " + hex(want) + ")";
}

TestCase make_case(std::string id, std::string group, std::string name, std::string requirement,
                   std::vector<devices::SlaveMutant> targets,
                   std::function<void(TestContext&, TestResult&)> run) {
  TestCase c;
  c.id = std::move(id);
  c.group = std::move(group);
  c.name = std::move(name);
  c.requirement = std::move(requirement);
  c.run = std::move(run);
  c.targets = std::move(targets);
  return c;
}

// --- Run
// ------------------------------------------------------------------------------------------

Run::Run(TestContext& ctx, TestResult& result, std::optional<bus::Baud> baud)
    : m_ctx(ctx), m_result(result) {
  m_dut = ctx.spec().address;
  std::string error;
  m_session = ctx.open(baud, error);
  if (!m_session) {
    m_result.verdict = Verdict::Error;
    m_result.message = "no session with the device under test: " + error;
    return;
  }
  m_tester = m_session->bus().options().tester_address;
  m_dut = m_session->dut_address();
}

Run::~Run() {
  collect();
  constexpr std::size_t kHead = 24;
  constexpr std::size_t kTail = 40;
  if (m_evidence.size() > kHead + kTail) {
    const std::size_t dropped = m_evidence.size() - kHead - kTail;
    std::vector<Exchange> kept(m_evidence.begin(), m_evidence.begin() + kHead);
    kept.insert(kept.end(), m_evidence.end() - kTail, m_evidence.end());
    m_evidence = std::move(kept);
    m_result.message +=
        " (evidence: " + std::to_string(dropped) + " exchanges in the middle left out)";
  }
  for (auto& e : m_evidence) m_result.evidence.push_back(std::move(e));
}

void Run::collect() {
  if (!m_session) return;
  const auto t = m_session->exchanges();
  m_evidence.insert(m_evidence.end(), t.begin(), t.end());
}

bool Run::reopen(std::optional<bus::Baud> baud, std::string& error) {
  collect();
  m_session.reset();
  m_session = m_ctx.open(baud, error);
  if (!m_session) return false;
  m_tester = m_session->bus().options().tester_address;
  m_dut = m_session->dut_address();
  return true;
}

bus::Ticks Run::bits(std::int64_t n) const {
  return bus::bits_to_ticks(n, m_session->bus().baud());
}

Exchange Run::slave_diag(std::string note, std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapSlaveDiag, dp::kSapMs0, {});
  return bus().request(t, std::move(note));
}

Exchange Run::set_prm(std::span<const std::uint8_t> du, std::string note,
                      std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapSetPrm, dp::kSapMs0, du);
  return bus().request(t, std::move(note));
}

Exchange Run::chk_cfg(std::span<const std::uint8_t> du, std::string note,
                      std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapChkCfg, dp::kSapMs0, du);
  return bus().request(t, std::move(note));
}

Exchange Run::get_cfg(std::string note, std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapGetCfg, dp::kSapMs0, {});
  return bus().request(t, std::move(note));
}

Exchange Run::rd_inp(std::string note, std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapRdInp, dp::kSapMs0, {});
  return bus().request(t, std::move(note));
}

Exchange Run::rd_outp(std::string note, std::optional<std::uint8_t> sa) {
  const auto t = srd(m_dut, sa.value_or(m_tester), dp::kSapRdOutp, dp::kSapMs0, {});
  return bus().request(t, std::move(note));
}

Exchange Run::data_exchange(std::span<const std::uint8_t> outputs, std::string note,
                            std::optional<bus::Ticks> not_before, std::optional<std::uint8_t> sa) {
  const std::uint8_t from = sa.value_or(m_tester);
  const bus::Ticks interval = bus().options().dx_interval;
  if (!not_before && interval > 0) {
    // The battery's relaxed DP cycle (steps.hpp): no earlier than dx_interval after the end of
    // this master's previous Data_Exchange.
    const auto& t = bus().transcript();
    for (auto it = t.rbegin(); it != t.rend(); ++it) {
      fdl::Telegram tg;
      if (fdl::decode(it->request, tg) != fdl::DecodeError::None) continue;
      const auto fn = fdl::fc_request_fn(tg.fc);
      if (tg.sa == from && !tg.dsap &&
          (fn == fdl::RequestFn::SrdHigh || fn == fdl::RequestFn::SrdLow)) {
        not_before = it->request_end + interval;
        break;
      }
    }
  }
  const auto t = srd(m_dut, from, std::nullopt, std::nullopt, outputs);
  return bus().request(t, std::move(note), not_before);
}

Exchange Run::global_control(std::uint8_t control_command, std::uint8_t group_select,
                             std::string note) {
  const std::uint8_t du[2] = {control_command, group_select};
  const auto t = sdn(fdl::kBroadcast, m_tester, dp::kSapGlobalControl, dp::kSapMs0, du);
  return bus().send_no_reply(t, std::move(note));
}

Exchange Run::set_slave_add(std::uint8_t da, std::uint8_t new_address, std::uint16_t ident,
                            bool no_add_chg, std::string note) {
  const std::uint8_t du[4] = {new_address, static_cast<std::uint8_t>(ident >> 8),
                              static_cast<std::uint8_t>(ident & 0xFF),
                              static_cast<std::uint8_t>(no_add_chg ? 1 : 0)};
  const auto t = srd(da, m_tester, dp::kSapSetSlaveAdd, dp::kSapMs0, du);
  return bus().request(t, std::move(note));
}

Exchange Run::service(std::uint8_t dsap, std::span<const std::uint8_t> du, std::string note,
                      std::optional<bus::Ticks> not_before) {
  const auto t = srd(m_dut, m_tester, dsap, dp::kSapMs0, du);
  return bus().request(t, std::move(note), not_before);
}

bool wait_prm_diag(const dp::StandardDiag& d) {
  return (d.status_1 & dp::kDiagStationNotReady) != 0 && d.master_add == dp::kNoMaster;
}

bool data_answer(const TestContext& ctx, const Reply& r) {
  return r.ok_with_data() || (r.kind == Reply::Kind::Sc && ctx.input_len() == 0);
}

Exchange Run::c1(std::uint8_t dsap, std::span<const std::uint8_t> pdu, std::string note) {
  const auto t = srd(m_dut, m_tester, dsap, dp::kSapMs1, pdu);
  return bus().request(t, std::move(note));
}

std::optional<dp::StandardDiag> Run::diag(std::string& why, std::string note,
                                          std::optional<std::uint8_t> sa) {
  const Exchange e = slave_diag(std::move(note), sa);
  const Reply r = reply_of(e);
  auto d = standard_diag(r);
  if (!d) why = "Slave_Diag answered " + r.describe() + ", not a diagnosis of six or more octets";
  return d;
}

namespace {
bool acknowledged(const Reply& r) {
  if (r.kind == Reply::Kind::Sc) return true;
  return r.kind == Reply::Kind::Telegram && r.data.empty() &&
         (r.status == fdl::ResponseStatus::OK || r.status == fdl::ResponseStatus::DL);
}
}  // namespace

bool Run::start_up(std::string& why, const dp::SlaveParams* params,
                   std::optional<std::uint8_t> sa) {
  const dp::SlaveParams& p = params ? *params : m_ctx.params();
  if (!diag(why, "start-up: Slave_Diag", sa)) return false;
  const auto prm = p.set_prm_du();
  const Reply r1 = reply_of(set_prm(prm, "start-up: Set_Prm", sa));
  if (!acknowledged(r1)) {
    why = "start-up: Set_Prm answered " + r1.describe() + " instead of SC";
    return false;
  }
  const auto cfg = p.chk_cfg_du();
  const Reply r2 = reply_of(chk_cfg(cfg, "start-up: Chk_Cfg", sa));
  if (!acknowledged(r2)) {
    why = "start-up: Chk_Cfg answered " + r2.describe() + " instead of SC";
    return false;
  }
  const auto d = diag(why, "start-up: Slave_Diag after Chk_Cfg", sa);
  if (!d) return false;
  if (!diag_ready(*d)) {
    const auto b = d->encode();
    why = "start-up: the diagnosis after Set_Prm and Chk_Cfg is not ready for data exchange: " +
          hex(b);
    return false;
  }
  return true;
}

std::vector<std::uint8_t> Run::outputs(std::uint8_t fill) const {
  return std::vector<std::uint8_t>(m_ctx.output_len(), fill);
}

void Run::pass(std::string message) {
  m_result.verdict = Verdict::Pass;
  m_result.message = std::move(message);
}

void Run::fail(std::string message) {
  m_result.verdict = Verdict::Fail;
  m_result.message = std::move(message);
}

void Run::error(std::string message) {
  m_result.verdict = Verdict::Error;
  m_result.message = std::move(message);
}

void Run::not_ready(const std::string& why, const std::string& with) {
  error("precondition not established: the device did not reach Data_Exch with " + with + " (" +
        why + "); the Start-up group's tests say why");
}

void Run::na(std::string message) {
  m_result.verdict = Verdict::NotApplicable;
  m_result.message = std::move(message);
}

}  // namespace pbvbus::conformance::detail
