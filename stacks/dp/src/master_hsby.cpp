// Hot standby of the DP master class 1 (master.hpp header comment; docs/quantum-hsby-dp.md):
// the shadow of the active master at the same address, built from the frames a passive
// ActiveStation reports, and the takeover. The per-frame path does not allocate.
#include <algorithm>

#include "confirmation_kind.hpp"

#include "pbvbus/dp/master.hpp"

namespace pbvbus::dp {

using fdl::ResponseStatus;

namespace {
bool shadow_same(std::span<const std::uint8_t> a, const std::vector<std::uint8_t>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end());
}
}  // namespace

void Master::reset_shadow() {
  for (auto& s : m_slaves) {
    s.sh_dx = false;
    s.sh_prm_ok = s.sh_cfg_ok = true;
    s.probe = false;
  }
  m_sh_slave = -1;
  m_sh_kind = Kind::None;
  m_sh_gc_seen = false;
  m_sh_gc_at = bus::kNever;
}

bool Master::shadow_in_dx(std::uint8_t address) const {
  return has_slave(address) && slave(address).sh_dx;
}

void Master::set_standby(bool on) {
  if (on == m_standby) return;
  if (!on) {
    take_over(m_now);
    return;
  }
  // What this master established so far is the shadow's starting point.
  for (auto& s : m_slaves) {
    s.sh_dx = s.in_dx;
    s.sh_prm_ok = s.sh_cfg_ok = true;
    s.probe = false;
  }
  m_sh_slave = -1;
  m_sh_kind = Kind::None;
  m_sh_gc_seen = m_last_gc != bus::kNever;
  m_sh_gc_clear = m_mode == MasterMode::Clear;
  m_sh_gc_at = m_last_gc;
  m_out_kind = Kind::None;
  m_out_slave = -1;
  m_pass_active = false;
  m_standby = true;
}

void Master::take_over(bus::Ticks now) {
  if (!m_standby) return;
  m_standby = false;
  m_now = now;
  ++m_hsby.takeovers;
  m_out_kind = Kind::None;
  m_out_slave = -1;
  m_pass_active = false;
  m_sh_slave = -1;
  m_sh_kind = Kind::None;
  const bool running = m_mode == MasterMode::Clear || m_mode == MasterMode::Operate;
  for (auto& s : m_slaves) {
    s.probe = false;
    if (!s.p.active || !running) continue;
    s.last_dx = s.last_main = s.last_retry = bus::kNever;
    s.diag_after_dh = false;
    if (s.sh_dx && s.sh_prm_ok && s.sh_cfg_ok) {
      // Resume: the slave is in data exchange with "us" (same address, same parameters).
      s.state = SlaveStatusState::DataExchange;
      s.in_dx = true;
      s.failed = false;
      s.image->set_valid(true);
      s.probe = true;
    } else {
      s.state = SlaveStatusState::Diag;
      s.in_dx = false;
      s.image->set_valid(false);
      ++m_hsby.restarted;
    }
  }
  // Global_Control: owed now only if the last one on the line did not announce our mode.
  const bool clear = m_mode == MasterMode::Clear;
  m_gc_due = !(m_sh_gc_seen && m_sh_gc_clear == clear);
  m_last_gc = m_sh_gc_seen ? m_sh_gc_at : bus::kNever;
}

void Master::probe_done(Slave& s, bool ok) {
  s.probe = false;
  if (ok) {
    ++m_hsby.resumed;
  } else {
    ++m_hsby.restarted;
  }
}

void Master::on_observed(bus::Ticks now, const fdl::Telegram& t) {
  if (!m_standby) return;
  m_now = now;
  ++m_hsby.frames_observed;
  const int pending = m_sh_slave;
  const Kind kind = m_sh_kind;
  m_sh_slave = -1;
  m_sh_kind = Kind::None;
  if (t.is_request()) {
    if (t.sa == m_p.address) shadow_request(now, t);
    return;
  }
  if (pending < 0 || t.type == fdl::FrameType::SD4) return;
  Slave& s = m_slaves[static_cast<std::size_t>(pending)];
  if (t.type != fdl::FrameType::SC && (t.sa != s.p.address || t.da != m_p.address)) return;
  shadow_reply(s, kind, t);
}

