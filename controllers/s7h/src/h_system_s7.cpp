// S7 communication in the H CPUs (the block "S7 communication" of h_system.hpp; h_s7_memory.hpp
// and h_s7_session.hpp; docs/h-system.md "S7 communication"): each CPU's memory as
// s7cpu::CpuMemory views, the sessions and their routes, the H lists over Read SZL.
#include <algorithm>
#include <stdexcept>

#include "pbvbus/s7cpu/s7_server.hpp"
#include "pbvbus/s7cpu/szl_source.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {
namespace {

/// The H lists SFC 51 answers (h_ssl.hpp), asked through Read SZL.
bool is_h_list(std::uint16_t id) {
  switch (id) {
    case kSslHState:
    case kSslHStateHeader:
    case kSslSwitchedSlave:
    case kSslAllLeds:
    case kSslOneLed:
    case kSslInterrupt:
    case kSslProtection:
      return true;
    default:
      return false;
  }
}

/// SFC 51's answer framed for Read SZL: RET_VAL 8082/8083/8085 -> the SZL statuses
/// (szl_source.hpp: D401/D402/D406); SSL_HEADER (LENTHDR, N_DR) + records -> the list.
s7cpu::SzlList to_szl(const SslResult& r) {
  s7cpu::SzlList l;
  switch (r.ret_val) {
    case 0:
      break;
    case kRetSslIdUnknown:
      l.status = s7cpu::SzlStatus::UnknownId;
      return l;
    case kRetSslIndex:
      l.status = s7cpu::SzlStatus::UnknownIndex;
      return l;
    default:  // W#16#8085 and anything else: not available now
      l.status = s7cpu::SzlStatus::NotAvailableNow;
      return l;
  }
  if (r.data.size() < 4) {
    l.status = s7cpu::SzlStatus::NotAvailableNow;
    return l;
  }
  l.record_length = static_cast<std::uint16_t>((r.data[0] << 8) | r.data[1]);
  l.record_count = static_cast<std::uint16_t>((r.data[2] << 8) | r.data[3]);
  l.records.assign(r.data.begin() + 4, r.data.end());
  return l;
}

}  // namespace

/// The H lists of the answering CPU (set before every request).
class HSzlSource final : public s7cpu::SzlSource {
 public:
  explicit HSzlSource(HSystemModel& m) : m_model(m) {}
  int rack = 0;
  std::optional<s7cpu::SzlList> read_szl(std::uint16_t id, std::uint16_t index) override {
    if (!is_h_list(id)) return std::nullopt;
    return to_szl(m_model.read_ssl_on(rack, id, index));
  }

 private:
  HSystemModel& m_model;
};

struct HSystemModel::S7SessionState {
  explicit S7SessionState(HSystemModel& m) : szl(m) {
    server = std::make_unique<s7cpu::S7Server>(view, info);
    server->set_szl_source(&szl);
  }
  S7Route route = S7Route::AdHoc;
  int rack = -1;        ///< AdHoc: the CPU; Routing: the master at the opening
  int connection = -1;  ///< Standard / FaultTolerant: index into comms().connections()
  bus::Ticks lost_at = bus::kNever;  ///< the connection's lost_at at the opening
  std::uint64_t epoch = 0;           ///< AdHoc: the pair's connection epoch at the opening
  std::size_t system = 0;            ///< Routing
  std::uint8_t station = 0;
  int active_line = -1;
  S7Endpoint device;
  S7CloseReason reason = S7CloseReason::None;
  std::string text;
  s7cpu::CpuMemory view;
  s7cpu::CpuMemory mirror;
  s7cpu::CpuInfo info;
  HSzlSource szl;
  std::unique_ptr<s7cpu::S7Server> server;
};

void HSystemModel::S7SessionDeleter::operator()(S7SessionState* s) const { delete s; }

HSystemModel::~HSystemModel() = default;

// ---- memory ----------------------------------------------------------------------------------

void HSystemModel::set_s7_memory(HS7MemoryConfig c) {
  const auto errors = validate(c);
  if (!errors.empty()) throw std::invalid_argument("s7 memory: " + errors.front());
  if (m_scans > 0)
    throw std::invalid_argument("s7 memory: the memory is fixed once an OB 1 ran");
  m_s7_cfg = std::move(c);
  if (m_s7_spec) {
    // Rebuild the execution with the new memory area (no scan ran: no state is lost).
    const ProgramSpec spec = *m_s7_spec;
    set_program(spec);
  } else {
    m_s7_layout = layout(m_s7_cfg, 0);
  }
  s7_prepare();
}

