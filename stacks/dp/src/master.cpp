// DP master class 1 (protocol-facts.md §D.9, §D.6, §E); decisions are listed in master.hpp.
#include "pbvbus/dp/master.hpp"
#include "confirmation_kind.hpp"

#include <algorithm>
#include <stdexcept>

namespace pbvbus::dp {

using fdl::Confirmation;
using fdl::RequestFn;
using fdl::ResponseStatus;

std::string_view to_string(MasterMode m) {
  switch (m) {
    case MasterMode::Offline: return "offline";
    case MasterMode::Stop: return "stop";
    case MasterMode::Clear: return "clear";
    case MasterMode::Operate: return "operate";
  }
  return "?";
}

std::string_view to_string(SlaveStatusState s) {
  switch (s) {
    case SlaveStatusState::Inactive: return "inactive";
    case SlaveStatusState::Diag: return "start-up: Slave_Diag";
    case SlaveStatusState::Prm: return "start-up: Set_Prm";
    case SlaveStatusState::Cfg: return "start-up: Chk_Cfg";
    case SlaveStatusState::CheckDiag: return "start-up: check diagnosis";
    case SlaveStatusState::DataExchange: return "data exchange";
    case SlaveStatusState::NotPresent: return "not present";
    case SlaveStatusState::Locked: return "locked by another master";
  }
  return "?";
}

std::string_view to_string(MasterEvent::Kind k) {
  switch (k) {
    case MasterEvent::Kind::StationFailure: return "station failure";
    case MasterEvent::Kind::StationReturn: return "station return";
    case MasterEvent::Kind::Diagnosis: return "diagnosis";
    case MasterEvent::Kind::Alarm: return "alarm";
    case MasterEvent::Kind::ModeChange: return "mode change";
    case MasterEvent::Kind::DataExchangeEntered: return "data exchange entered";
    case MasterEvent::Kind::PrmCmdDone: return "PrmCmd done";
    case MasterEvent::Kind::AlarmAcknowledged: return "alarm acknowledged";
  }
  return "?";
}

std::string_view to_string(MasterEvent::Cause c) {
  switch (c) {
    case MasterEvent::Cause::None: return "none";
    case MasterEvent::Cause::NoResponse: return "no response";
    case MasterEvent::Cause::LeftDataExchange: return "left data exchange";
    case MasterEvent::Cause::InvalidResponse: return "invalid response";
  }
  return "?";
}

std::vector<std::uint8_t> SlaveParams::set_prm_du() const {
  PrmHeader h;
  h.station_status = station_status;
  h.wd_fact_1 = wd_fact_1;
  h.wd_fact_2 = wd_fact_2;
  h.min_tsdr = min_tsdr;
  h.ident = ident;
  h.group_ident = group_ident;
  if (prm_cmd.empty()) return encode_prm(h, user_prm);
  std::vector<std::uint8_t> user(user_prm);
  if (user.size() >= 3) user[2] |= kPrmCmd | kPrmStructure;
  user.insert(user.end(), prm_cmd.begin(), prm_cmd.end());
  return encode_prm(h, user);
}

std::vector<std::uint8_t> SlaveParams::chk_cfg_du() const {
  std::vector<std::uint8_t> out;
  for (const auto& m : modules) out.insert(out.end(), m.cfg.begin(), m.cfg.end());
  return out;
}

namespace {
constexpr std::uint8_t kFaultsRestart = kDiagCfgFault | kDiagPrmFault | kDiagNotSupported;

std::uint64_t make_tag(int kind, int slave) {
  return (static_cast<std::uint64_t>(kind) << 16) | static_cast<std::uint64_t>(slave & 0xFFFF);
}
}  // namespace

// --- construction -------------------------------------------------------------------------------

Master::Master(MasterParams params, std::vector<SlaveParams> slaves) : m_p(std::move(params)) {
  m_index.fill(-1);
  if (m_p.address > 126) throw std::invalid_argument("DP master: address must be 0..126");
  if (m_p.data_control_time == 0)
    throw std::invalid_argument("DP master: Data_Control_Time must be at least 1 (10 ms)");
  m_gc_interval = m_p.global_control_interval > 0
                      ? m_p.global_control_interval
                      : static_cast<bus::Ticks>(m_p.data_control_time) * 10 * bus::kTicksPerMs / 2;
  m_slaves.reserve(slaves.size());
  for (auto& sp : slaves) {
    const std::string who = "DP master: slave " + std::to_string(sp.address) + ": ";
    if (sp.address > kMaxSlaveAddress) throw std::invalid_argument(who + "address must be 0..125");
    if (sp.address == m_p.address) throw std::invalid_argument(who + "address is the master's");
    if (m_index[sp.address] >= 0) throw std::invalid_argument(who + "configured twice");
    if (sp.user_prm.size() + sp.prm_cmd.size() > kMaxUserPrmLen)
      throw std::invalid_argument(who + "more than 237 octets of user prm data");
    if (!sp.prm_cmd.empty() && (sp.prm_cmd.size() != kPrmCmdBlockLen || !sp.dpv1()))
      throw std::invalid_argument(who + "a PrmCmd block is 8 octets and needs a DP-V1 Set_Prm");
    if ((sp.station_status & kPrmWdOn) && (sp.wd_fact_1 == 0 || sp.wd_fact_2 == 0))
      throw std::invalid_argument(who + "watchdog factors must be 1..255");
    SlaveConfig sc;
    sc.ident = sp.ident;
    sc.modules = sp.modules;
    sc.max_user_prm_len = kMaxUserPrmLen;
    Slave s;
    const std::string why = build_layout(sc, s.layout);
    if (!why.empty()) throw std::invalid_argument(who + why);
    s.prm = sp.set_prm_du();
    s.cfg = s.layout.cfg;
    s.image = std::make_unique<MasterImage>(s.layout);
    s.min_interval = static_cast<bus::Ticks>(sp.min_slave_interval) * 100 * bus::kTicksPerUs;
    s.p = std::move(sp);
    m_index[s.p.address] = static_cast<int>(m_slaves.size());
    m_slaves.push_back(std::move(s));
  }
  if (m_p.equidistant_cycle < 0) throw std::invalid_argument("DP master: negative equidistant cycle");
  m_eq.period = m_p.equidistant_cycle;
  m_mode = m_p.initial_mode;
  m_standby = m_p.standby;
  m_scratch.reserve(kMaxDiagLen);
  reset_slaves();
}

Master::Slave& Master::slave(std::uint8_t address) {
  if (!has_slave(address)) throw std::out_of_range("DP master: no slave at that address");
  return m_slaves[static_cast<std::size_t>(m_index[address])];
}
const Master::Slave& Master::slave(std::uint8_t address) const {
  if (!has_slave(address)) throw std::out_of_range("DP master: no slave at that address");
  return m_slaves[static_cast<std::size_t>(m_index[address])];
}
const SlaveParams& Master::slave_params(std::uint8_t a) const { return slave(a).p; }
SlaveStatusState Master::slave_state(std::uint8_t a) const { return slave(a).state; }
std::span<const std::uint8_t> Master::slave_diag(std::uint8_t a) const { return slave(a).diag; }
const MasterSlaveStats& Master::slave_stats(std::uint8_t a) const { return slave(a).stats; }
MasterImage& Master::image(std::uint8_t a) { return *slave(a).image; }
const MasterImage& Master::image(std::uint8_t a) const { return *slave(a).image; }

bool Master::prm_cmd(std::uint8_t a, std::span<const std::uint8_t> block, bool send) {
  if (!has_slave(a) || block.size() != kPrmCmdBlockLen) return false;
  Slave& s = slave(a);
  if (s.p.prm_cmd.size() != kPrmCmdBlockLen) return false;
  s.p.prm_cmd.assign(block.begin(), block.end());
  // The block is the last 8 octets of the stored Set_Prm (set_prm_du() appends it).
  std::copy(block.begin(), block.end(), s.prm.end() - static_cast<std::ptrdiff_t>(kPrmCmdBlockLen));
  // Owed unless the start-up's own Set_Prm has yet to go out (it carries the new block).
  s.prm_cmd_due = send && s.state != SlaveStatusState::Prm && s.state != SlaveStatusState::Diag &&
                  s.state != SlaveStatusState::NotPresent && s.state != SlaveStatusState::Locked &&
                  s.state != SlaveStatusState::Inactive;
  return true;
}

bool Master::prm_cmd_pending(std::uint8_t a) const { return has_slave(a) && slave(a).prm_cmd_due; }

std::vector<std::uint8_t> Master::addresses() const {
  std::vector<std::uint8_t> out;
  for (const auto& s : m_slaves) out.push_back(s.p.address);
  return out;
}

bus::Ticks Master::cycle_median(std::uint8_t a) const {
  const Slave& s = slave(a);
  const std::size_t n = static_cast<std::size_t>(
      std::min<std::uint64_t>(s.stats.cycle_count, kCycleSamples));
  if (n == 0) return 0;
  std::vector<bus::Ticks> v(s.cycles.begin(), s.cycles.begin() + static_cast<std::ptrdiff_t>(n));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
  return v[n / 2];
}

// --- operating state ----------------------------------------------------------------------------

void Master::reset_slaves() {
  const bool running = m_mode == MasterMode::Clear || m_mode == MasterMode::Operate;
  for (auto& s : m_slaves) {
    fail_jobs(s, m_now);
    s.in_dx = false;
    s.image->set_valid(false);
    s.last_dx = bus::kNever;
    s.last_main = bus::kNever;
    s.last_retry = bus::kNever;
    s.diag_after_dh = false;
    s.alarms_seen.clear();
    s.probe = false;
    if (!s.p.active) {
      s.state = SlaveStatusState::Inactive;
      const StandardDiag d{0, kDiagDeactivated, 0, kNoMaster, s.p.ident};
      const auto b = d.encode();
      s.diag.assign(b.begin(), b.end());
    } else {
      s.state = running ? SlaveStatusState::Diag : SlaveStatusState::Inactive;
    }
  }
  m_pass_active = false;
  m_gc_due = true;
  m_eq_due = bus::kNever;  // a new equidistance grid with the next pass
  m_eq_last_late = true;
}

void Master::set_mode(MasterMode m) {
  if (m == m_mode) return;
  const bool was_running = m_mode == MasterMode::Clear || m_mode == MasterMode::Operate;
  const bool running = m == MasterMode::Clear || m == MasterMode::Operate;
  m_mode = m;
  if (was_running != running) reset_slaves();
  m_gc_due = true;
  MasterEvent e;
  e.kind = MasterEvent::Kind::ModeChange;
  e.time = m_now;
  e.slave = m_p.address;
  e.mode = m;
  emit(e);
}

void Master::global_control(std::uint8_t command, std::uint8_t group_select) {
  m_gc_queue.push_back(
      {static_cast<std::uint8_t>(command & (kGcSync | kGcUnsync | kGcFreeze | kGcUnfreeze)),
       group_select});
}

// --- InitiatorUser ----------------------------------------------------------------------------

void Master::on_power_on(bus::Ticks now) {
  m_now = now;
  m_out_kind = Kind::None;
  m_out_slave = -1;
  m_last_gc = bus::kNever;
  reset_slaves();
  reset_shadow();
}

void Master::on_token(bus::Ticks now, bus::Ticks /*trr*/) {
  m_now = now;
  // A request is outstanding only while the station holds the token; one still marked at a
  // new token was lost with the ring (the station never confirmed it): forget it.
  m_out_kind = Kind::None;
  m_out_slave = -1;
  if (!m_pass_active && m_p.equidistant_cycle <= 0) start_pass();
}

void Master::start_pass() {
  m_pass_active = true;
  m_pass_fresh = true;
  m_cursor = 0;
  for (auto& s : m_slaves) s.turn_main = s.turn_diag = s.turn_acyclic = false;
}

void Master::fill(fdl::Request& out, const Slave& s, std::optional<std::uint8_t> dsap,
                  std::optional<std::uint8_t> ssap, Kind kind) {
  out.da = s.p.address;
  out.fn = RequestFn::SrdHigh;
  out.dsap = dsap;
  out.ssap = ssap;
  out.data.clear();
  const int idx = m_index[s.p.address];
  out.tag = make_tag(static_cast<int>(kind), idx);
  m_out_kind = kind;
  m_out_slave = idx;
  m_out_dh_diag = false;
}

bool Master::next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) {
  m_now = now;
  // All DP traffic is high priority (§B.4); a low-priority ask means we had nothing.
  if (prio != fdl::Priority::High) return false;
  if (m_standby) return false;  // a hot-standby master only listens
  if (m_mode != MasterMode::Clear && m_mode != MasterMode::Operate) return false;
  if (m_out_kind != Kind::None) return false;  // one request at a time
  if (m_p.equidistant_cycle > 0 && !m_pass_active && !equidistant_start(now)) return false;

  // Global_Control announcing the operating state.
  if (m_gc_due || m_last_gc == bus::kNever || now - m_last_gc >= m_gc_interval) {
    out.da = fdl::kBroadcast;
    out.fn = RequestFn::SdnHigh;
    out.dsap = kSapGlobalControl;
    out.ssap = kSapMs0;
    out.data.assign({static_cast<std::uint8_t>(m_mode == MasterMode::Clear ? kGcClearData : 0),
                     0x00});
    out.tag = make_tag(static_cast<int>(Kind::GlobalControl), 0xFFFF);
    m_out_kind = Kind::GlobalControl;
    m_out_slave = -1;
    m_gc_due = false;
    m_last_gc = now;
    return true;
  }
  if (!m_pass_active) return false;
  // Sync/freeze commands at the start of a pass: after the previous pass has delivered every
  // slave's outputs (Sync latches them), before this pass reads the inputs (Freeze).
  if (m_pass_fresh && !m_gc_queue.empty()) {
    const auto gc = m_gc_queue.front();
    m_gc_queue.pop_front();
    out.da = fdl::kBroadcast;
    out.fn = RequestFn::SdnHigh;
    out.dsap = kSapGlobalControl;
    out.ssap = kSapMs0;
    out.data.assign({static_cast<std::uint8_t>(
                         gc[0] | (m_mode == MasterMode::Clear ? kGcClearData : 0)),
                     gc[1]});
    out.tag = make_tag(static_cast<int>(Kind::GlobalControl), 0xFFFF);
    m_out_kind = Kind::GlobalControl;
    m_out_slave = -1;
    return true;
  }
  while (m_cursor < m_slaves.size()) {
    Slave& s = m_slaves[m_cursor];
    if (build_for_slave(s, now, out)) {
      m_pass_fresh = false;
      ++s.stats.requests;
      return true;
    }
    ++m_cursor;
  }
  m_pass_active = false;
  return false;
}

