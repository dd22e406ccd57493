// HSystemModel: F4 connections over the CPs and the SSL lists of SFC 51 (the block
// "F4 connections, SSL" of h_system.hpp; rules in h_connections.hpp and h_ssl.hpp).
#include <algorithm>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

// ---- connections ---------------------------------------------------------------------------

std::string HSystemModel::add_connection(const ConnectionConfig& c) {
  std::string err = m_comms.add_connection(c);
  if (err.empty()) comms_update(m_sched.now());  // established at once if the pair allows it
  return err;
}

void HSystemModel::comms_update(bus::Ticks now) {
  m_comms.update(m_pair, now);
  comms_log(now);
  s7_update(now);  // S7 sessions follow their connections (h_system_s7.cpp)
}

void HSystemModel::comms_log(bus::Ticks now) {
  const auto& ev = m_comms.events();
  for (; m_comms_logged < ev.size(); ++m_comms_logged) {
    const CommEvent& e = ev[m_comms_logged];
    log_on_powered(std::max(e.at, now), 0, e.text);
  }
}

bool HSystemModel::cp_failure(int rack, int cp) {
  const bool ok = m_comms.fail_cp(rack, cp, m_pair, m_sched.now());
  comms_log(m_sched.now());
  return ok;
}

bool HSystemModel::repair_cp(int rack, int cp) {
  const bus::Ticks now = m_sched.now();
  if (!m_comms.repair_cp(rack, cp, m_pair, now)) return false;
  // The partner re-establishes the standard connections this CP lost (000 §9.1.4 step 3).
  const auto& cs = m_comms.connections();
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const Connection& c = cs[i];
    if (c.config.kind == ConnectionKind::Standard && c.state == ConnectionState::Lost &&
        c.config.rack == rack && c.config.cp == cp)
      m_comms.reestablish(i, m_pair, now);
  }
  comms_log(now);
  return true;
}

bool HSystemModel::reestablish(std::string_view name) {
  const int i = m_comms.find(name);
  if (i < 0) return false;
  const bool ok = m_comms.reestablish(static_cast<std::size_t>(i), m_pair, m_sched.now());
  comms_log(m_sched.now());
  return ok;
}

// ---- SSL lists (SFC 51) ----------------------------------------------------------------------

namespace {

SslResult error(std::uint16_t code) {
  SslResult r;
  r.ret_val = code;
  return r;
}

SslResult header(std::uint16_t lenthdr, std::uint16_t n_dr) {
  SslResult r;
  put_word(r.data, lenthdr);
  put_word(r.data, n_dr);
  return r;
}

/// led_on, led_blink
std::pair<std::uint8_t, std::uint8_t> led_bytes(Redf r) {
  switch (r) {
    case Redf::Off: return {0, 0};
    case Redf::On: return {1, 0};
    case Redf::Flash2Hz: return {0, 1};
    case Redf::Flash0_5Hz: return {0, 2};
  }
  return {0, 0};
}
std::pair<std::uint8_t, std::uint8_t> led_bytes(BusLed l) {
  return l == BusLed::On ? std::pair<std::uint8_t, std::uint8_t>{1, 0}
                         : std::pair<std::uint8_t, std::uint8_t>{0, l == BusLed::Flashing ? 1 : 0};
}
std::pair<std::uint8_t, std::uint8_t> led_bytes(bool on) {
  return {static_cast<std::uint8_t>(on ? 1 : 0), 0};
}

}  // namespace

std::uint16_t bz_cpu(const HCpuPair& p, int r) {
  switch (p.state(r)) {
    case CpuState::Off: return 0x000F;                               // NO POWER
    case CpuState::Stop: return p.reset_request(r) ? 0x0002 : 0x0004;  // reset memory / internal
    case CpuState::Startup: return 0x0006;                           // warm restart (OB 100)
    case CpuState::Run: return p.system_mode() == SystemMode::Redundant ? 0x0009 : 0x0008;
    case CpuState::Hold: return 0x000A;
    case CpuState::LinkUp: return 0x000B;
    case CpuState::Update: return 0x000C;
    case CpuState::Defective: return 0x000D;
    case CpuState::ErrorSearch: return 0x000E;  // SELFTEST
    case CpuState::SyncUp: return 0x000B;       // 1500: no code of its own (h_ssl.hpp)
  }
  return 0;
}