std::string HSystemModel::s7_order_number() const {
  if (!m_s7_cfg.order_number.empty()) return m_s7_cfg.order_number;
  // CPU 417-5H PN/DP and CPU 1515R-2 PN (docs/h-system.md "S7 communication").
  return m_pair.params().profile == HProfile::S7_1500RH ? "6ES7 515-2RM00-0AB0"
                                                        : "6ES7 417-5HT06-0AB0";
}

void HSystemModel::s7_prepare() {
  for (int r = 0; r < 2; ++r) {
    const auto i = static_cast<std::size_t>(r);
    if (!m_exec && m_s7_work[i].size() != m_s7_layout.total)
      m_s7_work[i].assign(m_s7_layout.total, 0);
    if (m_s7_counters[i].size() != m_s7_cfg.counters) m_s7_counters[i].assign(m_s7_cfg.counters, 0);
    if (m_s7_timers[i].size() != m_s7_cfg.timers) m_s7_timers[i].assign(m_s7_cfg.timers, 0);
  }
}

void HSystemModel::s7_bind(s7cpu::CpuMemory& mem, int r) {
  s7_prepare();
  const auto i = static_cast<std::size_t>(r);
  std::span<std::uint8_t> pii, piq, work;
  if (m_exec) {
    ProcessImage& img = m_exec->image(r);
    pii = img.pii();
    piq = img.piq();
    work = img.memory();
  } else {
    // One program (a hook) on one pair of images: both CPUs see the model's PII/PIQ.
    pii = m_pii;
    piq = m_piq;
    work = m_s7_work[i];
  }
  mem.bind(s7cpu::Area::Inputs, pii);
  mem.bind(s7cpu::Area::Outputs, piq);
  mem.bind(s7cpu::Area::Flags, work.first(std::min(m_s7_layout.flags, work.size())));
  mem.clear_dbs();
  for (const auto& d : m_s7_layout.dbs)
    if (d.offset + d.size <= work.size()) mem.bind_db(d.number, work.subspan(d.offset, d.size));
  mem.bind_counters(m_s7_counters[i]);
  mem.bind_timers(m_s7_timers[i]);
}

s7cpu::CpuMemory& HSystemModel::s7_cpu_memory(int rack) {
  if (!valid_rack(rack)) throw std::out_of_range("rack " + std::to_string(rack) + " (0 or 1)");
  s7cpu::CpuMemory& m = m_s7_views[static_cast<std::size_t>(rack)];
  s7_bind(m, rack);
  return m;
}

bool HSystemModel::s7_mirror_live() const {
  // The standby's memory is a live copy of the master's: Redundant with both CPUs running the
  // program, or an update after its copy at t4 (a write before t4 reaches the standby through
  // that copy).
  if (m_pair.master_count() != 1) return false;
  if (m_pair.system_mode() == SystemMode::Redundant && m_pair.state(0) == CpuState::Run &&
      m_pair.state(1) == CpuState::Run)
    return true;
  return m_pair.interrupts_held() && m_update_copied;
}

void HSystemModel::s7_copy_update(int from, int to) {
  s7_prepare();
  const auto f = static_cast<std::size_t>(from), t = static_cast<std::size_t>(to);
  m_s7_counters[t] = m_s7_counters[f];
  m_s7_timers[t] = m_s7_timers[f];
  if (!m_exec) m_s7_work[t] = m_s7_work[f];
}

// ---- sessions --------------------------------------------------------------------------------

HSystemModel::S7SessionState* HSystemModel::s7_find(std::uint32_t id) const {
  for (const auto& [k, s] : m_s7_sessions)
    if (k == id) return s.get();
  return nullptr;
}

HS7Session HSystemModel::s7_open(S7SessionPtr s) {
  const std::uint32_t id = m_s7_next++;
  s->info.order_number = s7_order_number();
  const bool r1500 = m_pair.params().profile == HProfile::S7_1500RH;
  s->info.plc_name = r1500 ? "S7-1500R/H station" : "S7-400H station";
  s->info.module_name = r1500 ? "CPU 1515R-2 PN" : "CPU 417-5H PN/DP";
  s->info.module_type_name = s->info.module_name;
  m_s7_sessions.emplace_back(id, std::move(s));
  return HS7Session(this, id);
}

void HSystemModel::s7_finish(S7SessionState& s, S7CloseReason why, std::string text) {
  if (s.reason != S7CloseReason::None) return;
  // An ad-hoc connection the pair still counts gives its resource back.
  if (s.route == S7Route::AdHoc && m_pair.connection_epoch(s.rack) == s.epoch)
    m_pair.disconnect(s.rack);
  s.reason = why;
  s.text = std::move(text);
}