bool Master::build_for_slave(Slave& s, bus::Ticks now, fdl::Request& out) {
  if (!s.p.active || s.state == SlaveStatusState::Inactive) return false;
  if (!s.turn_main) {
    s.turn_main = true;
    if (s.last_main != bus::kNever && now - s.last_main < s.min_interval) {
      // Min_Slave_Interval not over: the slave sits this pass out.
      s.turn_diag = s.turn_acyclic = true;
      return false;
    }
    if (main_request(s, now, out)) {
      s.last_main = now;
      return true;
    }
  }
  if (s.diag_after_dh && !s.turn_diag) {
    s.turn_diag = true;
    s.diag_after_dh = false;
    fill(out, s, kSapSlaveDiag, kSapMs0, Kind::Diag);
    m_out_dh_diag = true;
    return true;
  }
  if (!s.turn_acyclic && s.state == SlaveStatusState::DataExchange && !s.jobs.empty()) {
    s.turn_acyclic = true;
    Job& j = s.jobs.front();
    if (j.sent && now >= j.deadline) {
      finish_job(s, AcyclicStatus::Timeout, now);
      return false;
    }
    fill(out, s, j.sap, kSapMs1, Kind::Acyclic);
    if (!j.sent) {
      // The request itself; afterwards polls without data until the answer comes (§E.4).
      out.data.assign(j.pdu.begin(), j.pdu.end());
      j.sent = true;
      j.deadline = now + static_cast<bus::Ticks>(s.p.c1_response_timeout) * 10 * bus::kTicksPerMs;
    }
    return true;
  }
  return false;
}

