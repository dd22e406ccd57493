// A single S7 CPU and a PG/OP in a running scenario (s7_nodes.hpp has the decisions).
#include "pbvbus/simulation/s7_nodes.hpp"

#include <algorithm>

#include "pbvbus/s7/s7_pdu.hpp"
#include "pbvbus/s7/s7_read_var.hpp"
#include "pbvbus/s7/s7_setup.hpp"

namespace pbvbus::tools {

namespace {

s7cpu::CpuMemorySizes sizes_of(const S7CpuPlan& p) {
  s7cpu::CpuMemorySizes s;
  s.inputs = p.input_bytes;
  s.outputs = p.output_bytes;
  s.flags = p.flag_bytes;
  return s;
}

/// The PDU size a CPU offers through the S7 door: 960, as S7-400 CPUs and their CPs do (the
/// door's clients ask for 480 or 960; over MPI the station caps it at 240).
constexpr std::uint16_t kDoorPduSize = 960;

}  // namespace

S7CpuNode::S7CpuNode(bus::Scheduler& sched, const S7CpuPlan& plan, const fdl::BusParams* mpi_params)
    : m_sched(sched), m_plan(plan), m_memory(sizes_of(plan)) {
  for (const auto& db : plan.dbs) m_memory.create_db(db.number, db.size);
  if (plan.program) {
    m_program.emplace(*plan.program, plan.input_bytes, plan.output_bytes);
    // M = the program's state from MB 0, then the free flags (docs/s7cpu.md).
    m_image.emplace(plan.input_bytes, plan.output_bytes,
                    std::max<std::size_t>(plan.flag_bytes, m_program->memory_size()));
    m_memory.bind(s7cpu::Area::Inputs, m_image->pii());
    m_memory.bind(s7cpu::Area::Outputs, m_image->piq());
    m_memory.bind(s7cpu::Area::Flags, m_image->memory());
  }
  m_info.order_number = plan.order_number;
  m_info.state = plan.run ? s7cpu::cpu_state::kRun : s7cpu::cpu_state::kStop;
  if (plan.mpi_line >= 0 && mpi_params != nullptr) {
    m_factory = std::make_unique<mpi_station::S7CpuSessionFactory>(m_memory, m_info);
    mpi_station::MpiStationConfig c;
    c.address = plan.mpi_address;
    c.bus = *mpi_params;
    c.pool.max_connections = plan.max_connections;
    m_mpi = std::make_unique<mpi_station::MpiStation>(c, m_factory.get());
  }
}

void S7CpuNode::start(bus::Ticks now) {
  if (m_program && m_info.state == s7cpu::cpu_state::kRun) m_sched.schedule(now, *this, 0);
}

void S7CpuNode::on_event(bus::Ticks now, std::uint64_t) {
  if (!m_program || m_info.state != s7cpu::cpu_state::kRun) return;
  m_program_events.clear();
  m_program->scan(*m_image, now, m_program_events);
  run_dp_sfcs(now);  // SFC 11/12 after the networks and SFC 14/15 (s7_dp_sfc.cpp)
  ++m_scans;
  m_sched.schedule(now + m_program->scan_time(), *this, 0);
}

std::unique_ptr<s7cpu::S7Server> S7CpuNode::open_server() {
  return std::make_unique<s7cpu::S7Server>(m_memory, m_info,
                                           s7::SetupCommunication{1, 1, kDoorPduSize});
}

void S7CpuNode::map(dp::Master& master) {
  std::vector<Slot> slots;
  auto addrs = master.addresses();
  std::sort(addrs.begin(), addrs.end());
  for (std::uint8_t a : addrs) {
    const dp::MasterImage& img = master.image(a);
    for (std::size_t m = 0; m < img.modules(); ++m) {
      Slot s;
      s.slave = a;
      s.module = m;
      s.in_len = static_cast<std::uint32_t>(img.module(m).in_len);
      s.out_len = static_cast<std::uint32_t>(img.module(m).out_len);
      s.in_at = m_next_in;
      s.out_at = m_next_out;
      m_next_in += s.in_len;
      m_next_out += s.out_len;
      if (s.in_at + s.in_len > m_plan.input_bytes) m_unmapped += s.in_len, s.in_len = 0;
      if (s.out_at + s.out_len > m_plan.output_bytes) m_unmapped += s.out_len, s.out_len = 0;
      slots.push_back(s);
    }
  }
  m_maps.emplace_back(&master, std::move(slots));
}

void S7CpuNode::exchange(dp::Master& master) {
  auto it = std::find_if(m_maps.begin(), m_maps.end(), [&](const auto& e) { return e.first == &master; });
  if (it == m_maps.end()) {
    map(master);
    it = m_maps.end() - 1;
  }
  ++m_exchanges;
  const auto in = m_memory.area(s7cpu::Area::Inputs);
  const auto out = m_memory.area(s7cpu::Area::Outputs);
  const bool run = m_info.state == s7cpu::cpu_state::kRun;
  for (const Slot& s : it->second) {
    dp::MasterImage& img = master.image(s.slave);
    const std::size_t mod_in = img.module(s.module).in_len;
    if (s.in_len != 0 && mod_in != 0) {
      m_buf.resize(mod_in);
      if (img.read_inputs(s.module, m_buf) == dp::ImageAccess::Ok)
        std::copy(m_buf.begin(), m_buf.end(), in.begin() + s.in_at);
    }
    if (img.module(s.module).out_len != 0) {
      m_buf.assign(img.module(s.module).out_len, 0);
      if (run && s.out_len != 0)
        std::copy_n(out.begin() + s.out_at, s.out_len, m_buf.begin());
      img.write_outputs(s.module, m_buf);
    }
  }
}

// --- HCpuMpiNode ---------------------------------------------------------------------------------

namespace {

/// One MPI connection's S7 session on an H CPU: answers while the model's session lives. A job
/// arriving during an update (t1..t5) is held by the model and answered at t5 or the abort, in
/// arrival order, through the station's late-answer sink (000 L1673-1680; docs/h-sfc90.md
/// "Communication jobs held by the update"): the station then queues it on the connection for
/// its next token, with the line's now (no wake of its own is needed: the station's MAC sends
/// queued frames whenever it holds the token, and it re-arms its timer through its port).
class HSession final : public mpi_station::S7Session {
 public:
  explicit HSession(devices::HS7Session s) : m_s(std::move(s)) {}
  ~HSession() override { m_s.on_late_answer(nullptr); }  // the connection ended: held jobs dropped
  HSession(const HSession&) = delete;
  HSession& operator=(const HSession&) = delete;
  std::vector<std::uint8_t> handle(std::span<const std::uint8_t> pdu) override { return m_s.handle(pdu); }
  bool holds_jobs_now() const override { return m_s.holds_jobs_now(); }
  void on_late_answer(mpi_station::LateAnswerSink sink) override { m_s.on_late_answer(std::move(sink)); }
  bool ended() const override { return !m_s.alive(); }  // lost with its CPU, at a link-up (R8)

