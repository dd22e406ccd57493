// The redundant DP master system on two lines (redundant_master_system.hpp).
#include "pbvbus/switched_io/redundant_master_system.hpp"

#include <stdexcept>

#include "pbvbus/dp/sap.hpp"

namespace pbvbus::devices {

/// One line's master: the dp::Master behind its ActiveStation, with the model's checks around
/// every call the station makes into it.
class RedundantMasterSystemModel::Node final : public fdl::InitiatorUser {
 public:
  Node(RedundantMasterSystemModel& m, int line, const dp::MasterParams& mp,
       std::vector<dp::SlaveParams> slaves, const fdl::BusParams& bp)
      : m_model(m), m_line(line), m_master(mp, std::move(slaves)), m_station(mp.address, bp, *this) {}

  dp::Master& master() { return m_master; }
  fdl::ActiveStation& station() { return m_station; }

  void on_power_on(bus::Ticks now) override {
    m_model.check_medium(m_line, now);
    m_master.on_power_on(now);
  }
  bool next_request(fdl::Priority prio, bus::Ticks now, fdl::Request& out) override {
    m_model.check_medium(m_line, now);
    if (!m_master.next_request(prio, now, out)) return false;
    if (out.da == fdl::kBroadcast && out.dsap == dp::kSapGlobalControl) ++global_controls;
    return true;
  }
  std::uint64_t global_controls = 0;
  void on_confirmation(const fdl::Confirmation& con) override {
    // Before the master can turn a short circuit into station failures.
    m_model.check_medium(m_line, con.now);
    m_master.on_confirmation(con);
  }
  void on_request(const fdl::Indication& ind, fdl::Reply& reply) override {
    m_master.on_request(ind, reply);
  }
  void on_token(bus::Ticks now, bus::Ticks trr) override {
    m_model.check_medium(m_line, now);
    m_model.cycle(m_line, now);
    m_master.on_token(now, trr);
  }
  bus::Ticks pause_until(bus::Ticks now) override { return m_master.pause_until(now); }

 private:
  RedundantMasterSystemModel& m_model;
  int m_line;
  dp::Master m_master;
  fdl::ActiveStation m_station;
};

RedundantMasterSystemModel::RedundantMasterSystemModel(
    RedundantMasterSystemOptions o, std::vector<dp::SlaveParams> slaves_a,
    std::vector<dp::SlaveParams> slaves_b, std::vector<redundancy::SwitchedStationRef> switched) {
  m_node[0] = std::make_unique<Node>(*this, 0, o.master[0], std::move(slaves_a), o.bus_params);
  m_node[1] = std::make_unique<Node>(*this, 1, o.master[1], std::move(slaves_b),
                                     o.bus_params_b ? *o.bus_params_b : o.bus_params);
  m_system = std::make_unique<redundancy::MasterSystem>(m_node[0]->master(), m_node[1]->master(),
                                                        std::move(switched), o.system);
  for (int l = 0; l < 2; ++l) {
    m_node[l]->master().set_event_handler([this, l](const dp::MasterEvent& e) {
      m_system->on_master_event(l, e);
      if (m_master_events) m_master_events(l, e);
    });
  }
}

RedundantMasterSystemModel::~RedundantMasterSystemModel() = default;

fdl::ActiveStation& RedundantMasterSystemModel::station(int l) { return m_node[l]->station(); }
const fdl::ActiveStation& RedundantMasterSystemModel::station(int l) const {
  return m_node[l]->station();
}
dp::Master& RedundantMasterSystemModel::master(int l) { return m_node[l]->master(); }
const dp::Master& RedundantMasterSystemModel::master(int l) const { return m_node[l]->master(); }
std::uint64_t RedundantMasterSystemModel::global_controls(int l) const {
  return m_node[l]->global_controls;
}

bus::AttachmentId RedundantMasterSystemModel::attach(int line, bus::Line& l, std::string label) {
  if (line != 0 && line != 1) throw std::invalid_argument("redundant master system: line 0 or 1");
  m_line[line] = &l;
  m_att[line] = l.attach(m_node[line]->station(), std::move(label));
  if (!m_cpu_on[line]) l.set_power(m_att[line], false);  // attachments start unpowered anyway
  return m_att[line];
}

bus::Ticks RedundantMasterSystemModel::now(int line) const {
  return m_line[line] != nullptr ? m_line[line]->scheduler().now() : 0;
}

void RedundantMasterSystemModel::check_medium(int line, bus::Ticks now) {
  const bool fault = m_node[line]->station().medium_fault();
  if (fault == m_short[line]) return;
  m_short[line] = fault;
  if (fault) m_system->line_lost(line, redundancy::LineLoss::ShortCircuit, now);
  else m_system->line_back(line, now);
}

void RedundantMasterSystemModel::cycle(int line, bus::Ticks now) {
  if (m_system->next_deadline() <= now) m_system->on_time(now);
  if (m_hook) m_hook(*this, line, now);
}

void RedundantMasterSystemModel::stop_master(int line) {
  // The system first, so that the master's own ModeChange finds the line already lost.
  m_system->line_lost(line, redundancy::LineLoss::MasterStop, now(line));
  m_node[line]->master().set_mode(dp::MasterMode::Stop);
}

void RedundantMasterSystemModel::start_master(int line) {
  m_system->line_back(line, now(line));
  m_node[line]->master().set_mode(dp::MasterMode::Operate);
}

void RedundantMasterSystemModel::fail_master(int line) {
  if (m_failed[line]) return;
  m_failed[line] = true;
  if (m_line[line] != nullptr) m_line[line]->set_power(m_att[line], false);
  m_system->line_lost(line, redundancy::LineLoss::MasterFailure, now(line));
}

void RedundantMasterSystemModel::repair_master(int line) {
  if (!m_failed[line]) return;
  m_failed[line] = false;
  m_system->line_back(line, now(line));
  apply_power(line);
}

void RedundantMasterSystemModel::set_cpu_power(int line, bool on) {
  if (line != 0 && line != 1) return;
  m_cpu_on[line] = on;
  apply_power(line);
}

void RedundantMasterSystemModel::apply_power(int line) {
  if (m_line[line] == nullptr) return;
  m_line[line]->set_power(m_att[line], m_cpu_on[line] && !m_failed[line]);
}

bool RedundantMasterSystemModel::attachment_powered(int line) const {
  return (line == 0 || line == 1) && m_line[line] != nullptr && m_line[line]->powered(m_att[line]);
}

}  // namespace pbvbus::devices