bool Master::main_request(Slave& s, bus::Ticks now, fdl::Request& out) {
  switch (s.state) {
    case SlaveStatusState::Inactive: return false;
    case SlaveStatusState::NotPresent:
    case SlaveStatusState::Locked:
      if (s.last_retry != bus::kNever && now - s.last_retry < m_p.failed_retry_interval)
        return false;
      s.last_retry = now;
      fill(out, s, kSapSlaveDiag, kSapMs0, Kind::Diag);
      return true;
    case SlaveStatusState::Diag:
    case SlaveStatusState::CheckDiag:
      fill(out, s, kSapSlaveDiag, kSapMs0, Kind::Diag);
      return true;
    case SlaveStatusState::Prm:
      fill(out, s, kSapSetPrm, kSapMs0, Kind::Prm);
      out.data.assign(s.prm.begin(), s.prm.end());
      ++s.stats.startups;
      s.prm_cmd_due = false;  // this Set_Prm carries the current PrmCmd block
      return true;
    case SlaveStatusState::Cfg:
      fill(out, s, kSapChkCfg, kSapMs0, Kind::Cfg);
      out.data.assign(s.cfg.begin(), s.cfg.end());
      return true;
    case SlaveStatusState::DataExchange: {
      if (s.prm_cmd_due) {
        // Pure PrmCmd (§G.2): header + DPV1_Status_1..3 + the block, instead of this pass's
        // Data_Exchange; the slave keeps its outputs (Output_Hold_Time covers the gap).
        s.prm_cmd_due = false;
        fill(out, s, kSapSetPrm, kSapMs0, Kind::PrmCmd);
        out.data.assign(s.prm.begin(), s.prm.begin() + static_cast<std::ptrdiff_t>(kPrmLenDpv1));
        out.data.insert(out.data.end(), s.prm.end() - static_cast<std::ptrdiff_t>(kPrmCmdBlockLen),
                        s.prm.end());
        return true;
      }
      fill(out, s, std::nullopt, std::nullopt, Kind::DataExchange);
      if (m_mode == MasterMode::Operate) {
        out.data.resize(s.layout.outputs);
        s.image->snapshot_outputs(out.data);
      } else if (!s.p.fail_safe) {
        out.data.assign(s.layout.outputs, 0);  // Clear: Output_Clear (§D.9)
      }
      if (s.last_dx != bus::kNever) {
        const bus::Ticks dt = now - s.last_dx;
        auto& st = s.stats;
        st.cycle_min = st.cycle_count == 0 ? dt : std::min(st.cycle_min, dt);
        st.cycle_max = std::max(st.cycle_max, dt);
        st.cycle_last = dt;
        s.cycles[s.cycle_pos] = dt;
        s.cycle_pos = (s.cycle_pos + 1) % kCycleSamples;
        ++st.cycle_count;
      }
      s.last_dx = now;
      return true;
    }
  }
  return false;
}

