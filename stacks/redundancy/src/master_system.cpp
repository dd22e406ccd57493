// The redundant DP master system (master_system.hpp has the decisions).
#include "pbvbus/redundancy/master_system.hpp"

#include <algorithm>
#include <stdexcept>

#include "pbvbus/dp/diagnosis.hpp"

namespace pbvbus::redundancy {

std::string_view to_string(LineLoss c) {
  switch (c) {
    case LineLoss::ShortCircuit: return "short circuit";
    case LineLoss::MasterStop: return "master stop";
    case LineLoss::MasterFailure: return "master failure";
    case LineLoss::CpuFailure: return "CPU failure";
  }
  return "?";
}

std::uint16_t SystemEvent::code() const {
  switch (kind) {
    case Kind::RedundancyLoss: return 0x73A3;
    case Kind::RedundancyReturn: return 0x72A3;
    case Kind::StationFailure: return 0x39C4;
    case Kind::StationReturn: return 0x38C4;
    case Kind::MasterSystemFailure: return 0x39C3;
    case Kind::MasterSystemReturn: return 0x38C3;
    case Kind::Switchover: return 0;
  }
  return 0;
}

int SystemEvent::ob() const {
  switch (kind) {
    case Kind::RedundancyLoss:
    case Kind::RedundancyReturn: return 70;
    case Kind::Switchover: return 0;
    default: return 86;
  }
}

std::string_view to_string(SystemEvent::Kind k) {
  switch (k) {
    case SystemEvent::Kind::RedundancyLoss: return "redundancy loss";
    case SystemEvent::Kind::RedundancyReturn: return "redundancy restored";
    case SystemEvent::Kind::StationFailure: return "station failure";
    case SystemEvent::Kind::StationReturn: return "station return";
    case SystemEvent::Kind::MasterSystemFailure: return "master system failure";
    case SystemEvent::Kind::MasterSystemReturn: return "master system return";
    case SystemEvent::Kind::Switchover: return "switchover";
  }
  return "?";
}

std::string_view to_string(SystemEvent::Cause c) {
  switch (c) {
    case SystemEvent::Cause::None: return "none";
    case SystemEvent::Cause::ChannelFailure: return "channel failure";
    case SystemEvent::Cause::ChannelMissing: return "channel missing";
    case SystemEvent::Cause::LineLost: return "line lost";
    case SystemEvent::Cause::SwitchoverTimeout: return "switchover timeout";
    case SystemEvent::Cause::StartUp: return "start-up";
    case SystemEvent::Cause::Station: return "by the station";
  }
  return "?";
}

std::optional<RedStatusBlock> find_red_status(std::span<const std::uint8_t> diag) {
  if (diag.size() <= dp::kStdDiagLen) return std::nullopt;
  std::vector<dp::ExtDiagBlock> blocks;
  if (!dp::split_ext_diag(diag.subspan(dp::kStdDiagLen), blocks)) return std::nullopt;
  for (const auto& b : blocks) {
    if (b.bytes.size() != kRedStatusLen || b.bytes[1] != kStatusRedStatus) continue;
    RedStatusBlock r;
    if (decode_red_status(b.bytes, r) == RedStatusError::None) return r;
  }
  return std::nullopt;
}

// --------------------------------------------------------------------------------------------

MasterSystem::MasterSystem(dp::Master& a, dp::Master& b, std::vector<SwitchedStationRef> switched,
                           MasterSystemParams p)
    : m_master{&a, &b}, m_p(p) {
  m_index.fill(-1);
  if (m_p.preferred != 0 && m_p.preferred != 1)
    throw std::invalid_argument("master system: the preferred line is 0 or 1");
  if (m_p.switch_attempts < 1) throw std::invalid_argument("master system: switch_attempts >= 1");
  for (const auto& r : switched) {
    const std::string who = "master system: switched station " + std::to_string(r.address) + ": ";
    if (r.address > dp::kMaxSlaveAddress) throw std::invalid_argument(who + "bad address");
    if (m_index[r.address] >= 0) throw std::invalid_argument(who + "listed twice");
    for (int l = 0; l < 2; ++l) {
      if (!m_master[l]->has_slave(r.address))
        throw std::invalid_argument(who + "not configured on line " + std::to_string(l));
      if (m_master[l]->slave_params(r.address).prm_cmd.size() != kPrmCmdLen)
        throw std::invalid_argument(who + "no PrmCmd block in its Set_Prm on line " +
                                    std::to_string(l));
    }
    Station s;
    s.address = r.address;
    s.switched = true;
    s.t_slave_um = r.t_slave_um;
    s.flying = r.flying;
    m_index[r.address] = static_cast<int>(m_st.size());
    m_st.push_back(s);
  }
  for (int l = 0; l < 2; ++l) {
    for (std::uint8_t addr : m_master[l]->addresses()) {
      if (m_index[addr] >= 0) {
        if (m_st[static_cast<std::size_t>(m_index[addr])].switched) continue;
        throw std::invalid_argument("master system: one-sided slave " + std::to_string(addr) +
                                    " is configured on both lines (a switched station?)");
      }
      Station s;
      s.address = addr;
      s.home = l;
      m_index[addr] = static_cast<int>(m_st.size());
      m_st.push_back(s);
    }
  }
  // The start-up blocks: Primary_Request on the preferred line only.
  for (auto& s : m_st) {
    if (!s.switched) continue;
    s.seq = 1;
    for (int l = 0; l < 2; ++l) {
      const auto blk = block(s, l == m_p.preferred);
      m_master[l]->prm_cmd(s.address, blk, false);
    }
  }
}

MasterSystem::Station* MasterSystem::find(std::uint8_t a) {
  return a < 128 && m_index[a] >= 0 ? &m_st[static_cast<std::size_t>(m_index[a])] : nullptr;
}
const MasterSystem::Station* MasterSystem::find(std::uint8_t a) const {
  return a < 128 && m_index[a] >= 0 ? &m_st[static_cast<std::size_t>(m_index[a])] : nullptr;
}

std::array<std::uint8_t, kPrmCmdLen> MasterSystem::block(const Station& s,
                                                         bool primary_request) const {
  PrmCmd c;
  c.seq_nr = s.seq & 0x1F;
  c.primary_request = primary_request;
  c.address_change = true;  // AUMA: Address_Change alone = system redundancy
  c.address_offset64 = s.flying;
  c.output_hold_time = m_p.output_hold_time;
  std::array<std::uint8_t, kPrmCmdLen> out{};
  encode_prm_cmd(c, out);  // cannot fail: Seq_Nr masked, Specifier 0
  return out;
}

bool MasterSystem::reporting(int line) const {
  // A 39C3 line loss reports once for the whole line; a master failure reports per station.
  if (m_line[line].idle) return false;  // never started: nothing to report for it
  return !m_line[line].lost || m_line[line].cause == LineLoss::MasterFailure;
}

std::optional<LineLoss> MasterSystem::line_loss(int line) const {
  if ((line != 0 && line != 1) || !m_line[line].lost) return std::nullopt;
  return m_line[line].cause;
}

bool MasterSystem::mark_line_idle(int line) {
  if (line != 0 && line != 1) return false;
  Line& l = m_line[line];
  if (l.ran || l.lost) return false;
  l.idle = true;
  return true;
}

bool MasterSystem::start_line(int line, bus::Ticks now) {
  if (line != 0 && line != 1) return false;
  if (!m_line[line].idle) return false;
  m_line[line].idle = false;
  m_now = std::max(m_now, now);
  return true;
}

void MasterSystem::emit(SystemEvent::Kind k, bus::Ticks t, int line, std::uint8_t station,
                        SystemEvent::Cause cause, int from) {
  SystemEvent e;
  e.kind = k;
  e.time = t;
  e.line = line;
  e.station = station;
  e.cause = cause;
  e.from = from;
  m_events.push_back(e);
  if (m_cb) m_cb(e);
  for (const auto& l : m_listeners) l(e);
}

void MasterSystem::on_master_event(int line, const dp::MasterEvent& e) {
  if (line != 0 && line != 1) return;
  m_now = std::max(m_now, e.time);
  using K = dp::MasterEvent::Kind;
  if (e.kind == K::ModeChange) {
    const bool running = e.mode == dp::MasterMode::Clear || e.mode == dp::MasterMode::Operate;
    if (!running) line_lost(line, LineLoss::MasterStop, e.time);
    else if (m_line[line].lost && m_line[line].cause == LineLoss::MasterStop)
      line_back(line, e.time);
    return;
  }
  Station* s = find(e.slave);
  if (s == nullptr || (!s->switched && s->home != line)) return;
  switch (e.kind) {
    case K::StationFailure: channel_down(*s, line, e.time, reporting(line)); break;
    case K::DataExchangeEntered: channel_up(*s, line, e.time, e.diag); break;
    case K::Diagnosis:
      if (s->switched) observe_red_status(*s, line, e.diag, e.time);
      on_diagnosis_event(*s, line, e);
      break;
    case K::Alarm: on_alarm_event(*s, line, e); break;
    case K::AlarmAcknowledged: on_alarm_ack(*s, line, e); break;
    default: break;
  }
}

void MasterSystem::on_alarm_event(Station& s, int line, const dp::MasterEvent& e) {
  const std::uint8_t spec = e.alarm_specifier & 0x03;
  const std::uint8_t seq = dp::alarm_seq_nr(e.alarm_specifier);
  // Orphans past the window are no longer expected to come back.
  std::erase_if(s.unacked, [&](const Station::Unacked& u) {
    return u.orphaned != bus::kNever && e.time - u.orphaned > m_p.alarm_repeat_window;
  });
  for (auto& u : s.unacked) {
    if (u.type != e.alarm_type || u.slot != e.alarm_slot || u.spec != spec) continue;
    if (u.orphaned == bus::kNever && u.line == line) continue;  // a new one on the same channel
    if (!std::equal(u.data.begin(), u.data.end(), e.alarm_data.begin(), e.alarm_data.end())) continue;
    // The station's repeat on its new primary: its master acknowledges it; the program has it.
    u.line = line;
    u.seq = seq;
    u.orphaned = bus::kNever;
    ++m_alarm_repeats;
    return;
  }
  Station::Unacked u;
  u.line = line;
  u.type = e.alarm_type;
  u.slot = e.alarm_slot;
  u.seq = seq;
  u.spec = spec;
  u.data.assign(e.alarm_data.begin(), e.alarm_data.end());
  s.unacked.push_back(std::move(u));
  SystemAlarm a;
  a.time = e.time;
  a.station = s.address;
  a.line = line;
  a.type = e.alarm_type;
  a.slot = e.alarm_slot;
  a.specifier = e.alarm_specifier;
  a.data.assign(e.alarm_data.begin(), e.alarm_data.end());
  m_alarms.push_back(a);
  if (m_alarm_cb) m_alarm_cb(m_alarms.back());
}

std::vector<std::uint8_t> diagnosis_content(std::span<const std::uint8_t> diag) {
  std::vector<std::uint8_t> out;
  std::vector<dp::ExtDiagBlock> blocks;
  if (diag.size() <= dp::kStdDiagLen ||
      !dp::split_ext_diag(diag.subspan(dp::kStdDiagLen), blocks))
    return out;
  for (const auto& b : blocks) {
    // Prm_Cmd_Ack (0x9E) and Red_Status (0x9F): the redundancy's own state, per line.
    if (b.kind == dp::kBlockDevice && b.bytes.size() >= 2 &&
        (b.bytes[1] == 0x9E || b.bytes[1] == 0x9F))
      continue;
    out.insert(out.end(), b.bytes.begin(), b.bytes.end());
  }
  return out;
}

void MasterSystem::on_diagnosis_event(Station& s, int line, const dp::MasterEvent& e) {
  const int act = s.switched ? s.active : s.home;
  if (line != act) return;  // the passive channel's diagnosis is not the program's
  auto content = diagnosis_content(e.diag);
  if (content == s.diag_content) return;
  SystemDiagnosis d;
  d.time = e.time;
  d.station = s.address;
  d.line = line;
  d.diag.assign(e.diag.begin(), e.diag.end());
  d.previous = s.diag_du;
  s.diag_content = std::move(content);
  s.diag_du = d.diag;
  ++m_diag_changes;
  if (m_diag_cb) m_diag_cb(d);
}

void MasterSystem::on_alarm_ack(Station& s, int line, const dp::MasterEvent& e) {
  const std::uint8_t seq = dp::alarm_seq_nr(e.alarm_specifier);
  std::erase_if(s.unacked, [&](const Station::Unacked& u) {
    return u.line == line && u.type == e.alarm_type && u.slot == e.alarm_slot && u.seq == seq;
  });
}

void MasterSystem::observe_red_status(Station& s, int line, std::span<const std::uint8_t> diag,
                                      bus::Ticks now) {
  const auto rs = find_red_status(diag);
  if (!rs || !rs->own.primary || !s.up[line]) return;
  // The station says which interface drives its outputs: that is the active channel, whether
  // we commanded it or the station switched by itself.
  const int from = s.active;
  s.active = line;
  if (from != line && s.target != line)
    emit(SystemEvent::Kind::Switchover, now, line, s.address,
         from < 0 ? SystemEvent::Cause::StartUp : SystemEvent::Cause::Station, from);
  if (s.target == line) {
    s.target = -1;
    s.deadline = bus::kNever;
    s.attempts = 0;
  }
}

void MasterSystem::channel_up(Station& s, int line, bus::Ticks now,
                              std::span<const std::uint8_t> diag) {
  const int other = 1 - line;
  s.up[line] = true;
  s.down[line] = false;
  m_line[line].ran = true;
  if (!s.switched) {
    if (s.failed) {
      s.failed = false;
      if (!s.silent_failed) emit(SystemEvent::Kind::StationReturn, now, line, s.address);
      s.silent_failed = false;
    }
    return;
  }
  if (s.failed) {
    s.failed = false;
    if (!s.silent_failed) emit(SystemEvent::Kind::StationReturn, now, line, s.address);
    s.silent_failed = false;
  }
  if (s.up[other] && s.red_lost) {
    s.red_lost = false;
    if (!s.silent_red_lost) emit(SystemEvent::Kind::RedundancyReturn, now, line, s.address);
    s.silent_red_lost = false;
  } else if (s.down[other] && !s.red_lost) {
    // Start-up with the other channel absent.
    s.red_lost = true;
    s.silent_red_lost = !reporting(other);
    if (!s.silent_red_lost)
      emit(SystemEvent::Kind::RedundancyLoss, now, other, s.address,
           SystemEvent::Cause::ChannelMissing);
  }
  observe_red_status(s, line, diag, now);
  const bool has_primary = s.active >= 0 && s.up[s.active];
  if (!has_primary && s.target < 0) switch_to(s, line, now, SystemEvent::Cause::StartUp);
}

void MasterSystem::channel_down(Station& s, int line, bus::Ticks now, bool report,
                                SystemEvent::Cause cause) {
  const int other = 1 - line;
  const bool was_up = s.up[line];
  s.up[line] = false;
  s.down[line] = true;
  // Alarms read on this channel and not yet acknowledged may come again from the station.
  for (auto& u : s.unacked)
    if (u.line == line && u.orphaned == bus::kNever) u.orphaned = now;
  if (!s.switched) {
    if (!s.failed) {
      s.failed = true;
      s.silent_failed = !report;
      if (report) emit(SystemEvent::Kind::StationFailure, now, line, s.address, cause);
    }
    return;
  }
  if (s.active == line) s.active = -1;
  if (s.up[other]) {
    if (!s.red_lost) {
      s.red_lost = true;
      s.silent_red_lost = !report;
      if (report)
        emit(SystemEvent::Kind::RedundancyLoss, now, line, s.address,
             was_up ? cause : SystemEvent::Cause::ChannelMissing);
    }
    // The other channel is up: make it active unless it already is (or is becoming so).
    if (s.active != other && s.target != other) switch_to(s, other, now, cause);
    return;
  }
  if (s.down[other]) {
    // Both channels gone (F11, F24): the station has failed.
    s.target = -1;
    s.deadline = bus::kNever;
    s.active = -1;
    if (!s.failed) {
      s.failed = true;
      s.silent_failed = !report;
      if (report) emit(SystemEvent::Kind::StationFailure, now, line, s.address, cause);
    }
  }
  // Otherwise the other channel's state is not known yet (start-up): wait for it.
}

void MasterSystem::switch_to(Station& s, int line, bus::Ticks now, SystemEvent::Cause cause) {
  const int other = 1 - line;
  s.seq = static_cast<std::uint8_t>((s.seq + 1) & 0x1F);
  const auto req = block(s, true);
  const auto idle = block(s, false);
  // The failed/old line's stored Set_Prm loses its Primary_Request first (no switch back at a
  // later re-start-up there), then the request goes out on the new line.
  m_master[other]->prm_cmd(s.address, idle, false);
  m_master[line]->prm_cmd(s.address, req, true);
  const int from = s.active;
  s.target = line;
  if (s.attempts == 0 || cause != SystemEvent::Cause::SwitchoverTimeout) s.attempts = 1;
  s.deadline = now + std::max(m_p.switch_supervision, 2 * s.t_slave_um);
  ++m_switchovers;
  emit(SystemEvent::Kind::Switchover, now, line, s.address, cause, from);
}

void MasterSystem::line_lost(int line, LineLoss cause, bus::Ticks now) {
  if ((line != 0 && line != 1) || m_line[line].lost || m_line[line].idle) return;
  m_line[line].lost = true;
  m_line[line].cause = cause;
  const bool per_station = cause == LineLoss::MasterFailure;
  if (!per_station)
    emit(SystemEvent::Kind::MasterSystemFailure, now, line, 0xFF, SystemEvent::Cause::LineLost);
  for (auto& s : m_st) {
    if (!s.switched && s.home != line) continue;
    if (!s.up[line] && s.down[line]) continue;
    channel_down(s, line, now, per_station, SystemEvent::Cause::LineLost);
  }
}

void MasterSystem::line_back(int line, bus::Ticks now) {
  if ((line != 0 && line != 1) || !m_line[line].lost || m_line[line].idle) return;
  m_line[line].lost = false;
  if (m_line[line].cause != LineLoss::MasterFailure)
    emit(SystemEvent::Kind::MasterSystemReturn, now, line, 0xFF, SystemEvent::Cause::LineLost);
  // The channels come back one by one as the line's master reaches data exchange with them.
}

bus::Ticks MasterSystem::next_deadline() const {
  bus::Ticks t = bus::kNever;
  for (const auto& s : m_st) t = std::min(t, s.deadline);
  // A record job waiting for a channel is looked at every call (its wait ends with a channel).
  for (const auto& r : m_records)
    if (r.line < 0) t = std::min(t, r.waiting_since);
  return t;
}

std::uint32_t MasterSystem::read(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                                 std::uint8_t length, dp::AcyclicCallback cb, bus::Ticks now) {
  Record r;
  r.address = address;
  r.slot = slot;
  r.index = index;
  r.length = length;
  r.cb = std::move(cb);
  m_now = std::max(m_now, now);
  if (!start_record(r)) return 0;
  r.id = m_next_record++;
  m_records.push_back(std::move(r));
  return m_records.back().id;
}

std::uint32_t MasterSystem::write(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                                  std::span<const std::uint8_t> data, dp::AcyclicCallback cb,
                                  bus::Ticks now) {
  Record r;
  r.address = address;
  r.write = true;
  r.slot = slot;
  r.index = index;
  r.data.assign(data.begin(), data.end());
  r.cb = std::move(cb);
  m_now = std::max(m_now, now);
  if (!start_record(r)) return 0;
  r.id = m_next_record++;
  m_records.push_back(std::move(r));
  return m_records.back().id;
}

bool MasterSystem::start_record(Record& r) {
  const int line = active(r.address);
  if (line < 0) return false;
  // The id is not known yet for a new job: the callback finds it by the master's job id.
  const std::uint32_t sys_id = r.id != 0 ? r.id : m_next_record;
  auto done = [this, sys_id](const dp::AcyclicResult& res) { record_done(sys_id, res); };
  const std::uint32_t mid =
      r.write ? m_master[line]->write(r.address, r.slot, r.index, r.data, std::move(done))
              : m_master[line]->read(r.address, r.slot, r.index, r.length, std::move(done));
  if (mid == 0) return false;
  r.line = line;
  r.waiting_since = bus::kNever;
  ++r.attempts;
  return true;
}

void MasterSystem::record_done(std::uint32_t id, const dp::AcyclicResult& res) {
  auto it = std::find_if(m_records.begin(), m_records.end(),
                         [id](const Record& r) { return r.id == id; });
  if (it == m_records.end()) return;
  using St = dp::AcyclicStatus;
  const bool interrupted = res.status == St::NoResponse || res.status == St::NotAvailable ||
                           res.status == St::Timeout || res.status == St::Rejected;
  if (interrupted && it->attempts < m_p.record_attempts) {
    // Wait for the station's (new) active channel; retry_records() starts it again.
    it->line = -1;
    it->waiting_since = m_now;
    return;
  }
  Record r = std::move(*it);
  m_records.erase(it);
  dp::AcyclicResult out = res;
  out.id = r.id;
  if (r.cb) r.cb(out);
}

void MasterSystem::retry_records(bus::Ticks now) {
  for (std::size_t i = 0; i < m_records.size();) {
    Record& r = m_records[i];
    if (r.line >= 0) {
      ++i;
      continue;
    }
    const int line = active(r.address);
    const bool channel = line >= 0 && switching_to(r.address) < 0;
    if (channel && start_record(r)) {
      ++m_record_repeats;
      ++i;
      continue;
    }
    if (now - r.waiting_since >= m_p.record_wait) {
      Record done = std::move(r);
      m_records.erase(m_records.begin() + static_cast<std::ptrdiff_t>(i));
      dp::AcyclicResult res;
      res.id = done.id;
      res.slave = done.address;
      res.fn = done.write ? dp::kFnWrite : dp::kFnRead;
      res.slot = done.slot;
      res.index = done.index;
      res.status = dp::AcyclicStatus::NotAvailable;
      if (done.cb) done.cb(res);
      continue;
    }
    ++i;
  }
}

void MasterSystem::on_time(bus::Ticks now) {
  m_now = now;
  retry_records(now);
  for (auto& s : m_st) {
    if (s.deadline > now) continue;
    s.deadline = bus::kNever;
    const int line = s.target;
    s.target = -1;
    if (line < 0) continue;
    if (s.up[line] && s.attempts < m_p.switch_attempts) {
      const int tries = s.attempts + 1;
      switch_to(s, line, now, SystemEvent::Cause::SwitchoverTimeout);
      s.attempts = tries;
      continue;
    }
    // F24: the station did not take over in time: it is lost as a whole.
    s.active = -1;
    s.attempts = 0;
    if (!s.failed) {
      s.failed = true;
      s.silent_failed = false;
      emit(SystemEvent::Kind::StationFailure, now, line, s.address,
           SystemEvent::Cause::SwitchoverTimeout);
    }
  }
}

bool MasterSystem::is_switched(std::uint8_t a) const {
  const Station* s = find(a);
  return s != nullptr && s->switched;
}
int MasterSystem::active(std::uint8_t a) const {
  const Station* s = find(a);
  if (s == nullptr) return -1;
  if (!s->switched) return s->up[s->home] ? s->home : -1;
  return s->active;
}
int MasterSystem::switching_to(std::uint8_t a) const {
  const Station* s = find(a);
  return s != nullptr ? s->target : -1;
}
bool MasterSystem::channel_up(std::uint8_t a, int line) const {
  const Station* s = find(a);
  return s != nullptr && (line == 0 || line == 1) && s->up[line];
}
bool MasterSystem::redundancy_lost(std::uint8_t a) const {
  const Station* s = find(a);
  return s != nullptr && s->red_lost;
}
bool MasterSystem::station_failed(std::uint8_t a) const {
  const Station* s = find(a);
  return s != nullptr && s->failed;
}
std::vector<std::uint8_t> MasterSystem::addresses() const {
  std::vector<std::uint8_t> out;
  for (const auto& s : m_st) out.push_back(s.address);
  std::sort(out.begin(), out.end());
  return out;
}

bool MasterSystem::write_outputs(std::uint8_t a, std::size_t module,
                                 std::span<const std::uint8_t> data) {
  const Station* s = find(a);
  if (s == nullptr) return false;
  bool ok = true;
  for (int l = 0; l < 2; ++l) {
    if (!s->switched && s->home != l) continue;
    dp::MasterImage& img = m_master[l]->image(a);
    if (img.write_outputs(module, data) != dp::ImageAccess::Ok) ok = false;
  }
  return ok;
}

bool MasterSystem::write_outputs(int line, std::uint8_t a, std::size_t module,
                                 std::span<const std::uint8_t> data) {
  const Station* s = find(a);
  if (s == nullptr || line < 0 || line > 1 || (!s->switched && s->home != line)) return false;
  return m_master[line]->image(a).write_outputs(module, data) == dp::ImageAccess::Ok;
}

const dp::MasterImage* MasterSystem::active_image(std::uint8_t a) const {
  const int l = active(a);
  return l < 0 ? nullptr : &m_master[l]->image(a);
}

}  // namespace pbvbus::redundancy