SslResult HSystemModel::read_ssl(std::uint16_t id, std::uint16_t index) {
  const bus::Ticks now = m_sched.now();
  if (const std::uint16_t busy = m_pair.record_job_result(51, now); busy != 0)
    return error(busy);  // W#16#8085 during the update
  const int cpu = m_pair.master();
  if (cpu < 0) return error(kRetSfc51Update);  // no CPU runs the SFC: not available
  return ssl_from(cpu, id, index);
}

SslResult HSystemModel::read_ssl_on(int rack, std::uint16_t id, std::uint16_t index) {
  const bus::Ticks now = m_sched.now();
  if (const std::uint16_t busy = m_pair.record_job_result(51, now); busy != 0)
    return error(busy);  // W#16#8085 during the update
  if (!valid_rack(rack) || m_pair.state(rack) == CpuState::Off) return error(kRetSfc51Update);
  return ssl_from(rack, id, index);
}

SslResult HSystemModel::ssl_from(int cpu, std::uint16_t id, std::uint16_t index) {
  switch (id) {
    case kSslHState:
      return index == 0 ? ssl_h_state(cpu) : error(kRetSslIndex);
    case kSslHStateHeader:
      return index == 0 ? header(0x0010, 1) : error(kRetSslIndex);
    case kSslSwitchedSlave: return ssl_switched_slave(index);
    case kSslAllLeds:
    case kSslOneLed: return ssl_leds(cpu, id, index);
    case kSslInterrupt: return ssl_interrupt(index);
    case kSslProtection: return ssl_protection(cpu, index);
    default: return error(kRetSslIdUnknown);
  }
}

SslResult HSystemModel::ssl_h_state(int cpu) const {
  const HCpuPair& p = m_pair;
  const bool redundant = p.system_mode() == SystemMode::Redundant;
  SslResult r = header(0x0010, 1);
  put_word(r.data, 0x0012);  // redinf: 1 of 2 H system
  r.data.push_back(static_cast<std::uint8_t>((p.is_master(0) ? 0x10 : 0) |
                                             (p.is_master(1) ? 0x20 : 0)));  // mwstat1
  const bool on0 = p.state(0) != CpuState::Off, on1 = p.state(1) != CpuState::Off;
  r.data.push_back(static_cast<std::uint8_t>((on0 && on1 && p.link_whole() ? 0x01 : 0) |
                                             (on0 && !redundant ? 0x10 : 0) |
                                             (on1 && !redundant ? 0x20 : 0)));  // mwstat2
  put_word(r.data, 0);  // hsfcinfo (SFC 90 not modelled)
  put_word(r.data, 0);  // samfehl (reserved)
  put_word(r.data, bz_cpu(p, 0));
  put_word(r.data, bz_cpu(p, 1));
  put_word(r.data, 0);  // bz_cpu_2 (reserved)
  const int partner = 1 - cpu;
  r.data.push_back(static_cast<std::uint8_t>((1 << cpu) | (p.link_whole() ? 1 << partner : 0)));
  r.data.push_back(0);  // byte 15: not in the excerpt found
  return r;
}

SslResult HSystemModel::ssl_switched_slave(std::uint16_t index) const {
  const std::size_t sys = (index >> 8) == 0 ? m_systems.size() : (index >> 8) - 1u;
  const auto station = static_cast<std::uint8_t>(index & 0xFF);
  if (sys >= m_systems.size()) return error(kRetSslIndex);
  const redundancy::MasterSystem& ms = m_systems[sys]->system();
  const auto addrs = ms.addresses();
  if (std::find(addrs.begin(), addrs.end(), station) == addrs.end() || !ms.is_switched(station))
    return error(kRetSslIndex);
  const int active = ms.active(station);
  SslResult r = header(0x0010, 1);
  put_word(r.data, active == 0 ? index : 0);  // adr1_bgt0
  put_word(r.data, 0);                        // adr2_bgt0 (IM slot: not modelled)
  put_word(r.data, active == 1 ? index : 0);  // adr1_bgt1
  put_word(r.data, 0);                        // adr2_bgt1
  put_word(r.data, 0);                        // res
  put_word(r.data, 0);
  put_word(r.data, index);  // logadr: the model's key (no diagnostic addresses)
  put_word(r.data, 0);      // bytes 14-15: not in the excerpt found
  return r;
}