void Master::on_confirmation(const Confirmation& con) {
  m_now = con.now;
  const Kind kind = m_out_kind;
  const int idx = m_out_slave;
  const bool dh_diag = m_out_dh_diag;
  m_out_kind = Kind::None;
  m_out_slave = -1;
  if (kind == Kind::None || kind == Kind::GlobalControl) return;
  if (idx < 0 || static_cast<std::size_t>(idx) >= m_slaves.size()) return;
  if (con.tag != make_tag(static_cast<int>(kind), idx)) return;  // not ours
  Slave& s = m_slaves[static_cast<std::size_t>(idx)];
  s.stats.retries += con.retries;
  if (kind == Kind::Acyclic && s.jobs.empty()) return;
  if (s.state == SlaveStatusState::Inactive) return;  // the master stopped meanwhile

  if (con.result == Confirmation::Result::NoResponse) {
    if (kind == Kind::Acyclic) finish_job(s, AcyclicStatus::NoResponse, con.now);
    no_response(s, con.now);
    return;
  }
  if (con.result != Confirmation::Result::Ok) {
    // Not sent (the station rejected it), or sent without reply, which a DP request never is:
    // try again next pass, except an acyclic request, which reports it.
    if (kind == Kind::Acyclic) finish_job(s, AcyclicStatus::Rejected, con.now);
    return;
  }
  switch (kind) {
    case Kind::Diag: on_diag(s, con, dh_diag); break;
    case Kind::Prm:
      if (is_empty_ack(con)) {
        s.state = SlaveStatusState::Cfg;
      } else {
        ++s.stats.invalid_responses;
        restart(s, con.now, MasterEvent::Cause::InvalidResponse);
      }
      break;
    case Kind::Cfg:
      if (is_empty_ack(con)) {
        s.state = SlaveStatusState::CheckDiag;
      } else {
        ++s.stats.invalid_responses;
        restart(s, con.now, MasterEvent::Cause::InvalidResponse);
      }
      break;
    case Kind::DataExchange: on_dx(s, con); break;
    case Kind::Acyclic: on_acyclic(s, con); break;
    case Kind::PrmCmd:
      if (is_empty_ack(con)) {
        ++s.stats.prm_cmds;
        MasterEvent e;
        e.kind = MasterEvent::Kind::PrmCmdDone;
        e.time = con.now;
        e.slave = s.p.address;
        emit(e);
      } else {
        ++s.stats.invalid_responses;
        restart(s, con.now, MasterEvent::Cause::InvalidResponse);
      }
      break;
    default: break;
  }
}