 private:
  devices::HS7Session m_s;
};

}  // namespace

class HCpuMpiNode::Factory final : public mpi_station::S7SessionFactory {
 public:
  Factory(int rack, std::function<devices::HSystemModel*()> model)
      : m_rack(rack), m_model(std::move(model)) {}
  std::unique_ptr<mpi_station::S7Session> open(std::uint8_t) override {
    devices::HSystemModel* m = m_model();
    if (m == nullptr) return nullptr;
    devices::HS7Session s = m->open_s7_adhoc(m_rack);
    if (!s.alive()) return nullptr;  // no resources, R8, CPU not carrying: refused
    return std::make_unique<HSession>(std::move(s));
  }

 private:
  int m_rack;
  std::function<devices::HSystemModel*()> m_model;
};

HCpuMpiNode::HCpuMpiNode(const HMpiPlan& plan, int rack, const fdl::BusParams& params,
                         std::function<devices::HSystemModel*()> model)
    : m_plan(plan), m_rack(rack), m_factory(std::make_unique<Factory>(rack, std::move(model))) {
  mpi_station::MpiStationConfig c;
  c.address = plan.address[rack];
  c.bus = params;
  // The model counts the CPU's connections (HCpuPair::connect); the pool is no tighter.
  c.pool.max_connections = plan.max_connections;
  m_station = std::make_unique<mpi_station::MpiStation>(c, m_factory.get());
}

HCpuMpiNode::~HCpuMpiNode() = default;

// --- MpiClientNode ------------------------------------------------------------------------------

namespace {

constexpr bus::Ticks kPgRetry = bus::kTicksPerSecond;
constexpr std::uint16_t kPgPduSize = 240;  // the most one MPI data message carries (docs/mpi.md)
// Tags: kind in the high 32 bits, peer index below.
constexpr std::uint64_t kPgTagEvents = 1ull << 32;
constexpr std::uint64_t kPgTagReconnect = 2ull << 32;
constexpr std::uint64_t kPgTagPump = 3ull << 32;

std::uint8_t area_code(S7ItemPlan::Area a) {
  switch (a) {
    case S7ItemPlan::Area::Inputs: return s7::area::kInputs;
    case S7ItemPlan::Area::Outputs: return s7::area::kOutputs;
    case S7ItemPlan::Area::Flags: return s7::area::kFlags;
    case S7ItemPlan::Area::Db: break;
  }
  return s7::area::kDataBlock;
}

}  // namespace

MpiClientNode::MpiClientNode(bus::Scheduler& sched, const MpiStationPlan& plan,
                             const fdl::BusParams& params)
    : m_sched(sched), m_plan(plan), m_station([&] {
        mpi_station::MpiStationConfig c;
        c.address = plan.address;
        c.bus = params;
        return c;
      }()) {
  for (const auto& r : plan.reads) {
    if (std::none_of(m_peers.begin(), m_peers.end(), [&](const Peer& p) { return p.cpu == r.cpu; })) {
      Peer p;
      p.cpu = r.cpu;
      m_peers.push_back(p);
    }
  }
  m_stats.resize(plan.reads.size());
  m_due.assign(plan.reads.size(), 0);
  m_station.set_event_handler([this](const mpi_station::StationEvent& e) {
    // Handled in an event of its own at the same tick: the station is inside its MAC callback.
    m_pending.push_back(e);
    if (m_pending.size() == 1) m_sched.schedule(e.at, *this, kPgTagEvents);
  });
}

void MpiClientNode::start(bus::Ticks now) {
  for (std::size_t i = 0; i < m_due.size(); ++i) m_due[i] = now;
  for (auto& p : m_peers) connect(p);
}

MpiClientNode::Peer* MpiClientNode::peer_of(mpi_station::Handle h) {
  for (auto& p : m_peers)
    if (p.handle && *p.handle == h) return &p;
  return nullptr;
}

void MpiClientNode::connect(Peer& p) {
  p.ready = false;
  p.outstanding = -1;
  p.handle = m_station.open(p.cpu);
  if (p.handle) ++m_connects;
  else m_sched.schedule(m_sched.now() + kPgRetry, *this, kPgTagReconnect | static_cast<std::uint64_t>(&p - m_peers.data()));
}

void MpiClientNode::on_event(bus::Ticks now, std::uint64_t tag) {
  const std::uint64_t kind = tag & ~0xFFFFFFFFull;
  const auto index = static_cast<std::size_t>(tag & 0xFFFFFFFFull);
  if (kind == kPgTagEvents) {
    auto events = std::move(m_pending);
    m_pending.clear();
    for (const auto& e : events) on_station_event(e);
  } else if (kind == kPgTagReconnect && index < m_peers.size()) {
    if (!m_peers[index].handle) connect(m_peers[index]);
  } else if (kind == kPgTagPump && index < m_peers.size()) {
    pump(m_peers[index], now);
  }
}

void MpiClientNode::on_station_event(const mpi_station::StationEvent& e) {
  if (e.role != mpi_station::Role::Client) return;
  Peer* p = peer_of(e.handle);
  if (p == nullptr) return;
  const auto index = static_cast<std::uint64_t>(p - m_peers.data());
  switch (e.kind) {
    case mpi_station::EventKind::Connected: {
      const auto setup = s7::encode_setup_communication_request(p->next_ref++, {1, 1, kPgPduSize});
      if (setup.ok()) m_station.submit(*p->handle, setup.value);
      break;
    }
    case mpi_station::EventKind::Reply: {
      const auto pdu = s7::decode_s7_pdu(e.pdu);
      if (!pdu.ok()) break;
      if (!p->ready) {
        p->ready = s7::decode_setup_communication(pdu.value).ok();
      } else if (p->outstanding >= 0) {
        const auto r = static_cast<std::size_t>(p->outstanding);
        S7ReadStats& st = m_stats[r];
        const auto items = s7::decode_read_var_response(pdu.value);
        if (items.ok() && items.value.size() == 1 &&
            items.value[0].return_code == s7::return_code::kSuccess) {
          ++st.ok;
          st.last_value.assign(items.value[0].data.begin(), items.value[0].data.end());
        } else {
          ++st.errors;
          st.last_code = items.ok() && !items.value.empty() ? items.value[0].return_code : 0;
        }
        st.last_latency = e.at - p->sent_at;
        st.max_latency = std::max(st.max_latency, st.last_latency);
        // A fixed grid of periods from the first read; a late answer moves it to the answer.
        m_due[r] = std::max(m_due[r] + m_plan.reads[r].period, e.at);
        p->outstanding = -1;
      }
      pump(*p, e.at);
      break;
    }
    case mpi_station::EventKind::Refused:
    case mpi_station::EventKind::Broken:
    case mpi_station::EventKind::Closed:
      ++(e.kind == mpi_station::EventKind::Refused ? m_refusals : m_breaks);
      if (e.kind != mpi_station::EventKind::Refused)
        ++m_ends[std::string(mpi_station::to_string(e.reason))];
      p->handle.reset();
      p->ready = false;
      p->outstanding = -1;
      m_sched.schedule(e.at + kPgRetry, *this, kPgTagReconnect | index);
      break;
    case mpi_station::EventKind::Accepted:
      break;
  }
}

void MpiClientNode::pump(Peer& p, bus::Ticks now) {
  if (!p.handle || !p.ready || p.outstanding >= 0) return;
  int best = -1;
  for (std::size_t r = 0; r < m_plan.reads.size(); ++r) {
    if (m_plan.reads[r].cpu != p.cpu) continue;
    if (best < 0 || m_due[r] < m_due[static_cast<std::size_t>(best)]) best = static_cast<int>(r);
  }
  if (best < 0) return;
  const auto r = static_cast<std::size_t>(best);
  const auto index = static_cast<std::uint64_t>(&p - m_peers.data());
  if (m_due[r] > now) {
    m_sched.schedule(m_due[r], *this, kPgTagPump | index);
    return;
  }
  const S7ItemPlan& it = m_plan.reads[r].item;
  s7::VarItem v;
  v.transport_size = s7::transport::kByte;
  v.count = static_cast<std::uint16_t>(it.bytes());
  v.db_number = it.area == S7ItemPlan::Area::Db ? it.db : 0;
  v.area = area_code(it.area);
  v.address = it.byte * 8;
  const auto job = s7::encode_read_var_request(p.next_ref++, std::span<const s7::VarItem>(&v, 1));
  if (!job.ok() || m_station.submit(*p.handle, job.value) != mpi::RequestError::None) return;
  ++m_stats[r].requests;
  p.outstanding = best;
  p.sent_at = now;
}

}  // namespace pbvbus::tools
