// An s7_door in a running scenario (s7_door_node.hpp has the decisions).
#include "pbvbus/simulation/s7_door_node.hpp"

#include <algorithm>
#include <deque>
#include <iostream>
#include <stdexcept>

#include "pbvbus/s7cpu/s7_server.hpp"

namespace pbvbus::tools {

namespace {
constexpr std::uint64_t kDoorTagEvents = 1;
}  // namespace

/// A client connection to a single CPU's memory: its own S7 server session, answered at once.
class S7DoorNode::CpuChannel final : public iso_on_tcp::S7Channel {
 public:
  explicit CpuChannel(std::unique_ptr<s7cpu::S7Server> server) : m_server(std::move(server)) {}
  void request(std::vector<std::uint8_t> pdu, Reply reply) override {
    reply(m_server->handle(pdu).value);
  }
  void on_closed(Closed) override {}  // a CPU reached directly does not go away in the model

 private:
  std::unique_ptr<s7cpu::S7Server> m_server;
};

/// A client connection carried over one MPI connection of the door's station.
class S7DoorNode::MpiChannel final : public iso_on_tcp::S7Channel {
 public:
  MpiChannel(S7DoorNode& door, mpi_station::Handle h) : m_door(door), m_handle(h) {}
  ~MpiChannel() override {
    auto& v = m_door.m_mpi_channels;
    v.erase(std::remove(v.begin(), v.end(), this), v.end());
    if (m_open) m_door.m_mpi->close(m_handle);
  }
  void request(std::vector<std::uint8_t> pdu, Reply reply) override {
    m_replies.push_back(std::move(reply));
    if (m_connected) m_door.m_mpi->submit(m_handle, pdu);
    else m_waiting.push_back(std::move(pdu));
  }
  void on_closed(Closed closed) override { m_closed = std::move(closed); }

  mpi_station::Handle handle() const { return m_handle; }
  void connected() {
    m_connected = true;
    for (auto& p : m_waiting) m_door.m_mpi->submit(m_handle, p);
    m_waiting.clear();
  }
  void answer(std::vector<std::uint8_t> pdu) {
    if (m_replies.empty()) return;  // an answer nobody asked for: dropped
    auto r = std::move(m_replies.front());
    m_replies.pop_front();
    r(std::move(pdu));
  }
  void ended(const std::string& why) {
    m_open = false;
    if (m_closed) {
      auto c = std::move(m_closed);
      m_closed = nullptr;
      c(why);
    }
  }

 private:
  S7DoorNode& m_door;
  mpi_station::Handle m_handle;
  bool m_open = true;
  bool m_connected = false;
  std::deque<Reply> m_replies;
  std::vector<std::vector<std::uint8_t>> m_waiting;
  Closed m_closed;
};

/// A client connection to an H-system over one of the model's S7 sessions. A job the model
/// holds during an update (t1..t5, 000 L1673-1680; docs/h-sfc90.md "held jobs") waits in a FIFO
/// of replies and is answered through the session's late-answer sink at t5 (or the abort), in
/// arrival order; an empty late answer (the session ended meanwhile) closes the connection.
class S7DoorNode::HChannel final : public iso_on_tcp::S7Channel {
 public:
  explicit HChannel(devices::HS7Session s) : m_s(std::move(s)) {
    m_s.on_late_answer([this](std::vector<std::uint8_t> answer) { late(std::move(answer)); });
  }
  ~HChannel() override { m_s.on_late_answer(nullptr); }  // the held jobs are dropped
  HChannel(const HChannel&) = delete;
  HChannel& operator=(const HChannel&) = delete;

  void request(std::vector<std::uint8_t> pdu, Reply reply) override {
    if (m_s.holds_jobs_now()) {
      m_held.push_back(std::move(reply));
      auto answer = m_s.handle(pdu);
      if (answer.empty()) return;  // stored: answered by late()
      auto r = std::move(m_held.back());  // answered after all (defensive)
      m_held.pop_back();
      r(std::move(answer));
      return;
    }
    if (m_s.alive()) {
      auto answer = m_s.handle(pdu);
      if (m_s.alive() || !answer.empty()) {
        reply(std::move(answer));
        return;
      }
    }
    ended();
  }
  void on_closed(Closed closed) override { m_closed = std::move(closed); }

 private:
  void late(std::vector<std::uint8_t> answer) {
    if (m_held.empty()) return;  // an answer nobody waits for: dropped
    if (answer.empty() && !m_s.alive()) {
      ended();
      return;
    }
    auto r = std::move(m_held.front());
    m_held.pop_front();
    r(std::move(answer));
  }
  // The connection ended with its CPU (or CP, or at a link-up), also with jobs still held: the
  // client gets a DR, no reply is left hanging.
  void ended() {
    m_held.clear();
    if (m_closed) {
      auto c = std::move(m_closed);
      m_closed = nullptr;
      c(m_s.close_text());
    }
  }