// --- diagnosis evaluation (§D.4, §D.9) ------------------------------------------------------------

void Master::store_diag(Slave& s, std::span<const std::uint8_t> du, std::uint8_t extra_status_1,
                        bus::Ticks now, bool force_event) {
  m_scratch.assign(du.begin(), du.end());
  if (m_scratch.size() < kStdDiagLen) {
    // Too short to be a diagnosis: keep the master's own six octets.
    const auto b = StandardDiag{0, 0, 0, kNoMaster, s.p.ident}.encode();
    m_scratch.assign(b.begin(), b.end());
  }
  m_scratch[0] |= extra_status_1;
  const bool changed = m_scratch != s.diag;
  s.diag.swap(m_scratch);
  // Start-up reads are the master's own business; a diagnosis is news once the slave has been
  // in data exchange (S7: OB 82 comes from slaves in operation).
  if ((changed && s.in_dx) || force_event) {
    MasterEvent e;
    e.kind = MasterEvent::Kind::Diagnosis;
    e.time = now;
    e.slave = s.p.address;
    e.diag = s.diag;
    emit(e);
  }
}

void Master::on_diag(Slave& s, const Confirmation& con, bool after_dh) {
  const bus::Ticks now = con.now;
  ++s.stats.diag_reads;
  StandardDiag d;
  if (!is_data(con) || !StandardDiag::decode(con.data, d) || (d.status_2 & kDiagAlways1) == 0) {
    // Implausible: no data, fewer than six octets, or the always-1 bit missing.
    ++s.stats.invalid_responses;
    store_diag(s, is_data(con) ? con.data : std::span<const std::uint8_t>{},
               kDiagInvalidSlaveResponse, now, after_dh);
    restart(s, now, MasterEvent::Cause::InvalidResponse);
    return;
  }
  const bool ours = d.master_add == m_p.address;
  const bool other_master = d.master_add != kNoMaster && !ours;
  const bool was_in_dx = s.in_dx;
  if (other_master) {
    store_diag(s, con.data, kDiagMasterLock, now, after_dh);
    if (s.state != SlaveStatusState::Locked) {
      restart(s, now, MasterEvent::Cause::LeftDataExchange);
      s.state = SlaveStatusState::Locked;
      s.last_retry = now;
    }
    return;
  }
  store_diag(s, con.data, 0, now, after_dh);
  if (was_in_dx && s.p.dpv1()) evaluate_alarms(s, now);

  switch (s.state) {
    case SlaveStatusState::Diag:
    case SlaveStatusState::NotPresent:
    case SlaveStatusState::Locked:
      // Present and free (or already ours): parameterise, whatever faults it shows now.
      s.state = SlaveStatusState::Prm;
      return;
    case SlaveStatusState::CheckDiag:
    case SlaveStatusState::DataExchange: {
      const bool restart_needed = !ours || (d.status_1 & kFaultsRestart) != 0 ||
                                  (d.status_2 & kDiagPrmReq) != 0 ||
                                  (was_in_dx && (d.status_1 & kDiagStationNotReady) != 0);
      if (restart_needed) {
        restart(s, now, MasterEvent::Cause::LeftDataExchange);
        return;
      }
      if ((d.status_1 & kDiagStationNotReady) != 0 || (d.status_2 & kDiagStatDiag) != 0) {
        // Not yet (or static diagnosis): read the diagnosis again next pass, no data exchange.
        if (s.state == SlaveStatusState::DataExchange) {
          s.state = SlaveStatusState::CheckDiag;
          s.image->set_valid(false);
          s.last_dx = bus::kNever;
        }
        return;
      }
      enter_dx(s, now);
      return;
    }
    default: return;
  }
}

