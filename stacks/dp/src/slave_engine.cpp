// DP slave engine (protocol-facts.md §D, §E, §F); decisions are listed in slave_engine.hpp.
#include "pbvbus/dp/slave_engine.hpp"

#include <algorithm>
#include <stdexcept>

#include "pbvbus/dp/dpv1_pdu.hpp"
#include "pbvbus/dp/sap.hpp"
#include "record_key.hpp"

namespace pbvbus::dp {

using fdl::Indication;
using fdl::Reply;
using fdl::RequestFn;
using fdl::ResponseStatus;

namespace {
SlaveLayout checked_layout(const SlaveConfig& cfg) {
  SlaveLayout l;
  const std::string why = build_layout(cfg, l);
  if (!why.empty()) throw std::invalid_argument("DP slave configuration: " + why);
  return l;
}
bool is_srd(RequestFn fn) { return fn == RequestFn::SrdHigh || fn == RequestFn::SrdLow; }
}  // namespace

SlaveEngine::SlaveEngine(SlaveConfig cfg)
    : m_cfg(std::move(cfg)), m_layout(checked_layout(m_cfg)), m_app(m_layout),
      m_diag(m_cfg.max_diag_len) {
  m_c2.resize(m_cfg.features.c2 ? m_cfg.features.c2_connections : 0);
  m_scratch_ids.reserve(m_layout.modules.size() + 64);
  m_cfg_fault_modules.reserve(m_layout.modules.size() + 64);
}

// --- state helpers ----------------------------------------------------------------------------

void SlaveEngine::set_state(SlaveState s) {
  m_state = s;
  m_app.m_state.store(s, std::memory_order_release);
}

void SlaveEngine::set_outputs_safe() {
  m_app.m_image.clear_outputs();
  m_app.m_outputs_safe.store(true, std::memory_order_release);
}

void SlaveEngine::apply_outputs() {
  m_app.m_image.write_all_outputs({m_rx_outputs.data(), m_layout.outputs});
  m_app.m_outputs_safe.store(false, std::memory_order_release);
}

void SlaveEngine::snapshot_inputs(std::span<std::uint8_t> out) {
  if (m_freeze_mode && !mutated(EngineMutation::IgnoreFreeze))
    std::copy_n(m_frozen.begin(), m_layout.inputs, out.begin());
  else
    m_app.m_image.read_all_inputs(out.first(m_layout.inputs));
}

void SlaveEngine::enter_data_exchange() {
  set_state(SlaveState::DataExch);
  ++m_stats.data_exch_entries;
  std::lock_guard lk(m_app.m_mu);
  m_app.m_alarms.clear();
  m_app.m_alarms_open = m_dpv1.dpv1_enable();
  m_app.m_alarm_enables = m_dpv1.dpv1_enable() ? m_dpv1.alarm_enables() : 0;
  m_app.m_alarm_mode = m_dpv1.alarm_mode();
}

void SlaveEngine::leave_operation() {
  set_outputs_safe();
  std::fill_n(m_rx_outputs.begin(), m_layout.outputs, 0);
  m_sync_mode = m_freeze_mode = m_clear = m_fail_safe_zero = false;
  m_c1 = PendingRecord{};
  std::lock_guard lk(m_app.m_mu);
  m_app.m_alarms_open = false;
  m_app.m_alarms.clear();
}

void SlaveEngine::go_wait_prm() {
  leave_operation();
  set_state(SlaveState::WaitPrm);
  m_master = kNoMaster;
  m_app.m_master.store(kNoMaster, std::memory_order_release);
  m_wd_on = false;
  m_wd_deadline = bus::kNever;
  m_sync_enabled = m_freeze_enabled = false;
  m_group = 0;
  m_dpv1 = {};
}

void SlaveEngine::on_power_on(bus::Ticks now) {
  if (mutated(EngineMutation::KeepStateOnPowerCycle)) {  // mutant: nothing is forgotten
    if (m_wd_on) m_wd_deadline = now + m_wd_ticks;
    return;
  }
  m_prm_fault = m_cfg_fault = m_not_supported = false;
  m_cfg_fault_modules.clear();
  go_wait_prm();
  for (auto& c : m_c2) c = C2Connection{};
  m_diag_pending = false;
  m_seen_diag_gen = m_app.m_diag_gen.load(std::memory_order_acquire);
}

// --- time ---------------------------------------------------------------------------------------

bus::Ticks SlaveEngine::next_deadline() const {
  bus::Ticks t =
      m_wd_on && !mutated(EngineMutation::IgnoreWatchdog) ? m_wd_deadline : bus::kNever;
  for (const auto& c : m_c2)
    if (c.st != C2Connection::St::Closed) t = std::min(t, c.deadline);
  return t;
}

void SlaveEngine::on_time(bus::Ticks now) { check_timers(now); }

void SlaveEngine::check_timers(bus::Ticks now) {
  if (m_wd_on && now >= m_wd_deadline &&
      !mutated(EngineMutation::IgnoreWatchdog)) {  // watchdog expiry (§D.8)
    ++m_stats.watchdog_expiries;
    go_wait_prm();
  }
  for (auto& c : m_c2)
    if (c.st != C2Connection::St::Closed && now >= c.deadline) c = C2Connection{};
}

// --- dispatch -----------------------------------------------------------------------------------

void SlaveEngine::on_request(const Indication& ind, Reply& reply) {
  check_timers(ind.now);
  const bool from_owner = m_master != kNoMaster && ind.sa == m_master;
  if (from_owner && m_wd_on) m_wd_deadline = ind.now + m_wd_ticks;

  if (ind.broadcast()) {
    if (ind.dsap == kSapGlobalControl) {
      ++m_stats.global_control;
      handle_global_control(ind, reply);
    } else {
      ++m_stats.other;
    }
    reply.none();
    return;
  }
  // A slave at the default address 126 is in Power_On: only diagnosis, Get_Cfg and
  // Set_Slave_Add make sense there (§D.8).
  if (ind.da == kDefaultSlaveAddress && m_state == SlaveState::WaitPrm) set_state(SlaveState::PowerOn);
  if (ind.da != kDefaultSlaveAddress && m_state == SlaveState::PowerOn) set_state(SlaveState::WaitPrm);

  if (!ind.dsap) {
    if (is_srd(ind.fn)) {
      ++m_stats.data_exchange;
      if (mutated(EngineMutation::SlowSlaveInterval)) [[unlikely]] {
        // Mutant: still busy with the last one; 10 x Min_Slave_Interval (100 us units).
        const bus::Ticks busy =
            10 * static_cast<bus::Ticks>(m_cfg.min_slave_interval) * (bus::kTicksPerMs / 10);
        if (from_owner && m_last_dx_valid && ind.now - m_last_dx < busy) {
          reply.none();
          return;
        }
        handle_data_exchange(ind, reply);
        if (from_owner && reply.kind != Reply::Kind::Status) {
          m_last_dx = ind.now;
          m_last_dx_valid = true;
        }
      } else {
        handle_data_exchange(ind, reply);
      }
    } else {
      ++m_stats.other;
    }
  } else {
    const std::uint8_t dsap = *ind.dsap;
    count_request(dsap);
    switch (dsap) {
      case kSapSetPrm: handle_set_prm(ind, reply); break;
      case kSapChkCfg: handle_chk_cfg(ind, reply); break;
      case kSapSlaveDiag: handle_slave_diag(ind, reply); break;
      case kSapGetCfg:
        if (m_layout.cfg.empty()) {
          reply.short_ack();
        } else if (mutated(EngineMutation::WrongGetCfg)) {  // mutant: last octet + 1
          std::vector<std::uint8_t> cfg = m_layout.cfg;
          ++cfg.back();
          reply.respond(ResponseStatus::DL, cfg);
        } else {
          reply.respond(ResponseStatus::DL, m_layout.cfg);
        }
        if (mutated(EngineMutation::GetCfgSapsNotSwapped)) [[unlikely]] reply.saps_not_mirrored = true;
        break;
      case kSapGlobalControl: handle_global_control(ind, reply); break;
      case kSapSetSlaveAdd: handle_set_slave_add(ind, reply); break;
      case kSapRdInp: handle_rd_inp(reply); break;
      case kSapRdOutp: handle_rd_outp(reply); break;
      case kSapC1ReadWrite: handle_c1_read_write(ind, reply); break;
      case kSapC1Alarm: handle_c1_alarm(ind, reply); break;
      case kSapC2ResourceManager: handle_c2_rm(ind, reply); break;
      default:
        if (dsap <= kSapC2ConnectionHigh &&
            static_cast<std::size_t>(kSapC2ConnectionHigh - dsap) < m_c2.size()) {
          auto& c = m_c2[kSapC2ConnectionHigh - dsap];
          if (c.st != C2Connection::St::Closed && c.master == ind.sa) handle_c2_conn(c, ind, reply);
        }
        break;  // anything else: RS (the preset)
    }
  }
  if (!fdl::fn_expects_reply(ind.fn)) reply.none();
  if (reply.kind == Reply::Kind::Status && reply.status == ResponseStatus::RS) ++m_stats.refused;
}

void SlaveEngine::count_request(std::uint8_t dsap) {
  switch (dsap) {
    case kSapSetPrm: ++m_stats.set_prm; break;
    case kSapChkCfg: ++m_stats.chk_cfg; break;
    case kSapSlaveDiag: ++m_stats.slave_diag; break;
    case kSapGetCfg: ++m_stats.get_cfg; break;
    case kSapGlobalControl: ++m_stats.global_control; break;
    case kSapSetSlaveAdd: ++m_stats.set_slave_add; break;
    case kSapRdInp: ++m_stats.rd_inp; break;
    case kSapRdOutp: ++m_stats.rd_outp; break;
    default:
      if (dsap <= kSapC1ReadWrite) ++m_stats.dpv1;
      else ++m_stats.other;
      break;
  }
}

// --- Set_Prm (§D.2) -----------------------------------------------------------------------------

void SlaveEngine::handle_set_prm(const Indication& ind, Reply& reply) {
  if (m_state == SlaveState::PowerOn) return;  // RS
  reply.short_ack();
  if (m_master != kNoMaster && ind.sa != m_master && !mutated(EngineMutation::IgnoreLock))
    return;  // locked by another master

  PrmView pv;
  if (!parse_prm(ind.data, pv)) {
    ++m_stats.prm_faults;
    m_prm_fault = true;
    go_wait_prm();
    return;
  }
  const PrmHeader& h = pv.header;
  if (h.min_tsdr != 0 && !h.lock_req()) reply.new_min_tsdr = h.min_tsdr;
  if (!h.lock_req() && !h.unlock_req()) return;  // only min TSDR may change
  if (h.unlock_req()) {
    if (m_master != kNoMaster) go_wait_prm();  // released for other masters
    return;
  }

  const SlaveFeatures& f = m_cfg.features;
  // A pure PrmCmd from the owner of a parameterised slave: only the block counts (§G.2).
  if (ind.data.size() == kPrmLenPureCmd && ind.sa == m_master && f.prm_cmd && f.prm_structure &&
      (m_state == SlaveState::WaitCfg || m_state == SlaveState::DataExch)) {
    const Dpv1Status pd = pv.dpv1();
    const auto block = pv.user_prm.subspan(3);
    if (pd.prm_cmd() && pd.prm_structure() && block[0] == kPrmCmdBlockLen &&
        block[1] == kPrmBlockPrmCmd) {
      const PrmCmdResult r = m_cfg.on_prm_cmd
                                 ? m_cfg.on_prm_cmd(PrmCmdView{ind.now, ind.sa, true, block})
                                 : PrmCmdResult::Accept;
      if (r == PrmCmdResult::Reject) {
        ++m_stats.prm_faults;
        go_wait_prm();
        m_prm_fault = true;
      }
      return;
    }
  }
  bool fault = false;
  bool not_supported = false;
  if (h.ident != m_cfg.ident && !mutated(EngineMutation::AcceptWrongIdent)) fault = true;
  if (h.wd_on() && (h.wd_fact_1 == 0 || h.wd_fact_2 == 0)) fault = true;
  if ((h.sync_req() && !f.sync) || (h.freeze_req() && !f.freeze)) not_supported = true;
  const std::size_t up = pv.user_prm.size();
  if (up < m_cfg.min_user_prm_len || up > m_cfg.max_user_prm_len) fault = true;
  Dpv1Status d;
  std::vector<PrmBlock> blocks;  // not on the cyclic path
  if (f.dpv1 && up >= 3) {
    d = pv.dpv1();
    if (d.fail_safe() && !f.fail_safe) fault = true;
    if (d.wd_base_1ms() && !f.wd_base_1ms) fault = true;
    if ((d.s1 & kDpv1PublisherEnable) != 0) fault = true;  // DXB publisher: not supported
    if (d.check_cfg_mode() && !f.check_cfg_mode) fault = true;
    if (d.alarm_enables() & ~f.alarms_supported) fault = true;
    if (d.alarm_mode() > f.max_alarm_mode) fault = true;
    // Isochronous mode is not implemented; structured blocks and PrmCmd only where the
    // configuration says so (the blocks themselves go to check_user_prm).
    if (d.isom_req()) fault = true;
    if (d.prm_cmd() && !f.prm_cmd) fault = true;
    if (d.prm_structure()) {
      if (!f.prm_structure || !split_prm_blocks(pv.user_prm.subspan(3), blocks)) fault = true;
      // A PrmCmd block needs the PrmCmd bit and has exactly 8 octets; at most one per Set_Prm.
      std::size_t n_cmd = 0;
      for (const auto& b : blocks) {
        if (b.type != kPrmBlockPrmCmd) continue;
        ++n_cmd;
        if (!d.prm_cmd() || b.bytes.size() != kPrmCmdBlockLen || n_cmd > 1) fault = true;
      }
    }
    if (!d.dpv1_enable() && (d.alarm_enables() != 0 || d.check_cfg_mode())) fault = true;
  }
  if (!fault && m_cfg.check_user_prm && !m_cfg.check_user_prm(pv.user_prm)) fault = true;
  if (!fault && !not_supported && m_cfg.on_prm_cmd)
    for (const auto& b : blocks)
      if (b.type == kPrmBlockPrmCmd &&
          m_cfg.on_prm_cmd(PrmCmdView{ind.now, ind.sa, false, b.bytes}) == PrmCmdResult::Reject)
        fault = true;

  if (fault || not_supported) {
    ++m_stats.prm_faults;
    go_wait_prm();
    m_prm_fault = fault;
    m_not_supported = not_supported;
    return;
  }
  if (m_state == SlaveState::DataExch || m_state == SlaveState::WaitCfg) leave_operation();
  m_prm_fault = m_not_supported = m_cfg_fault = false;
  m_cfg_fault_modules.clear();
  m_master = ind.sa;
  m_app.m_master.store(ind.sa, std::memory_order_release);
  m_group = h.group_ident;
  m_sync_enabled = h.sync_req();
  m_freeze_enabled = h.freeze_req();
  m_dpv1 = d;
  m_wd_on = h.wd_on();
  m_wd_ticks = m_wd_on ? watchdog_ticks(h.wd_fact_1, h.wd_fact_2, f.wd_base_1ms && d.wd_base_1ms())
                       : 0;
  m_wd_deadline = m_wd_on ? ind.now + m_wd_ticks : bus::kNever;
  if (h.min_tsdr != 0) reply.new_min_tsdr = h.min_tsdr;
  set_state(SlaveState::WaitCfg);
}

// --- Chk_Cfg (§D.3) -----------------------------------------------------------------------------

void SlaveEngine::handle_chk_cfg(const Indication& ind, Reply& reply) {
  if (m_state != SlaveState::WaitCfg && m_state != SlaveState::DataExch) return;  // RS
  reply.short_ack();
  if (ind.sa != m_master) return;  // locked by another master

  std::vector<CfgIdentifier> ids;  // not on the cyclic path
  const CfgError e = parse_cfg(ind.data, ids, true);
  m_cfg_fault_modules.clear();
  m_cfg_fault_span = m_layout.modules.size();
  bool ok = e == CfgError::None;
  if (ok && m_dpv1.check_cfg_mode() && m_cfg.features.check_cfg_mode && m_cfg.check_cfg_user) {
    ok = m_cfg.check_cfg_user(ind.data);
  } else if (ok) {
    const auto& real = m_layout.identifiers;
    const std::size_t n = std::max(ids.size(), real.size());
    for (std::size_t j = 0; j < n; ++j) {
      if (j < ids.size() && j < real.size() && cfg_matches(ids[j], real[j])) continue;
      ok = false;
      const std::size_t mod = j < real.size() ? m_layout.module_of_id[j]
                                              : m_layout.modules.size() + (j - real.size());
      if (m_cfg_fault_modules.empty() || m_cfg_fault_modules.back() != mod)
        m_cfg_fault_modules.push_back(static_cast<std::uint16_t>(mod));
      m_cfg_fault_span = std::max(m_cfg_fault_span, mod + 1);
    }
  }
  if (!ok && mutated(EngineMutation::AcceptWrongCfg)) {  // mutant: any Chk_Cfg will do
    ok = true;
    m_cfg_fault_modules.clear();
  }
  if (!ok) {
    ++m_stats.cfg_faults;
    go_wait_prm();
    m_cfg_fault = true;
    return;
  }
  m_cfg_fault = false;
  if (m_state == SlaveState::WaitCfg) enter_data_exchange();
}

// --- Slave_Diag (§D.4, §D.5) ----------------------------------------------------------------------

void SlaveEngine::build_diag() {
  StandardDiag sd;
  sd.ident = mutated(EngineMutation::WrongDiagIdent) ? static_cast<std::uint16_t>(m_cfg.ident + 1)
                                                    : m_cfg.ident;
  sd.master_add = m_master;
  if (m_state != SlaveState::DataExch) sd.status_1 |= kDiagStationNotReady;
  if (m_cfg_fault) sd.status_1 |= kDiagCfgFault;
  if (m_not_supported) sd.status_1 |= kDiagNotSupported;
  if (m_prm_fault) sd.status_1 |= kDiagPrmFault;
  if ((m_state == SlaveState::PowerOn || m_state == SlaveState::WaitPrm) &&
      !mutated(EngineMutation::NoPrmReqBit))
    sd.status_2 |= kDiagPrmReq;
  if (m_wd_on) sd.status_2 |= kDiagWdOn;
  if (m_freeze_mode) sd.status_2 |= kDiagFreezeMode;
  if (m_sync_mode) sd.status_2 |= kDiagSyncMode;

  m_diag.reset();
  std::lock_guard lk(m_app.m_mu);
  if (m_app.m_stat_diag) sd.status_2 |= kDiagStatDiag;
  m_scratch_ids.assign(m_cfg_fault_modules.begin(), m_cfg_fault_modules.end());
  bool module_fault = false;
  for (std::size_t m = 0; m < m_app.m_module_states.size(); ++m) {
    if (m_app.m_module_states[m] == ModuleState::Ok) continue;
    module_fault = true;
    if (std::find(m_scratch_ids.begin(), m_scratch_ids.end(), m) == m_scratch_ids.end())
      m_scratch_ids.push_back(static_cast<std::uint16_t>(m));
  }
  const bool dpv1 = m_dpv1.dpv1_enable();
  if (!m_scratch_ids.empty())
    m_diag.add_identifier_block(m_scratch_ids, std::max(m_cfg_fault_span, m_layout.modules.size()));
  if (dpv1 && module_fault) m_diag.add_module_status(m_app.m_module_states);
  for (const auto& st : m_app.m_status)
    m_diag.add_status(st.type, st.slot, st.specifier, {st.data.data(), st.len});
  for (const auto& c : m_app.m_channels) m_diag.add_channel(c);
  m_diag.add_device_block(m_app.m_device_diag);
  if (dpv1)
    for (const auto& a : m_app.m_alarms)
      m_diag.add_alarm(a.type, a.slot, a.specifier, {a.data.data(), a.len});
  if (m_app.m_ext_diag || !m_scratch_ids.empty() || !m_app.m_channels.empty())
    sd.status_1 |= kDiagExtDiag;
  if (m_diag.overflow()) sd.status_3 |= kDiagExtDiagOverflow;
  m_diag.set_standard(sd);
}

std::span<const std::uint8_t> SlaveEngine::current_diag() {
  build_diag();
  return m_diag.bytes();
}

void SlaveEngine::handle_slave_diag(const Indication& ind, Reply& reply) {
  const std::uint32_t gen = m_app.m_diag_gen.load(std::memory_order_acquire);
  build_diag();
  reply.respond(ResponseStatus::DL, m_diag.bytes());
  if (ind.sa == m_master) {
    m_diag_pending = false;
    m_seen_diag_gen = gen;
  }
}

// --- Data_Exchange (§D.7) -------------------------------------------------------------------------

void SlaveEngine::handle_data_exchange(const Indication& ind, Reply& reply) {
  const bool early = m_state == SlaveState::WaitCfg && ind.sa == m_master &&
                     mutated(EngineMutation::DataExchangeInWaitCfg);  // mutant: no Chk_Cfg needed
  if ((m_state != SlaveState::DataExch && !early) || ind.sa != m_master) return;  // RS
  const std::size_t n_out = m_layout.outputs;
  if (ind.data.size() == n_out) {
    std::copy(ind.data.begin(), ind.data.end(), m_rx_outputs.begin());
    std::copy(ind.data.begin(), ind.data.end(), m_last_rx.begin());
    m_fail_safe_zero = false;
    if ((!m_sync_mode || mutated(EngineMutation::IgnoreSync)) && !m_clear) apply_outputs();
  } else if (ind.data.empty() && m_cfg.features.fail_safe &&
             !mutated(EngineMutation::RejectFailSafe)) {
    // Fail_Safe: the master in Clear sends no output data at all.
    m_fail_safe_zero = true;
    if (!m_sync_mode) set_outputs_safe();
  } else {
    go_wait_prm();
    return;  // RS: the slave has left data exchange
  }
  snapshot_inputs(m_inputs);
  if (mutated(EngineMutation::TearConsistent)) [[unlikely]] tear_inputs();
  const std::uint32_t gen = m_app.m_diag_gen.load(std::memory_order_acquire);
  if (gen != m_seen_diag_gen) m_diag_pending = true;
  const ResponseStatus st = m_diag_pending ? ResponseStatus::DH : ResponseStatus::DL;
  if (m_layout.inputs == 0 && st == ResponseStatus::DL)
    reply.short_ack();
  else
    reply.respond(st, {m_inputs.data(), m_layout.inputs});
}

void SlaveEngine::tear_inputs() {
  for (const ModuleLayout& m : m_layout.modules) {
    if (!m.consistent || m.in_len < 2) continue;
    const std::size_t half = m.in_len / 2;
    for (std::size_t i = m.in_offset; i < m.in_offset + m.in_len; ++i) {
      const std::uint8_t now = m_inputs[i];
      if (i < m.in_offset + half) m_inputs[i] = m_tear_prev[i];
      m_tear_prev[i] = now;
    }
  }
}

void SlaveEngine::handle_rd_inp(Reply& reply) {
  if (m_state != SlaveState::DataExch) return;  // RS
  std::array<std::uint8_t, kMaxIoLen> buf{};
  snapshot_inputs(buf);
  if (m_layout.inputs == 0) reply.short_ack();
  else reply.respond(ResponseStatus::DL, {buf.data(), m_layout.inputs});
}

void SlaveEngine::handle_rd_outp(Reply& reply) {
  if (m_state != SlaveState::DataExch) return;  // RS
  if (m_layout.outputs == 0) reply.short_ack();
  else reply.respond(ResponseStatus::DL, {m_rx_outputs.data(), m_layout.outputs});
}

// --- Global_Control (§D.6) -------------------------------------------------------------------------

void SlaveEngine::handle_global_control(const Indication& ind, Reply& reply) {
  if (m_state != SlaveState::DataExch || ind.sa != m_master || ind.data.size() != 2) return;  // RS
  reply.short_ack();
  const std::uint8_t cmd = ind.data[0];
  const std::uint8_t groups = ind.data[1];
  if (groups != 0 && (groups & m_group) == 0) return;  // not for our groups

  const bool clear = (cmd & 0x02) != 0 && !mutated(EngineMutation::IgnoreClearData);
  if (clear && !m_clear) set_outputs_safe();
  m_clear = clear;

  if (m_sync_enabled) {
    if (cmd & 0x10) {  // Unsync wins over Sync in the same telegram
      m_sync_mode = false;
      if (!m_clear && !m_fail_safe_zero) apply_outputs();
    } else if (cmd & 0x20) {
      m_sync_mode = true;
      if (!m_clear && !m_fail_safe_zero) apply_outputs();  // latch the latest outputs
    }
  }
  if (m_freeze_enabled) {
    if (cmd & 0x04) {  // Unfreeze wins over Freeze
      m_freeze_mode = false;
    } else if (cmd & 0x08) {
      m_app.m_image.read_all_inputs({m_frozen.data(), m_layout.inputs});
      m_freeze_mode = true;
    }
  }
}

// --- Set_Slave_Add (§D.7) ---------------------------------------------------------------------------

void SlaveEngine::handle_set_slave_add(const Indication& ind, Reply& reply) {
  if (!m_cfg.features.set_slave_add || m_no_add_chg) return;  // RS
  if (m_state != SlaveState::PowerOn && m_state != SlaveState::WaitPrm) return;
  if (ind.data.size() < 4) return;
  const std::uint8_t new_add = ind.data[0];
  const auto ident = static_cast<std::uint16_t>((ind.data[1] << 8) | ind.data[2]);
  if (ident != m_cfg.ident || new_add > kMaxSlaveAddress) return;
  reply.short_ack();
  reply.new_address = new_add;
  m_no_add_chg = ind.data[3] != 0;
  set_state(SlaveState::WaitPrm);
}

// --- MSAC_C1 (§E.2–§E.5) ----------------------------------------------------------------------------

void SlaveEngine::record_request(std::span<const std::uint8_t> pdu, std::uint8_t master, bool c2,
                                 PendingRecord& pending, Reply& reply) {
  pending = PendingRecord{};
  const std::uint8_t fn = pdu[0];
  auto negative = [&](std::uint8_t code_1) {
    const auto r = negative_response(fn, {kErrorDecodeDpv1, code_1, 0});
    reply.respond(ResponseStatus::DL, r);
  };
  if (fn != kFnRead && fn != kFnWrite) return negative(dpv1_err::kFeatureNotSupported);
  RecordRequest rq;
  const RecordParse p = parse_record_request(pdu, rq);
  if (p == RecordParse::TooShort) return negative(dpv1_err::kInvalidParameter);
  if (p == RecordParse::BadLength)
    return negative(fn == kFnWrite ? dpv1_err::kWriteLengthError : dpv1_err::kInvalidParameter);

  RecordCall call{m_next_record_id++, rq.slot, rq.index, master, c2};
  RecordReadHandler rh;
  RecordWriteHandler wh;
  {
    std::lock_guard lk(m_app.m_mu);
    if (fn == kFnRead) {
      const auto it = m_app.m_read_handlers.find(record_key(rq.slot, rq.index));
      if (it != m_app.m_read_handlers.end()) rh = it->second;
    } else {
      const auto it = m_app.m_write_handlers.find(record_key(rq.slot, rq.index));
      if (it != m_app.m_write_handlers.end()) wh = it->second;
      else wh = m_app.m_write_any;  // empty unless the device set one
    }
  }
  if (!rh && !wh && fn == kFnRead && rq.slot <= m_layout.modules.size() &&
      mutated(EngineMutation::Dpv1BadIndexAccepted)) {
    // Mutant: an unknown index reads as zeros instead of "invalid index".
    std::array<std::uint8_t, 4 + kMaxRecordData> out{};
    out[0] = fn;
    out[1] = rq.slot;
    out[2] = rq.index;
    out[3] = rq.length;
    reply.respond(ResponseStatus::DL, {out.data(), 4u + rq.length});
    return;
  }
  if (!rh && !wh)
    return negative(rq.slot > m_layout.modules.size() ? dpv1_err::kInvalidSlot
                                                      : dpv1_err::kInvalidIndex);
  const RecordResult r = rh ? rh(call, {m_record_buf.data(), rq.length}) : wh(call, rq.data);
  if (r.kind == RecordResult::Kind::Pending) {
    pending = {true, call.id, fn, rq.slot, rq.index, rq.length};
    reply.short_ack();
    return;
  }
  if (r.kind == RecordResult::Kind::Error) {
    reply.respond(ResponseStatus::DL, negative_response(fn, r.error));
    return;
  }
  std::array<std::uint8_t, 4 + kMaxRecordData> out{};
  out[0] = fn;
  out[1] = rq.slot;
  out[2] = rq.index;
  if (fn == kFnRead) {
    const std::size_t n = std::min<std::size_t>(r.length, rq.length);
    out[3] = static_cast<std::uint8_t>(n);
    std::copy_n(m_record_buf.begin(), n, out.begin() + 4);
    reply.respond(ResponseStatus::DL, {out.data(), 4 + n});
  } else {
    out[3] = rq.length;
    reply.respond(ResponseStatus::DL, {out.data(), 4});
  }
}

void SlaveEngine::record_poll(PendingRecord& pending, Reply& reply) {
  reply.short_ack();
  if (!pending.active) return;
  SlaveApplication::Completion c;
  {
    std::lock_guard lk(m_app.m_mu);
    const auto it = m_app.m_completions.find(pending.id);
    if (it == m_app.m_completions.end()) return;  // not ready yet: SC again
    c = std::move(it->second);
    m_app.m_completions.erase(it);
  }
  const PendingRecord p = pending;
  pending = PendingRecord{};
  if (c.error) {
    reply.respond(ResponseStatus::DL, negative_response(p.fn, c.err));
    return;
  }
  std::array<std::uint8_t, 4 + kMaxRecordData> out{p.fn, p.slot, p.index, p.length};
  std::size_t len = 4;
  if (p.fn == kFnRead) {
    const std::size_t n = std::min<std::size_t>(c.data.size(), p.length);
    out[3] = static_cast<std::uint8_t>(n);
    std::copy_n(c.data.begin(), n, out.begin() + 4);
    len += n;
  }
  reply.respond(ResponseStatus::DL, {out.data(), len});
}

void SlaveEngine::handle_c1_read_write(const Indication& ind, Reply& reply) {
  if (!m_cfg.features.dpv1 || !m_cfg.features.c1_read_write || !m_dpv1.dpv1_enable() ||
      m_state != SlaveState::DataExch || ind.sa != m_master)
    return;  // RS
  if (ind.data.empty()) return record_poll(m_c1, reply);
  record_request(ind.data, ind.sa, false, m_c1, reply);
}

void SlaveEngine::handle_c1_alarm(const Indication& ind, Reply& reply) {
  if (!m_cfg.features.dpv1 || !m_dpv1.dpv1_enable() || m_state != SlaveState::DataExch ||
      ind.sa != m_master)
    return;  // RS
  AlarmAck ack;
  if (!parse_alarm_ack(ind.data, ack)) {
    const std::uint8_t fn = ind.data.empty() ? kFnAlarmAck : ind.data[0];
    reply.respond(ResponseStatus::DL,
                  negative_response(fn, {kErrorDecodeDpv1, fn == kFnAlarmAck
                                                               ? dpv1_err::kInvalidParameter
                                                               : dpv1_err::kFeatureNotSupported,
                                         0}));
    return;
  }
  std::function<void(std::uint8_t, std::uint8_t, std::uint8_t)> cb;
  bool found = false;
  {
    std::lock_guard lk(m_app.m_mu);
    auto& al = m_app.m_alarms;
    const auto it = std::find_if(al.begin(), al.end(), [&](const SlaveApplication::Alarm& a) {
      return a.slot == ack.slot && a.type == ack.type &&
             alarm_seq_nr(a.specifier) == alarm_seq_nr(ack.specifier);
    });
    if (it != al.end()) {
      al.erase(it);
      found = true;
      cb = m_app.m_alarm_ack_cb;
    }
  }
  if (!found) {
    reply.respond(ResponseStatus::DL,
                  negative_response(kFnAlarmAck, {kErrorDecodeDpv1, dpv1_err::kStateConflict, 0}));
    return;
  }
  reply.respond(ResponseStatus::DL, ind.data);
  if (cb) cb(ack.type, ack.slot, alarm_seq_nr(ack.specifier));
}

// --- MSAC_C2 (§E.6) -----------------------------------------------------------------------------------

void SlaveEngine::handle_c2_rm(const Indication& ind, Reply& reply) {
  if (m_c2.empty()) return;  // RS
  InitiateRequest rq;
  if (!parse_initiate(ind.data, rq)) {
    reply.respond(ResponseStatus::DL,
                  negative_response(kFnInitiate, {kErrorDecodeDpv1, dpv1_err::kInvalidParameter, 0}));
    return;
  }
  if (rq.send_timeout == 0) {
    reply.respond(ResponseStatus::DL,
                  negative_response(kFnInitiate, {kErrorDecodeDpv1, dpv1_err::kInvalidRange, 0}));
    return;
  }
  C2Connection* free_conn = nullptr;
  std::size_t idx = 0;
  for (std::size_t i = 0; i < m_c2.size(); ++i) {
    if (m_c2[i].st == C2Connection::St::Closed) {
      free_conn = &m_c2[i];
      idx = i;
      break;
    }
  }
  if (!free_conn) {
    reply.respond(ResponseStatus::DL,
                  negative_response(kFnInitiate,
                                    {kErrorDecodeDpv1, dpv1_err::kResourceUnavailable, 0}));
    return;
  }
  free_conn->st = C2Connection::St::Reserved;
  free_conn->master = ind.sa;
  free_conn->timeout = 2 * static_cast<bus::Ticks>(rq.send_timeout) * 10 * bus::kTicksPerMs;
  free_conn->deadline = ind.now + free_conn->timeout;
  free_conn->pending = PendingRecord{};
  const std::uint8_t sap = static_cast<std::uint8_t>(kSapC2ConnectionHigh - idx);
  const std::array<std::uint8_t, 4> res{kFnResourceManager, sap,
                                        static_cast<std::uint8_t>(rq.send_timeout >> 8),
                                        static_cast<std::uint8_t>(rq.send_timeout & 0xFF)};
  reply.respond(ResponseStatus::DL, res);
}

void SlaveEngine::handle_c2_conn(C2Connection& c, const Indication& ind, Reply& reply) {
  c.deadline = ind.now + c.timeout;
  if (c.st == C2Connection::St::Reserved) {
    InitiateRequest rq;
    if (!parse_initiate(ind.data, rq)) {
      reply.respond(ResponseStatus::DL,
                    negative_response(kFnInitiate, {kErrorDecodeDpv1, dpv1_err::kInvalidParameter, 0}));
      return;
    }
    if (rq.send_timeout != 0)
      c.timeout = 2 * static_cast<bus::Ticks>(rq.send_timeout) * 10 * bus::kTicksPerMs;
    c.deadline = ind.now + c.timeout;
    std::array<std::uint8_t, 244> res{};
    std::size_t n = 0;
    res[n++] = kFnInitiate;
    res[n++] = static_cast<std::uint8_t>(kMaxRecordData);
    res[n++] = 0x01;  // Features_Supported_1: Read/Write
    res[n++] = 0x00;
    res[n++] = rq.profile_features_1;
    res[n++] = rq.profile_features_2;
    res[n++] = static_cast<std::uint8_t>(rq.profile_ident >> 8);
    res[n++] = static_cast<std::uint8_t>(rq.profile_ident & 0xFF);
    res[n++] = rq.d_type;
    res[n++] = static_cast<std::uint8_t>(rq.d_addr.size());
    res[n++] = rq.s_type;
    res[n++] = static_cast<std::uint8_t>(rq.s_addr.size());
    for (auto b : rq.d_addr) res[n++] = b;
    for (auto b : rq.s_addr) res[n++] = b;
    c.st = C2Connection::St::Open;
    reply.respond(ResponseStatus::DL, {res.data(), n});
    return;
  }
  if (ind.data.empty() || ind.data[0] == kFnIdle) return record_poll(c.pending, reply);
  const std::uint8_t fn = ind.data[0];
  switch (fn) {
    case kFnAbort:
      c = C2Connection{};
      reply.short_ack();
      return;
    case kFnRead:
    case kFnWrite: record_request(ind.data, ind.sa, true, c.pending, reply); return;
    case kFnInitiate:
      reply.respond(ResponseStatus::DL,
                    negative_response(fn, {kErrorDecodeDpv1, dpv1_err::kStateConflict, 0}));
      return;
    default:
      reply.respond(ResponseStatus::DL,
                    negative_response(fn, {kErrorDecodeDpv1, dpv1_err::kFeatureNotSupported, 0}));
      return;
  }
}

}  // namespace pbvbus::dp