void Master::shadow_request(bus::Ticks now, const fdl::Telegram& t) {
  if (t.da == fdl::kBroadcast) {
    if (t.dsap && *t.dsap == kSapGlobalControl && t.data.size() == 2) {
      m_sh_gc_seen = true;
      m_sh_gc_at = now;
      m_sh_gc_clear = (t.data[0] & kGcClearData) != 0;
    }
    return;
  }
  if (!has_slave(t.da)) return;
  // Only SRD carries DP services (IEC 61158-6-3); the MAC's own requests to a slave address,
  // e.g. the GAP poll's Request FDL Status (FC 0x49, answered with an empty status reply), are
  // neither a Data_Exchange nor a DP service.
  const fdl::RequestFn fn = fdl::fc_request_fn(t.fc);
  if (fn != fdl::RequestFn::SrdLow && fn != fdl::RequestFn::SrdHigh) return;
  Slave& s = slave(t.da);
  const int idx = m_index[t.da];
  if (!t.dsap) {
    // Data_Exchange: the outputs the slave is about to hold.
    m_sh_slave = idx;
    m_sh_kind = Kind::DataExchange;
    if (t.data.size() == s.layout.outputs && !t.data.empty()) {
      for (std::size_t m = 0; m < s.image->modules(); ++m) {
        const ModuleLayout& ml = s.image->module(m);
        if (ml.out_len > 0) s.image->write_outputs(m, t.data.subspan(ml.out_offset, ml.out_len));
      }
    }
    return;
  }
  switch (*t.dsap) {
    case kSapSetPrm:
      if (t.data.size() == kPrmLenPureCmd && !s.p.prm_cmd.empty())
        break;  // pure PrmCmd: stays in DX
      s.sh_dx = false;
      s.sh_prm_ok = shadow_same(t.data, s.prm);
      break;
    case kSapChkCfg:
      s.sh_dx = false;
      s.sh_cfg_ok = shadow_same(t.data, s.cfg);
      break;
    case kSapSlaveDiag:
      m_sh_slave = idx;
      m_sh_kind = Kind::Diag;
      break;
    default:
      break;
  }
}

void Master::shadow_reply(Slave& s, Kind kind, const fdl::Telegram& t) {
  const bool sc = t.type == fdl::FrameType::SC;
  const ResponseStatus st = sc ? ResponseStatus::OK : fdl::fc_status(t.fc);
  if (kind == Kind::DataExchange) {
    const bool zero_ok = sc || (st == ResponseStatus::OK && t.data.empty());
    const bool data = !sc && (st == ResponseStatus::DL || st == ResponseStatus::DH);
    if (zero_ok || data) {
      const std::size_t n = zero_ok ? 0 : t.data.size();
      s.sh_dx = n == s.layout.inputs;
      if (s.sh_dx) {
        s.image->publish_inputs(zero_ok ? std::span<const std::uint8_t>{} : t.data);
        ++m_hsby.dx_observed;
      }
    } else if (st != ResponseStatus::NR) {
      s.sh_dx = false;  // RS, UE, RR: the slave left data exchange
    }
    return;
  }
  if (kind == Kind::Diag && !sc && t.data.size() >= kStdDiagLen) {
    const std::uint8_t s1 = t.data[0], s2 = t.data[1];
    if ((s1 & (kDiagStationNotReady | kDiagCfgFault | kDiagPrmFault | kDiagNotSupported)) != 0 ||
        (s2 & kDiagPrmReq) != 0 || t.data[3] != m_p.address)
      s.sh_dx = false;
  }
}

}  // namespace pbvbus::dp
