// DP-V1 alarms as OBs (held during the update), data-record jobs and SFC 51 (R7), OB 85 of the
// H-system model (h_system.hpp and h_system_records.hpp have the decisions).
#include <cstdio>

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

namespace {

/// The S7 OB of a DP-V1 alarm type (DP-V1 Alarm_Type; S7: OB 40 process, OB 82 diagnostic,
/// OB 83 pull/plug, OB 55 status, OB 56 update, OB 57 manufacturer-specific).
int alarm_ob(std::uint8_t type, const char*& name) {
  switch (type) {
    case 1: name = "diagnostic alarm"; return 82;
    case 2: name = "process alarm"; return 40;
    case 3: name = "pull alarm"; return 83;
    case 4: name = "plug alarm"; return 83;
    case 5: name = "status alarm"; return 55;
    case 6: name = "update alarm"; return 56;
    default: name = "manufacturer-specific alarm"; return 57;
  }
}

}  // namespace

void HSystemModel::on_alarm(std::size_t s, const redundancy::SystemAlarm& a) {
  HSystemEvent h;
  const char* name = "";
  h.ob = alarm_ob(a.type, name);
  h.time = a.time;
  h.original_time = a.time;
  char buf[160];
  std::snprintf(buf, sizeof buf, "OB %d %s, DP master system %zu, station %u, slot %u, line %s",
                h.ob, name, s + 1, static_cast<unsigned>(a.station),
                static_cast<unsigned>(a.slot), a.line == 1 ? "B" : "A");
  h.text = buf;
  h.source = HSystemEvent::Source::Alarm;
  h.system = static_cast<int>(s);
  h.line = a.line;
  h.station = a.station;
  h.code = a.type;  // the DP-V1 Alarm_Type (OB 82/83: the S7 event ID, alarm_start_info)
  h.incoming = (a.specifier & 0x03) != 2;  // Alarm_Specifier 2 = disappears
  alarm_start_info(s, a, h);  // OB 82/83: S7 event ID, MDL_ADDR, both CPUs log (F3)
  if (m_pair.interrupts_held()) {
    m_held_alarms.push_back(std::move(h));  // digest §4: DP modules store them, delivered after
    return;
  }
  deliver_alarm(std::move(h), a.time);
}

void HSystemModel::deliver_alarm(HSystemEvent h, bus::Ticks now) {
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  if (!run0 && !run1) return;  // no program runs: no OB (the station's alarm is acknowledged)
  h.time = now;
  h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  add_event(std::move(h));
}

void HSystemModel::deliver_held(bus::Ticks now) {
  if (m_pair.interrupts_held()) return;
  // In their order, once: moved out before delivering (a handler may add new ones).
  auto alarms = std::move(m_held_alarms);
  m_held_alarms.clear();
  for (auto& h : alarms) deliver_alarm(std::move(h), now);
  auto records = std::move(m_held_records);
  m_held_records.clear();
  for (auto& r : records) {
    r.res.completed = now;
    if (r.cb) r.cb(r.res);
  }
}

// ---- data-record jobs (SFC 58/59) and SFC 51 -----------------------------------------------

std::uint16_t HSystemModel::read_record(std::size_t system, std::uint8_t station,
                                        std::uint8_t slot, std::uint8_t index,
                                        std::uint8_t length, RecordJobCallback cb) {
  return start_record(system, station, false, slot, index, length, {}, std::move(cb));
}

std::uint16_t HSystemModel::write_record(std::size_t system, std::uint8_t station,
                                         std::uint8_t slot, std::uint8_t index,
                                         std::span<const std::uint8_t> data,
                                         RecordJobCallback cb) {
  return start_record(system, station, true, slot, index, 0, data, std::move(cb));
}