  devices::HS7Session m_s;
  std::deque<Reply> m_held;
  Closed m_closed;
};

S7DoorNode::S7DoorNode(bus::Scheduler& sched, const S7DoorPlan& plan, std::vector<S7CpuNode*> cpus,
                       const fdl::BusParams* mpi_params,
                       std::function<devices::HSystemModel*(int)> h_model)
    : m_sched(sched), m_plan(plan), m_cpus(std::move(cpus)), m_h_model(std::move(h_model)) {
  if (plan.mpi_line >= 0 && mpi_params != nullptr) {
    mpi_station::MpiStationConfig c;
    c.address = plan.mpi_address;
    c.bus = *mpi_params;
    m_mpi = std::make_unique<mpi_station::MpiStation>(c);
    m_mpi->set_event_handler([this](const mpi_station::StationEvent& e) {
      m_pending.push_back(e);
      if (m_pending.size() == 1) m_sched.schedule(e.at, *this, kDoorTagEvents);
    });
  }
}

S7DoorNode::~S7DoorNode() { close(); }

void S7DoorNode::close() {
  if (m_door) m_door->close();
  m_door.reset();
}

void S7DoorNode::open(bus::PacedRunner& runner) {
  if (m_door) return;
  iso_on_tcp::IsoDoorOptions o;
  o.address = m_plan.listen.host;
  o.port = m_plan.listen.port;
  if (m_plan.max_connections != 0) o.max_clients = m_plan.max_connections;
  o.idle_timeout = std::chrono::milliseconds(m_plan.idle_timeout / bus::kTicksPerMs);
  const std::string name = m_plan.name;
  o.log = [name](const std::string& line) {
    std::cerr << "pbvbus run: s7_door \"" << name << "\": " << line << std::endl;
  };
  o.capture = m_capture;
  try {
    m_door = std::make_unique<iso_on_tcp::IsoOnTcpDoor>(runner.io_context(), *this, o);
  } catch (const std::exception& e) {
    throw std::runtime_error("s7_door \"" + m_plan.name + "\" on " + m_plan.listen.str() + ": " +
                             e.what());
  }
}

iso_on_tcp::RouteResult S7DoorNode::open(const iso_on_tcp::RouteRequest& request) {
  // DR reasons (ISO 8073 / RFC 905 table): 3 = "unknown destination TSAP"-like refusal as the
  // door's LocalCpuRouter gives it, 1 = congestion at the TSAP (docs/iso-on-tcp.md).
  if (!request.called)
    return iso_on_tcp::RouteResult::refuse(3, "the called TSAP names no rack/slot");
  const auto rack = request.called->rack, slot = request.called->slot;
  const auto it = std::find_if(m_plan.routes.begin(), m_plan.routes.end(),
                               [&](const S7RoutePlan& r) { return r.rack == rack && r.slot == slot; });
  if (it == m_plan.routes.end())
    return iso_on_tcp::RouteResult::refuse(
        3, "no route for rack " + std::to_string(rack) + " slot " + std::to_string(slot));
  iso_on_tcp::RouteResult r;
  switch (it->kind) {
    case S7RoutePlan::Kind::Cpu:
      r.channel = std::make_unique<CpuChannel>(m_cpus.at(static_cast<std::size_t>(it->target))->open_server());
      return r;
    case S7RoutePlan::Kind::Mpi: {
      const auto h = m_mpi ? m_mpi->open(it->mpi_address) : std::nullopt;
      if (!h)
        return iso_on_tcp::RouteResult::refuse(
            1, "no MPI connection to " + std::to_string(it->mpi_address) + " can be opened now");
      auto ch = std::make_unique<MpiChannel>(*this, *h);
      m_mpi_channels.push_back(ch.get());
      r.channel = std::move(ch);
      return r;
    }
    case S7RoutePlan::Kind::HSystem: {
      devices::HSystemModel* m = m_h_model ? m_h_model(it->target) : nullptr;
      if (m == nullptr) return iso_on_tcp::RouteResult::refuse(1, "the H-system is not running");
      devices::HS7Session session;
      if (it->connection >= 0) {
        session = m->open_s7_connection(m->comms().connections().at(
            static_cast<std::size_t>(it->connection)).config.name);
      } else {
        const int master = m->pair().master();
        if (master < 0) return iso_on_tcp::RouteResult::refuse(1, "the H-system has no master CPU");
        session = m->open_s7_adhoc(master);
      }
      if (!session.alive()) return iso_on_tcp::RouteResult::refuse(1, session.close_text());
      r.channel = std::make_unique<HChannel>(std::move(session));
      return r;
    }
  }
  return iso_on_tcp::RouteResult::refuse(3, "route kind not served");
}

void S7DoorNode::on_event(bus::Ticks, std::uint64_t tag) {
  if (tag != kDoorTagEvents) return;
  auto events = std::move(m_pending);
  m_pending.clear();
  for (const auto& e : events) on_station_event(e);
}

void S7DoorNode::on_station_event(const mpi_station::StationEvent& e) {
  if (e.role != mpi_station::Role::Client) return;
  const auto it = std::find_if(m_mpi_channels.begin(), m_mpi_channels.end(),
                               [&](const MpiChannel* c) { return c->handle() == e.handle; });
  if (it == m_mpi_channels.end()) return;
  MpiChannel& ch = **it;
  switch (e.kind) {
    case mpi_station::EventKind::Connected: ch.connected(); break;
    case mpi_station::EventKind::Reply: ch.answer(e.pdu); break;
    case mpi_station::EventKind::Refused:
      ch.ended("the CPU at MPI address " + std::to_string(e.peer) + " refused the connection");
      break;
    case mpi_station::EventKind::Broken:
    case mpi_station::EventKind::Closed:
      ch.ended("the MPI connection to " + std::to_string(e.peer) + " ended (" +
               std::string(mpi_station::to_string(e.reason)) + ")");
      break;
    case mpi_station::EventKind::Accepted: break;
  }
}

}  // namespace pbvbus::tools