void Master::evaluate_alarms(Slave& s, bus::Ticks now) {
  std::vector<ExtDiagBlock> blocks;
  if (s.diag.size() <= kStdDiagLen ||
      !split_ext_diag(std::span<const std::uint8_t>(s.diag).subspan(kStdDiagLen), blocks))
    return;
  std::vector<AlarmKey> present;
  for (const auto& b : blocks) {
    if (b.kind != kBlockDevice || b.bytes.size() < 4) continue;
    const std::uint8_t type = b.bytes[1];
    if ((type & 0x80) != 0 || type == 0 || type == 127) continue;  // status PDU or reserved
    const AlarmKey key{type, b.bytes[2], alarm_seq_nr(b.bytes[3])};
    present.push_back(key);
    if (std::find(s.alarms_seen.begin(), s.alarms_seen.end(), key) != s.alarms_seen.end()) continue;
    ++s.stats.alarms;
    MasterEvent e;
    e.kind = MasterEvent::Kind::Alarm;
    e.time = now;
    e.slave = s.p.address;
    e.diag = s.diag;
    e.alarm_type = type;
    e.alarm_slot = b.bytes[2];
    e.alarm_specifier = b.bytes[3];
    e.alarm_data = b.bytes.subspan(4);
    emit(e);
    if (m_p.auto_alarm_ack) {
      Job j;
      j.id = m_next_job_id++;
      j.fn = kFnAlarmAck;
      j.sap = kSapC1Alarm;
      j.slot = b.bytes[2];
      j.index = type;
      j.length = b.bytes[3];
      j.pdu = {kFnAlarmAck, b.bytes[2], type, b.bytes[3]};
      j.internal = true;
      s.jobs.push_back(std::move(j));
    }
  }
  s.alarms_seen = std::move(present);
}