void HSystemModel::s7_release(std::uint32_t id) {
  const auto it = std::find_if(m_s7_sessions.begin(), m_s7_sessions.end(),
                               [id](const auto& p) { return p.first == id; });
  if (it == m_s7_sessions.end()) return;
  s7_finish(*it->second, S7CloseReason::Closed, "closed");
  m_s7_sessions.erase(it);
}

std::size_t HSystemModel::s7_sessions_alive() const {
  return static_cast<std::size_t>(
      std::count_if(m_s7_sessions.begin(), m_s7_sessions.end(),
                    [](const auto& p) { return p.second->reason == S7CloseReason::None; }));
}

HS7Session HSystemModel::open_s7_adhoc(int rack) {
  S7SessionPtr s(new S7SessionState(*this));
  s->route = S7Route::AdHoc;
  s->rack = rack;
  if (!valid_rack(rack)) {
    s->reason = S7CloseReason::Refused;
    s->text = "no CPU in rack " + std::to_string(rack);
    return s7_open(std::move(s));
  }
  const bool ok = m_pair.connect(rack, m_sched.now());
  after_op();  // connect() ran the pair's deadlines due now
  if (!ok) {
    s->reason = S7CloseReason::Refused;
    const CpuState st = m_pair.state(rack);
    if (st == CpuState::Off || st == CpuState::ErrorSearch || st == CpuState::Defective)
      s->text = "CPU " + std::to_string(rack) + " is " + std::string(to_string(st));
    else if (m_pair.accepts_connections(rack))
      s->text = "all " + std::to_string(m_pair.params().max_connections) +
                " connection resources of CPU " + std::to_string(rack) + " are in use";
    else
      s->text = "no new connections from the start of a link-up to the end of the update (R8)";
    return s7_open(std::move(s));
  }
  s->epoch = m_pair.connection_epoch(rack);
  return s7_open(std::move(s));
}

HS7Session HSystemModel::open_s7_connection(std::string_view name) {
  S7SessionPtr s(new S7SessionState(*this));
  const int i = m_comms.find(name);
  s->connection = i;
  if (i < 0) {
    s->reason = S7CloseReason::Refused;
    s->text = "no configured connection named '" + std::string(name) + "'";
    return s7_open(std::move(s));
  }
  const Connection& c = m_comms.connections()[static_cast<std::size_t>(i)];
  s->route = c.config.kind == ConnectionKind::Standard ? S7Route::Standard
                                                        : S7Route::FaultTolerant;
  s->lost_at = c.lost_at;
  if (c.state != ConnectionState::Established) {
    s->reason = S7CloseReason::Refused;
    s->text = "connection '" + c.config.name + "' is " + std::string(to_string(c.state));
  }
  for (const auto& [k, o] : m_s7_sessions)
    if (o->connection == i && o->reason == S7CloseReason::None &&
        s->reason == S7CloseReason::None) {
      s->reason = S7CloseReason::Refused;
      s->text = "connection '" + c.config.name + "' is in use by another session";
    }
  return s7_open(std::move(s));
}

HS7Session HSystemModel::open_s7_routing(std::size_t system, std::uint8_t station,
                                         S7Endpoint device) {
  S7SessionPtr s(new S7SessionState(*this));
  s->route = S7Route::Routing;
  s->system = system;
  s->station = station;
  s->device = std::move(device);
  const int m = m_pair.master();
  s->rack = m;
  std::string why;
  if (system >= m_systems.size()) {
    why = "no master system " + std::to_string(system);
  } else {
    const redundancy::MasterSystem& ms = m_systems[system]->system();
    const auto addrs = ms.addresses();
    if (std::find(addrs.begin(), addrs.end(), station) == addrs.end() || !ms.is_switched(station))
      why = "station " + std::to_string(station) + " is not a switched station";
    else
      s->active_line = ms.active(station);
  }
  if (why.empty() && !s->device) why = "no device endpoint";
  if (why.empty() && (m < 0 || !m_pair.accepts_connections(m)))
    why = m < 0 ? "no master CPU" : "no new connections now (R8)";
  if (why.empty() && s->active_line < 0) why = "the station has no active channel";
  if (!why.empty()) {
    s->reason = S7CloseReason::Refused;
    s->text = std::move(why);
  }
  return s7_open(std::move(s));
}