SslResult HSystemModel::ssl_leds(int cpu, std::uint16_t id, std::uint16_t index) const {
  const bool redundant = m_pair.system_mode() == SystemMode::Redundant;
  if (id == kSslAllLeds && index != 0) return error(kRetSslIndex);
  if (id == kSslAllLeds && redundant) return error(kRetSfc51Update);  // non-redundant modes only
  std::vector<std::uint8_t> ids;
  for (std::size_t s = 0; s < std::min<std::size_t>(m_systems.size(), 2); ++s)
    ids.push_back(static_cast<std::uint8_t>(s == 0 ? LedId::Bus1f : LedId::Bus2f));
  for (LedId l : {LedId::Redf, LedId::Mstr, LedId::Rack0, LedId::Rack1, LedId::Ifm1f,
                  LedId::Ifm2f})
    ids.push_back(static_cast<std::uint8_t>(l));
  if (id == kSslOneLed) {
    if (std::find(ids.begin(), ids.end(), index) == ids.end()) return error(kRetSslIndex);
    ids.assign(1, static_cast<std::uint8_t>(index));
  }
  std::vector<int> racks{cpu};
  if (id == kSslOneLed && redundant) racks = {0, 1};
  SslResult r = header(0x0004, static_cast<std::uint16_t>(ids.size() * racks.size()));
  for (int rack : racks) {
    const HSystemLeds l = leds(rack);
    for (std::uint8_t led : ids) {
      std::pair<std::uint8_t, std::uint8_t> b{0, 0};
      switch (static_cast<LedId>(led)) {
        case LedId::Bus1f: b = led_bytes(l.busf.at(0)); break;
        case LedId::Bus2f: b = led_bytes(l.busf.at(1)); break;
        case LedId::Redf: b = led_bytes(l.cpu.redf); break;
        case LedId::Mstr: b = led_bytes(l.cpu.mstr); break;
        case LedId::Rack0: b = led_bytes(l.cpu.rack0); break;
        case LedId::Rack1: b = led_bytes(l.cpu.rack1); break;
        case LedId::Ifm1f: b = led_bytes(l.cpu.ifm1f); break;
        case LedId::Ifm2f: b = led_bytes(l.cpu.ifm2f); break;
      }
      r.data.push_back(h_cpu_id_byte(rack, m_pair.is_master(rack)));
      r.data.push_back(led);
      r.data.push_back(b.first);
      r.data.push_back(b.second);
    }
  }
  return r;
}

SslResult HSystemModel::ssl_interrupt(std::uint16_t index) const {
  if (index != 70 && index != 72) return error(kRetSslIndex);  // W#16#0048 == 72
  std::uint16_t code = 0;
  for (const HSystemEvent& e : m_events)
    if (e.ob == index) code = e.code;  // the last start of that OB
  SslResult r = header(0x001C, 1);
  put_word(r.data, code);                                    // EV_CLASS, FLT_ID
  r.data.push_back(0);                                       // priority: not in the seeds
  r.data.push_back(static_cast<std::uint8_t>(index));        // OB number
  r.data.insert(r.data.end(), 16, 0);                        // info words, date-time
  put_word(r.data, 0x0010);                                  // al 1: bit 4 OB loaded
  r.data.insert(r.data.end(), 6, 0);                         // al 2, al 3
  return r;
}

SslResult HSystemModel::ssl_protection(int cpu, std::uint16_t index) const {
  if (index != 4) return error(kRetSslIndex);
  std::vector<int> racks{cpu};
  if (m_pair.system_mode() == SystemMode::Redundant) racks = {cpu, 1 - cpu};  // master first
  SslResult r = header(38, static_cast<std::uint16_t>(racks.size()));
  for (int rack : racks) {
    r.data.push_back(h_cpu_id_byte(rack, m_pair.is_master(rack)));
    r.data.push_back(0x04);
    put_word(r.data, 1);                                     // sch_schal
    put_word(r.data, 0);                                     // sch_par: no password
    put_word(r.data, 1);                                     // sch_rel
    put_word(r.data, m_pair.switch_at_run(rack) ? 1 : 3);    // bart_sch: RUN / STOP
    put_word(r.data, 0);                                     // anl_sch: none
    r.data.insert(r.data.end(), 10 + 16, 0);                 // ken_rel, ken_ver x4, res x8
  }
  return r;
}

}  // namespace pbvbus::devices
