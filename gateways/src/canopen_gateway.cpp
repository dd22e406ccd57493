#include "pbvbus/gateways/canopen_gateway.hpp"

#include <algorithm>
#include <cstring>

#include "pbvbus/gateways/canopen_sdo.hpp"

namespace pbvbus::gateways {

CanopenGateway::CanopenGateway(bus::Scheduler& sched, ProcessSource& source, CanHub& hub,
                               CanopenOptions options)
    : m_sched(sched), m_source(source), m_hub(hub), m_opt(std::move(options)) {
  m_map = build_canopen_map(m_source.slaves(), m_opt);
  if (m_opt.change_period <= 0) {
    m_map.warnings.push_back("change-detection period must be positive; 1 ms is used");
    m_opt.change_period = bus::kTicksPerMs;
  }
  if (m_opt.tpdo_cycle < 0) m_opt.tpdo_cycle = 0;
  m_by_node.fill(-1);
  for (const auto& cn : m_map.nodes) {
    Node n;
    n.map = cn;
    for (const auto& s : m_source.slaves())
      if (s.address == cn.address) n.slave = &s;
    n.heartbeat_ms = m_opt.heartbeat_ms;
    m_by_node[cn.node] = static_cast<std::int16_t>(m_nodes.size());
    m_nodes.push_back(std::move(n));
  }
  m_port = m_hub.add_port("canopen gateway",
                          [this](const CanFrame& f, bus::Ticks now) { on_frame(f, now); });
}

CanopenGateway::~CanopenGateway() {
  m_hub.remove_port(m_port);
}

void CanopenGateway::start(bus::Ticks now) {
  if (m_started) return;
  m_started = true;
  m_next_change = now;
  m_next_cycle = m_opt.tpdo_cycle > 0 ? now + m_opt.tpdo_cycle : bus::kNever;
  for (auto& n : m_nodes) restart_heartbeat(n, now);
  arm();
}

std::uint8_t CanopenGateway::error_register(std::uint8_t node) const {
  const Node* n = node_by_id(node);
  return n ? error_register(*n) : 0;
}

std::uint16_t CanopenGateway::heartbeat_ms(std::uint8_t node) const {
  const Node* n = node_by_id(node);
  return n ? n->heartbeat_ms : 0;
}

// --- time -------------------------------------------------------------------------------------

void CanopenGateway::arm() {
  bus::Ticks t = std::min(m_next_change, m_next_cycle);
  for (const auto& n : m_nodes) t = std::min(t, n.next_heartbeat);
  if (t == bus::kNever || t == m_armed_at) return;
  // No cancel in the scheduler: a newer generation makes the earlier event a no-op.
  m_armed_at = t;
  m_sched.schedule(t, *this, ++m_generation);
}

void CanopenGateway::on_event(bus::Ticks now, std::uint64_t tag) {
  if (tag != m_generation) return;
  m_armed_at = bus::kNever;
  const bool change_due = now >= m_next_change;
  const bool cycle_due = now >= m_next_cycle;
  if (change_due || cycle_due)
    for (auto& n : m_nodes) check_node(n, now, cycle_due);
  while (m_next_change <= now) m_next_change += m_opt.change_period;
  while (m_next_cycle <= now) m_next_cycle += m_opt.tpdo_cycle;  // kNever never loops

  const dp::MasterMode mode = m_source.mode();
  for (auto& n : m_nodes) {
    if (n.next_heartbeat > now) continue;
    const auto state = canopen::heartbeat_state(status_of(n).state, mode);
    if (state) {
      const std::uint8_t b = *state;
      send(canopen::kCobHeartbeat + n.map.node, {&b, 1}, now);
      ++m_stats.heartbeat_sent;
    }
    const bus::Ticks period = bus::Ticks{n.heartbeat_ms} * bus::kTicksPerMs;
    while (n.next_heartbeat <= now) n.next_heartbeat += period;
  }
  arm();
}

void CanopenGateway::restart_heartbeat(Node& n, bus::Ticks now) {
  n.next_heartbeat =
      n.heartbeat_ms == 0 ? bus::kNever : now + bus::Ticks{n.heartbeat_ms} * bus::kTicksPerMs;
}

// --- producer side: EMCY, boot-up, TPDOs -------------------------------------------------------

SlaveStatus CanopenGateway::status_of(const Node& n) const {
  auto st = m_source.status(n.map.address, Side::Primary);
  if (st) return *st;
  SlaveStatus none;  // cannot happen for a configured slave; treat it as absent
  none.state = dp::SlaveStatusState::NotPresent;
  return none;
}

std::uint8_t CanopenGateway::error_register(const Node& n) const {
  std::uint8_t r = 0;
  if (n.failure_active) r |= canopen::kErrCommunication;
  if (n.ext_active) r |= canopen::kErrManufacturer;
  if (r) r |= canopen::kErrGeneric;
  return r;
}

void CanopenGateway::check_node(Node& n, bus::Ticks now, bool cyclic) {
  const SlaveStatus st = status_of(n);
  const bool dx = st.state == dp::SlaveStatusState::DataExchange;
  const dp::MasterMode mode = m_source.mode();
  const bool commanded_off = mode == dp::MasterMode::Stop || mode == dp::MasterMode::Offline;

  // Station failure: data exchange lost while the master wanted it, or lost and regained
  // between two ticks (the master counted a failure).
  bool bounced = false;
  if (n.seen && n.data_exchange) {
    bounced = dx && st.failures > n.failures;
    const bool lost = !dx && !commanded_off;
    if ((lost || bounced) && !n.failure_active) {
      n.failure_active = true;
      send_emcy(n, canopen::kEmcyHeartbeatError, error_register(n),
                {canopen::dp_state_code(st.state), 0, 0, 0, 0}, now);
    }
  }
  if (dx && (!n.seen || !n.data_exchange || bounced)) send_bootup(n, now);
  if (dx && n.failure_active) {
    n.failure_active = false;
    send_emcy(n, canopen::kEmcyErrorReset, error_register(n), {}, now);
  }

  // Extended diagnosis: appears, changes, clears.
  const bool ext = canopen::has_ext_diag(st);
  if (ext) {
    std::vector<std::uint8_t> ext_octets;
    if (st.diag.size() > dp::kStdDiagLen)
      ext_octets.assign(st.diag.begin() + static_cast<std::ptrdiff_t>(dp::kStdDiagLen),
                        st.diag.end());
    if (!n.ext_active || ext_octets != n.ext_diag) {
      n.ext_active = true;
      n.ext_diag = std::move(ext_octets);
      auto octet = [&](std::size_t i) -> std::uint8_t {
        return i < st.diag.size() ? st.diag[i] : 0;
      };
      send_emcy(n, canopen::kEmcyDeviceSpecific, error_register(n),
                {octet(0), octet(1), octet(2), octet(6), octet(7)}, now);
    }
  } else if (n.ext_active) {
    n.ext_active = false;
    n.ext_diag.clear();
    send_emcy(n, canopen::kEmcyErrorReset, error_register(n), {}, now);
  }

  n.seen = true;
  n.data_exchange = dx;
  n.failures = st.failures;

  if (dx && st.data_valid)
    send_tpdos(n, now, cyclic);
  else
    n.sent.fill(false);  // after the return the first images go out whatever they are
}

void CanopenGateway::send_tpdos(Node& n, bus::Ticks now, bool cyclic) {
  m_in_buf.assign(n.map.input_len, 0);
  if (!m_source.read_inputs(n.map.address, Side::Primary, m_in_buf)) return;
  for (std::size_t i = 0; i < n.map.tpdos; ++i) {
    const std::size_t off = i * canopen::kPdoOctets;
    const auto len =
        static_cast<std::uint8_t>(std::min(canopen::kPdoOctets, m_in_buf.size() - off));
    const std::uint8_t* p = m_in_buf.data() + off;
    const bool changed =
        !n.sent[i] || n.last_len[i] != len || std::memcmp(n.last[i].data(), p, len) != 0;
    if (!changed && !cyclic) continue;
    std::memcpy(n.last[i].data(), p, len);
    n.last_len[i] = len;
    n.sent[i] = true;
    send(canopen::kCobTpdo[i] + n.map.node, {p, len}, now);
    ++m_stats.tpdo_sent;
  }
}

void CanopenGateway::send_emcy(const Node& n, std::uint16_t code, std::uint8_t reg,
                               std::array<std::uint8_t, 5> manufacturer, bus::Ticks now) {
  const std::array<std::uint8_t, 8> d{static_cast<std::uint8_t>(code & 0xFF),
                                      static_cast<std::uint8_t>(code >> 8),
                                      reg,
                                      manufacturer[0],
                                      manufacturer[1],
                                      manufacturer[2],
                                      manufacturer[3],
                                      manufacturer[4]};
  send(canopen::kCobEmcy + n.map.node, d, now);
  ++m_stats.emcy_sent;
}

void CanopenGateway::send_bootup(Node& n, bus::Ticks now) {
  const std::uint8_t b = canopen::kStateBootUp;
  send(canopen::kCobHeartbeat + n.map.node, {&b, 1}, now);
  ++m_stats.bootup_sent;
  n.sent.fill(false);  // a node that boots sends its process data afresh
}

void CanopenGateway::send(std::uint32_t id, std::span<const std::uint8_t> data, bus::Ticks now) {
  CanFrame f;
  f.id = id;
  f.dlc = static_cast<std::uint8_t>(std::min<std::size_t>(data.size(), 8));
  std::copy_n(data.begin(), f.dlc, f.data.begin());
  m_hub.send(m_port, f, now);
}

// --- consumer side: NMT, RPDO, SDO --------------------------------------------------------------

CanopenGateway::Node* CanopenGateway::node_by_id(std::uint8_t node) {
  if (node >= m_by_node.size() || m_by_node[node] < 0) return nullptr;
  return &m_nodes[static_cast<std::size_t>(m_by_node[node])];
}

const CanopenGateway::Node* CanopenGateway::node_by_id(std::uint8_t node) const {
  if (node >= m_by_node.size() || m_by_node[node] < 0) return nullptr;
  return &m_nodes[static_cast<std::size_t>(m_by_node[node])];
}

void CanopenGateway::on_frame(const CanFrame& f, bus::Ticks now) {
  // Not started: the gateway is not on the bus yet. CANopen uses 11-bit identifiers only, and
  // this server answers no remote frames.
  if (!m_started || f.extended || f.rtr || f.id > 0x7FF) {
    ++m_stats.ignored;
    return;
  }
  if (f.id == canopen::kCobNmt) {
    on_nmt(f, now);
    return;
  }
  const std::uint32_t function = f.id & 0x780;
  Node* n = node_by_id(static_cast<std::uint8_t>(f.id & 0x7F));
  if (!n) {
    ++m_stats.ignored;
    return;
  }
  switch (function) {
    case 0x200:
    case 0x300:
    case 0x400:
    case 0x500:
      on_rpdo(*n, (function - 0x200) >> 8, f);
      return;
    case canopen::kCobSdoRx:
      on_sdo(*n, f, now);
      return;
    default:
      ++m_stats.ignored;
      return;  // another producer's TPDO, heartbeat, EMCY, ...
  }
}

void CanopenGateway::on_nmt(const CanFrame& f, bus::Ticks now) {
  if (f.dlc != 2) {
    ++m_stats.bad;
    return;
  }
  const std::uint8_t cs = f.data[0];
  const std::uint8_t node = f.data[1];
  std::vector<Node*> targets;
  if (node == 0) {
    for (auto& n : m_nodes) targets.push_back(&n);
  } else if (Node* n = node_by_id(node)) {
    targets.push_back(n);
  } else {
    ++m_stats.ignored;  // another node's command
    return;
  }
  const bool known = cs == canopen::kNmtStart || cs == canopen::kNmtStop ||
                     cs == canopen::kNmtPreOperational || cs == canopen::kNmtResetNode ||
                     cs == canopen::kNmtResetCommunication;
  if (!known) {
    ++m_stats.bad;
    return;
  }
  if (!m_opt.accept_nmt) {
    ++m_stats.nmt_refused;
    return;
  }
  bool ok = true;
  switch (cs) {
    // One mode for the whole master system, whichever of its nodes was addressed.
    case canopen::kNmtStart:
      ok = m_source.command(dp::MasterMode::Operate);
      break;
    case canopen::kNmtStop:
      ok = m_source.command(dp::MasterMode::Stop);
      break;
    case canopen::kNmtPreOperational:
      ok = m_source.command(dp::MasterMode::Clear);
      break;
    default: {
      // Reset node / communication: the communication objects (0x1017) return to their
      // configured values, the node announces itself and its heartbeat starts anew. Only a
      // node that has a heartbeat now (a present slave) boots; an absent one stays silent.
      const dp::MasterMode mode = m_source.mode();
      for (Node* n : targets) {
        n->heartbeat_ms = m_opt.heartbeat_ms;
        restart_heartbeat(*n, now);
        if (canopen::heartbeat_state(status_of(*n).state, mode)) send_bootup(*n, now);
      }
      arm();
      break;
    }
  }
  if (ok)
    ++m_stats.nmt_received;
  else
    ++m_stats.nmt_refused;
}

void CanopenGateway::on_rpdo(Node& n, std::size_t pdo, const CanFrame& f) {
  const std::size_t off = pdo * canopen::kPdoOctets;
  if (!n.map.outputs_writable || off >= n.map.output_len || !n.slave) {
    ++m_stats.rpdo_refused;
    return;
  }
  const std::size_t len =
      std::min<std::size_t>({f.dlc, canopen::kPdoOctets, n.map.output_len - off});
  m_out_buf.assign(n.map.output_len, 0);
  if (!m_source.read_outputs(n.map.address, Side::Primary, m_out_buf)) {
    ++m_stats.rpdo_refused;
    return;
  }
  std::copy_n(f.data.begin(), len, m_out_buf.begin() + static_cast<std::ptrdiff_t>(off));
  bool ok = true;
  const auto& modules = n.slave->modules;
  for (std::size_t m = 0; m < modules.size() && len > 0; ++m) {
    const auto& mod = modules[m];
    if (mod.out_len == 0 || mod.out_offset >= off + len || mod.out_offset + mod.out_len <= off)
      continue;
    ok = m_source.write_module_outputs(
             n.map.address, m,
             std::span<const std::uint8_t>(m_out_buf).subspan(mod.out_offset, mod.out_len)) &&
         ok;
  }
  if (ok)
    ++m_stats.rpdo_received;
  else
    ++m_stats.rpdo_refused;
}

void CanopenGateway::on_sdo(Node& n, const CanFrame& f, bus::Ticks now) {
  ++m_stats.sdo_received;
  const canopen::SdoRequest r =
      canopen::parse_sdo_request({f.data.data(), std::min<std::size_t>(f.dlc, 8)});
  canopen::SdoFrame resp{};
  std::uint32_t abort = 0;
  switch (r.kind) {
    case canopen::SdoRequestKind::ClientAbort:
      return;
    case canopen::SdoRequestKind::Invalid:
      abort = r.abort;
      break;
    case canopen::SdoRequestKind::Upload:
    case canopen::SdoRequestKind::Download: {
      canopen::NodeObjects obj{n.slave, status_of(n), error_register(n), n.heartbeat_ms};
      if (r.kind == canopen::SdoRequestKind::Upload) {
        const canopen::ObjectAccess a = canopen::read_object(obj, r.index, r.sub);
        abort = a.abort;
        if (!abort) resp = canopen::sdo_upload_response(r.index, r.sub, a.value, a.size);
      } else {
        const canopen::ObjectAccess a = canopen::check_write(obj, r.index, r.sub, r.size, r.value);
        abort = a.abort;
        if (!abort) {
          // 0x1017: the new period starts now (CiA 301: the producer restarts with it).
          n.heartbeat_ms = static_cast<std::uint16_t>(a.value);
          restart_heartbeat(n, now);
          arm();
          resp = canopen::sdo_download_response(r.index, r.sub);
        }
      }
      break;
    }
  }
  if (abort) {
    resp = canopen::sdo_abort(r.index, r.sub, abort);
    ++m_stats.sdo_aborts;
  }
  send(canopen::kCobSdoTx + n.map.node, resp, now);
  ++m_stats.sdo_sent;
}

}  // namespace pbvbus::gateways