int HSystemModel::s7_answering(const S7SessionState& s) const {
  switch (s.route) {
    case S7Route::AdHoc:
      return s.rack;
    case S7Route::Standard:
      return m_comms.connections()[static_cast<std::size_t>(s.connection)].config.rack;
    case S7Route::FaultTolerant: {
      // The H system answers: the master (in Redundant both hold the same data).
      if (m_pair.master() >= 0) return m_pair.master();
      const Connection& c = m_comms.connections()[static_cast<std::size_t>(s.connection)];
      return c.active >= 0 ? c.paths[static_cast<std::size_t>(c.active)].rack : -1;
    }
    case S7Route::Routing:
      break;
  }
  return -1;
}

void HSystemModel::s7_check(S7SessionState& s) {
  if (s.reason != S7CloseReason::None) return;
  switch (s.route) {
    case S7Route::AdHoc: {
      if (m_pair.connection_epoch(s.rack) == s.epoch) return;
      const CpuState st = m_pair.state(s.rack);
      if (st == CpuState::Off || st == CpuState::ErrorSearch || st == CpuState::Defective ||
          st == CpuState::Stop)
        s7_finish(s, S7CloseReason::CpuLost, "CPU " + std::to_string(s.rack) + " lost");
      else
        s7_finish(s, S7CloseReason::LinkUp,
                  "link-up breaks the standby's connections (R8), CPU " +
                      std::to_string(s.rack));
      return;
    }
    case S7Route::Standard:
    case S7Route::FaultTolerant: {
      const Connection& c = m_comms.connections()[static_cast<std::size_t>(s.connection)];
      if (c.state == ConnectionState::Established && c.lost_at == s.lost_at) return;
      s7_finish(s, S7CloseReason::ConnectionLost, "connection '" + c.config.name + "' lost");
      return;
    }
    case S7Route::Routing: {
      const int m = m_pair.master();
      const redundancy::MasterSystem& ms = m_systems[s.system]->system();
      if (m != s.rack)
        s7_finish(s, S7CloseReason::Switchover, "master switchover: routing connection cleared");
      else if (ms.active(s.station) != s.active_line)
        s7_finish(s, S7CloseReason::Switchover,
                  "the IM switched its active channel: routing connection cleared");
      return;
    }
  }
}

void HSystemModel::s7_update(bus::Ticks) {
  for (auto& [id, s] : m_s7_sessions) s7_check(*s);
}

std::vector<std::uint8_t> HSystemModel::s7_handle(std::uint32_t id,
                                                  std::span<const std::uint8_t> pdu) {
  S7SessionState* s = s7_find(id);
  if (s == nullptr) return {};
  s7_check(*s);
  if (s->reason != S7CloseReason::None) return {};
  if (s7_hold(id, pdu)) return {};  // stored during the update (h_system_sfc90.cpp)
  if (s->route == S7Route::Routing) return s->device(pdu);
  const int r = s7_answering(*s);
  if (r < 0) {
    s7_finish(*s, S7CloseReason::ConnectionLost, "no CPU answers");
    return {};
  }
  s7_bind(s->view, r);
  s->info.state = static_cast<std::uint8_t>(bz_cpu(m_pair, r) & 0xFF);
  s->szl.rack = r;
  if (s7_mirror_live()) {
    s7_bind(s->mirror, 1 - r);
    s->server->set_mirror(&s->mirror);
  } else {
    s->server->set_mirror(nullptr);
  }
  const auto a = s->server->handle(pdu);
  if (!a.ok()) {
    s7_finish(*s, S7CloseReason::ProtocolError, "not an S7 PDU: " + std::string(s7::to_string(a.error)));
    return {};
  }
  return a.value;
}

// ---- the handle's queries (h_s7_session.hpp) --------------------------------------------------

bool HS7Session::alive() const { return close_reason() == S7CloseReason::None; }

S7CloseReason HS7Session::close_reason() const {
  if (m_model == nullptr) return S7CloseReason::Closed;
  auto* s = m_model->s7_find(m_id);
  if (s == nullptr) return S7CloseReason::Closed;
  m_model->s7_check(*s);
  return s->reason;
}

std::string HS7Session::close_text() const {
  if (m_model == nullptr) return "closed";
  auto* s = m_model->s7_find(m_id);
  if (s == nullptr) return "closed";
  m_model->s7_check(*s);
  return s->text;
}

int HS7Session::answering_rack() const {
  if (!alive()) return -1;
  return m_model->s7_answering(*m_model->s7_find(m_id));
}

S7Route HS7Session::route() const {
  auto* s = m_model != nullptr ? m_model->s7_find(m_id) : nullptr;
  return s != nullptr ? s->route : S7Route::AdHoc;
}

}  // namespace pbvbus::devices