std::uint16_t HSystemModel::start_record(std::size_t system, std::uint8_t station, bool write,
                                         std::uint8_t slot, std::uint8_t index,
                                         std::uint8_t length, std::span<const std::uint8_t> data,
                                         RecordJobCallback cb) {
  const bus::Ticks now = m_sched.now();
  const std::uint16_t refused = m_pair.record_job_result(write ? 58 : 59, now);
  if (refused != 0) return refused;  // W#16#80C3: a new job during the update
  if (system >= m_systems.size()) return kRetNoAddress;
  const std::size_t updates = m_measures.size();
  auto done = [this, updates, write, cb = std::move(cb)](const dp::AcyclicResult& r) {
    RecordJobResult res;
    res.result = r;
    res.completed = m_sched.now();
    const bool ok = r.status == dp::AcyclicStatus::Ok;
    res.ret_val = ok ? 0 : (write ? kRetWriteNegative : kRetReadNegative);
    // A job the update interrupted (an update started while it ran) returns 80C3; if it
    // completes inside the update it stays BUSY until t5 (digest §4 step 1).
    if (m_measures.size() != updates || m_pair.interrupts_held()) {
      res.ret_val = kRetUpdateBusy;
      if (m_pair.interrupts_held()) {
        m_held_records.push_back({cb, std::move(res)});
        return;
      }
    }
    if (cb) cb(res);
  };
  redundancy::MasterSystem& ms = m_systems[system]->system();
  const std::uint32_t id =
      write ? ms.write(station, slot, index, data, std::move(done), now)
            : ms.read(station, slot, index, length, std::move(done), now);
  return id == 0 ? kRetNoAddress : 0;
}

HSystemState HSystemModel::read_system_state(bus::Ticks now) {
  HSystemState st;
  st.ret_val = m_pair.record_job_result(51, now);
  if (st.ret_val != 0) return st;  // W#16#8085 during the update
  st.master_rack = m_pair.master();
  for (int r = 0; r < 2; ++r) {
    st.state[static_cast<std::size_t>(r)] = m_pair.state(r);
    st.role[static_cast<std::size_t>(r)] = m_pair.role(r);
  }
  st.mode = m_pair.system_mode();
  return st;
}

// ---- OB 85 -----------------------------------------------------------------------------------

void HSystemModel::check_process_image(bus::Ticks now) {
  if (m_ob85.size() != m_systems.size()) m_ob85.assign(m_systems.size(), std::vector<bool>(128));
  std::uint8_t last = 0xFF;
  int last_sys = -1;
  for (const HIoEntry& e : m_map.entries()) {
    if (e.central) continue;  // expansion racks: read_racks (h_system_racks.cpp)
    if (e.system == last_sys && e.address == last) continue;  // once per station
    last_sys = e.system;
    last = e.address;
    const redundancy::MasterSystem& ms = m_systems[static_cast<std::size_t>(e.system)]->system();
    const bool failed = ms.active_image(e.address) == nullptr && ms.station_failed(e.address);
    auto flag = m_ob85[static_cast<std::size_t>(e.system)][e.address];
    if (failed == static_cast<bool>(flag)) continue;
    flag = failed;
    HSystemEvent h;
    h.time = now;
    h.original_time = now;
    h.ob = 85;
    // S7 OB 85 event class 39 (incoming) / 38 (outgoing), fault ID B1: I/O access error while
    // transferring the process image (the seeds name OB 85, not its ID: S7 system software).
    h.code = failed ? 0x39B1 : 0x38B1;
    h.incoming = failed;
    h.source = HSystemEvent::Source::Image;
    h.system = e.system;
    h.station = e.address;
    char buf[128];
    std::snprintf(buf, sizeof buf, "OB 85 W#16#%04X process-image transfer error %s, DP master "
                  "system %d, station %u", static_cast<unsigned>(h.code),
                  failed ? "incoming" : "outgoing", e.system + 1, static_cast<unsigned>(e.address));
    h.text = buf;
    const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
    h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
    h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
    add_event(std::move(h));
  }
}

}  // namespace pbvbus::devices
