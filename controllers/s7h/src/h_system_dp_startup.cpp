// "Transfer of parameters to modules" monitoring started by the H-system model (h_system.hpp
// block of that name; h_dp_startup.hpp; 001 L8094-8114, docs/h-changes.md "In the H-system
// model"). Decisions:
//   - it starts when a CPU enters STARTUP (its DP master(s) parameterise every station: the
//     master's start-up, 001 L8113 "the bus load is highest at a new start of the DP master,
//     e.g. after power on") and when a standby enters UPDATE (the end of its link-up: its DP
//     master starts on its own line, 001 Fig. 6-1); a new start restarts it;
//   - the stations are those the CPU's DP master (line = rack) of each master system
//     configures; a station in data exchange at the end is in time (late_stations(): entering
//     at exactly the end counts);
//   - at the end one W#16#6547 entry per master system with late stations, on that CPU, if it
//     is still starting up or running (not Off/STOP); the start-up goes on (h_dp_startup.hpp).
#include <string>
#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/s7h/h_dp_startup.hpp"
#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

void HSystemModel::set_param_transfer_time(std::uint32_t units_100ms) {
  m_ptt = units_100ms;
  ++m_ptt_gen[0];  // a monitoring under way ends without an entry
  ++m_ptt_gen[1];
}

void HSystemModel::ptt_on_pair_event(const HEvent& e) {
  if (m_ptt == 0 || e.kind != HEvent::Kind::State || !valid_rack(e.rack)) return;
  if (e.to_state != CpuState::Startup && e.to_state != CpuState::Update) return;
  const int r = e.rack;
  const std::uint64_t gen = ++m_ptt_gen[static_cast<std::size_t>(r)];
  const bus::Ticks start = e.at;
  m_sched.schedule(start + param_transfer_time(m_ptt),
                   [this, r, gen, start] { ptt_end(r, gen, start); });
}

void HSystemModel::ptt_end(int rack, std::uint64_t gen, bus::Ticks start) {
  const auto i = static_cast<std::size_t>(rack);
  if (gen != m_ptt_gen[i]) return;  // restarted or switched off meanwhile
  m_ptt_late[i].clear();
  const CpuState st = m_pair.state(rack);
  if (st == CpuState::Off || st == CpuState::Stop) return;
  for (auto* ms : m_systems) {
    const dp::Master& m = ms->master(rack);
    std::vector<HStationStart> st_list;
    for (std::uint8_t a : ms->system().addresses()) {
      if (!m.has_slave(a)) continue;
      HStationStart x{a, std::nullopt};
      if (m.slave_state(a) == dp::SlaveStatusState::DataExchange) x.data_exchange_at = start;
      st_list.push_back(x);
    }
    const auto late = late_stations(start, m_ptt, st_list);
    if (late.empty()) continue;
    std::string t = "transfer of parameters to modules: monitoring time exceeded, stations";
    for (auto a : late) t += " " + std::to_string(a);
    log_entry(rack, std::move(t), kParamTransferExceeded);
    m_ptt_late[i].insert(m_ptt_late[i].end(), late.begin(), late.end());
  }
}

}  // namespace pbvbus::devices