// --- Data_Exchange (§D.7) -----------------------------------------------------------------------

void Master::on_dx(Slave& s, const Confirmation& con) {
  const bool zero_ok = con.short_ack || (con.status == ResponseStatus::OK && con.data.empty());
  if (zero_ok || is_data(con)) {
    const std::size_t n = zero_ok ? 0 : con.data.size();
    if (n != s.layout.inputs) {
      ++s.stats.invalid_responses;
      store_diag(s, s.diag, kDiagInvalidSlaveResponse, con.now, false);
      restart(s, con.now, MasterEvent::Cause::InvalidResponse);
      return;
    }
    s.image->publish_inputs(zero_ok ? std::span<const std::uint8_t>{} : con.data);
    ++s.stats.data_exchanges;
    if (s.probe) probe_done(s, true);
    if (!zero_ok && con.status == ResponseStatus::DH) {
      ++s.stats.dh;
      s.diag_after_dh = true;
    }
    return;
  }
  if (con.status == ResponseStatus::NR) return;  // no new inputs this time
  restart(s, con.now, MasterEvent::Cause::LeftDataExchange);
}

// --- DP-V1 (§E.2–§E.5) ----------------------------------------------------------------------------

void Master::on_acyclic(Slave& s, const Confirmation& con) {
  Job& j = s.jobs.front();
  if (con.short_ack || ((con.status == ResponseStatus::DL || con.status == ResponseStatus::OK) &&
                        con.data.empty())) {
    if (con.now >= j.deadline) finish_job(s, AcyclicStatus::Timeout, con.now);
    return;  // not ready: poll next pass
  }
  if (is_data(con)) {
    if (con.status == ResponseStatus::DH) s.diag_after_dh = true;
    Dpv1Error err;
    switch (match_record_response(con.data, j.fn, j.slot, j.index, j.length, err)) {
      case Dpv1Match::Ok:
        finish_job(s, AcyclicStatus::Ok, con.now, {},
                   j.fn == kFnRead ? con.data.subspan(4) : con.data);
        return;
      case Dpv1Match::Negative: finish_job(s, AcyclicStatus::Negative, con.now, err, con.data); return;
      case Dpv1Match::Invalid: finish_job(s, AcyclicStatus::InvalidResponse, con.now, {}, con.data); return;
    }
    return;
  }
  finish_job(s, AcyclicStatus::NotAvailable, con.now);
}

void Master::finish_job(Slave& s, AcyclicStatus st, bus::Ticks now, Dpv1Error err,
                        std::span<const std::uint8_t> data) {
  if (s.jobs.empty()) return;
  Job j = std::move(s.jobs.front());
  s.jobs.pop_front();
  if (j.internal && st == AcyclicStatus::Ok) ++s.stats.alarm_acks;
  if (j.fn == kFnAlarmAck && st == AcyclicStatus::Ok) {
    // The slave has it: redundancy::MasterSystem knows then that no repeat can follow.
    MasterEvent e;
    e.kind = MasterEvent::Kind::AlarmAcknowledged;
    e.time = now;
    e.slave = s.p.address;
    e.alarm_type = j.index;
    e.alarm_slot = j.slot;
    e.alarm_specifier = j.length;
    emit(e);
  }
  if (!j.cb) return;
  AcyclicResult r;
  r.id = j.id;
  r.slave = s.p.address;
  r.fn = j.fn;
  r.slot = j.slot;
  r.index = j.index;
  r.status = st;
  r.error = err;
  r.data.assign(data.begin(), data.end());
  j.cb(r);
}

void Master::fail_jobs(Slave& s, bus::Ticks now) {
  while (!s.jobs.empty()) finish_job(s, AcyclicStatus::NotAvailable, now);
}

std::uint32_t Master::queue_job(std::uint8_t address, Job job) {
  if (!has_slave(address)) return 0;
  Slave& s = slave(address);
  if (!s.p.dpv1() || s.state != SlaveStatusState::DataExchange) return 0;
  job.id = m_next_job_id++;
  s.jobs.push_back(std::move(job));
  return s.jobs.back().id;
}

std::uint32_t Master::read(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                           std::uint8_t length, AcyclicCallback cb) {
  if (length == 0 || length > kMaxRecordData) return 0;
  Job j;
  j.fn = kFnRead;
  j.slot = slot;
  j.index = index;
  j.length = length;
  j.pdu = {kFnRead, slot, index, length};
  j.cb = std::move(cb);
  return queue_job(address, std::move(j));
}

std::uint32_t Master::write(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                            std::span<const std::uint8_t> data, AcyclicCallback cb) {
  if (data.empty() || data.size() > kMaxRecordData) return 0;
  Job j;
  j.fn = kFnWrite;
  j.slot = slot;
  j.index = index;
  j.length = static_cast<std::uint8_t>(data.size());
  j.pdu.resize(4 + data.size());
  j.pdu[0] = kFnWrite;
  j.pdu[1] = slot;
  j.pdu[2] = index;
  j.pdu[3] = j.length;
  std::copy(data.begin(), data.end(), j.pdu.begin() + 4);
  j.cb = std::move(cb);
  return queue_job(address, std::move(j));
}

std::uint32_t Master::alarm_ack(std::uint8_t address, std::uint8_t slot, std::uint8_t type,
                                std::uint8_t specifier, AcyclicCallback cb) {
  Job j;
  j.fn = kFnAlarmAck;
  j.sap = kSapC1Alarm;
  j.slot = slot;
  j.index = type;
  j.length = specifier;
  j.pdu = {kFnAlarmAck, slot, type, specifier};
  j.cb = std::move(cb);
  return queue_job(address, std::move(j));
}

// --- failure and return ---------------------------------------------------------------------------

void Master::failure_event(Slave& s, bus::Ticks now, MasterEvent::Cause cause) {
  if (s.failed) return;
  s.failed = true;
  ++s.stats.failures;
  MasterEvent e;
  e.kind = MasterEvent::Kind::StationFailure;
  e.time = now;
  e.slave = s.p.address;
  e.cause = cause;
  e.diag = s.diag;
  emit(e);
}

void Master::restart(Slave& s, bus::Ticks now, MasterEvent::Cause cause) {
  if (s.probe) probe_done(s, false);
  const bool was_in_dx = s.in_dx;
  s.in_dx = false;
  s.image->set_valid(false);
  s.last_dx = bus::kNever;
  s.diag_after_dh = false;
  s.alarms_seen.clear();
  s.state = SlaveStatusState::Diag;
  fail_jobs(s, now);
  if (was_in_dx) {
    failure_event(s, now, cause);
    if (m_mode == MasterMode::Operate && m_p.auto_clear) set_mode(MasterMode::Clear);
  }
}

void Master::no_response(Slave& s, bus::Ticks now) {
  ++s.stats.no_response;
  if (s.probe) probe_done(s, false);
  const bool was_in_dx = s.in_dx;
  s.in_dx = false;
  s.image->set_valid(false);
  s.last_dx = bus::kNever;
  s.diag_after_dh = false;
  s.alarms_seen.clear();
  fail_jobs(s, now);
  const auto b = StandardDiag{kDiagStationNonExistent, 0, 0, kNoMaster, s.p.ident}.encode();
  s.diag.assign(b.begin(), b.end());
  s.state = SlaveStatusState::NotPresent;
  s.last_retry = now;
  failure_event(s, now, MasterEvent::Cause::NoResponse);
  if (was_in_dx && m_mode == MasterMode::Operate && m_p.auto_clear) set_mode(MasterMode::Clear);
}

void Master::enter_dx(Slave& s, bus::Ticks now) {
  s.state = SlaveStatusState::DataExchange;
  s.image->set_valid(true);
  if (s.in_dx) return;  // back from Stat_Diag
  s.in_dx = true;
  MasterEvent e;
  e.time = now;
  e.slave = s.p.address;
  e.diag = s.diag;
  if (s.failed) {
    s.failed = false;
    ++s.stats.returns;
    e.kind = MasterEvent::Kind::StationReturn;
    emit(e);
  }
  e.kind = MasterEvent::Kind::DataExchangeEntered;
  emit(e);
}

}  // namespace pbvbus::dp
