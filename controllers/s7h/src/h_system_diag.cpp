// F3 (I/O module fault), F15 (slave RUN <-> STOP) and OB 122 of the H-system model: OB 82/83
// start information, OB 82 from diagnosis changes, OB 122 for direct access (h_system.hpp, block
// "F3/F15/OB 122", has the decisions; docs/h-system.md "Interrupts, ...").
#include <algorithm>
#include <cstdio>

#include "pbvbus/s7h/h_event_ids.hpp"
#include "pbvbus/s7h/h_system.hpp"
#include "pbvbus/slaves/slave_fault.hpp"
#include "pbvbus/dp/diagnosis.hpp"

namespace pbvbus::devices {

namespace {

using namespace h_event;  // the event IDs (h_event_ids.hpp)

bool contains(const std::vector<std::uint32_t>& v, std::uint32_t k) {
  return std::find(v.begin(), v.end(), k) != v.end();
}
void set(std::vector<std::uint32_t>& v, std::uint32_t k, bool on) {
  const auto it = std::find(v.begin(), v.end(), k);
  if (on && it == v.end()) v.push_back(k);
  if (!on && it != v.end()) v.erase(it);
}

/// What a diagnosis says, per the rules in h_system.hpp.
struct DiagView {
  std::vector<std::size_t> faulty_ids;      ///< identifier numbers of channel blocks
  std::vector<std::size_t> faulty_modules;  ///< identifier-related block bits (module index)
  std::vector<std::uint8_t> alarm_slots;    ///< slots of Diagnostic/Pull/Plug alarm PDUs
  std::vector<std::size_t> no_module;       ///< DP-V1 Module_Status "no module" (pulled)
  bool stop = false;                        ///< S7 record 0 with MDL_STOP
};

DiagView view(std::span<const std::uint8_t> diag, bool dpv1) {
  DiagView v;
  std::vector<dp::ExtDiagBlock> blocks;
  if (diag.size() <= dp::kStdDiagLen || !dp::split_ext_diag(diag.subspan(dp::kStdDiagLen), blocks))
    return v;
  for (const auto& b : blocks) {
    const auto bytes = b.bytes;
    if (b.kind == dp::kBlockChannel && bytes.size() >= 1) {
      v.faulty_ids.push_back(bytes[0] & 0x3F);
    } else if (b.kind == dp::kBlockIdentifier) {
      for (std::size_t i = 1; i < bytes.size(); ++i)
        for (std::size_t bit = 0; bit < 8; ++bit)
          if ((bytes[i] >> bit) & 1u) v.faulty_modules.push_back((i - 1) * 8 + bit);
    } else if (b.kind == dp::kBlockDevice) {
      if (dpv1) {
        if (bytes.size() < 4) continue;
        const std::uint8_t type = bytes[1];
        if (type == 1 || type == 3 || type == 4) v.alarm_slots.push_back(bytes[2]);
        // Module_Status (0x82, slot 0): 2 bits per module from bit 0 of the first data octet.
        if (type == dp::kModuleStatus && bytes[2] == 0)
          for (std::size_t i = 4; i < bytes.size(); ++i)
            for (std::size_t k = 0; k < 4; ++k)
              if (((bytes[i] >> (2 * k)) & 0x03) == static_cast<std::uint8_t>(dp::ModuleState::NoModule))
                v.no_module.push_back((i - 4) * 4 + k);
        // Status_Message, slot 0, data = record 0: octet 2 of the data is the 7th of the PDU.
        if (type == kStatusMessage && bytes[2] == 0 && bytes.size() >= 8 &&
            (bytes[4 + kS7Rec0MdlStopOctet] & kS7Rec0MdlStop) != 0)
          v.stop = true;
      } else if (bytes.size() == 5 && (bytes[1 + kS7Rec0MdlStopOctet] & kS7Rec0MdlStop) != 0) {
        v.stop = true;  // DP-V0 free format: the 4-octet record 0
      }
    }
  }
  return v;
}

}  // namespace

std::uint16_t HSystemModel::module_address(int system, std::uint8_t station, int module) const {
  // A station-level event (F15, module -1): the slave's diagnostic address (D1/D2, 001 Table 4-8
  // L3072-3081, example OB82_MDL_ADDR := 1022 L3103-3110).
  if (module < 0 && system >= 0)
    if (const auto d = m_diag.slave(static_cast<std::size_t>(system), station)) return *d;
  for (const HIoEntry& e : m_map.entries()) {
    if (e.system != system || e.address != station) continue;
    if (module >= 0 && e.module != static_cast<std::size_t>(module)) continue;
    return static_cast<std::uint16_t>(e.in_len > 0 ? e.in_addr : e.out_addr);
  }
  return 0;
}

bool HSystemModel::module_reachable(const HIoEntry& e) const {
  // A central module (expansion rack, F8) is reachable with its rack; it has no DP station.
  if (e.central) return expansion_rack_reachable(e.rack);
  if (e.system < 0 || static_cast<std::size_t>(e.system) >= m_systems.size()) return false;
  const redundancy::MasterSystem& ms = m_systems[static_cast<std::size_t>(e.system)]->system();
  const auto key = module_key(e.system, e.address, e.module);
  return ms.active_image(e.address) != nullptr && !contains(m_pulled, key) &&
         !contains(m_pulled_alarm, key);
}

void HSystemModel::io_ob(HSystemEvent h) {
  log_on_powered(h.time, h.code, h.text);
  const bool run0 = m_pair.dp_master_operate(0), run1 = m_pair.dp_master_operate(1);
  if (!run0 && !run1) return;  // no program runs: only the buffer entries
  h.rack = run0 && run1 ? -1 : (run0 ? 0 : 1);
  h.role = h.rack < 0 ? CpuRole::Master : m_pair.role(h.rack);
  add_event(std::move(h));
}

void HSystemModel::alarm_start_info(std::size_t s, const redundancy::SystemAlarm& a,
                                    HSystemEvent& h) {
  const int sys = static_cast<int>(s);
  const int module = a.slot > 0 ? a.slot - 1 : -1;
  h.module = module;
  h.mdl_addr = module_address(sys, a.station, module);
  if (module < 0) return;
  const auto key = module_key(sys, a.station, static_cast<std::size_t>(module));
  // The alarm's own state is kept apart from the diagnosis-derived one (m_faulty, m_pulled):
  // an alarm's PDU leaving the diagnosis at its acknowledgement must not look like a change.
  if (h.ob == 82) {
    h.code = h.incoming ? kOb82Incoming : kOb82Outgoing;
  } else if (h.ob == 83) {
    const bool pulled = a.type == 3;
    h.code = pulled ? kOb83Removed : kOb83Inserted;
    h.incoming = pulled;
    set(m_pulled_alarm, key, pulled);
    if (!pulled) reparameterise(sys, a.station, static_cast<std::size_t>(module));
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, ", W#16#%04X, MDL_ADDR %u", static_cast<unsigned>(h.code),
                static_cast<unsigned>(h.mdl_addr));
  h.text += buf;
  // Both CPUs log it at receipt (the OB itself may be held until t5).
  log_on_powered(a.time, h.code, h.text);
}

void HSystemModel::on_diagnosis(std::size_t s, const redundancy::SystemDiagnosis& d) {
  const int sys = static_cast<int>(s);
  const redundancy::MasterSystem& ms = m_systems[s]->system();
  const int l = ms.master(0).has_slave(d.station) ? 0 : 1;
  if (!ms.master(l).has_slave(d.station)) return;
  const dp::Master& m = ms.master(l);
  const DiagView v = view(d.diag, m.slave_params(d.station).dpv1());
  const dp::MasterImage& img = m.image(d.station);
  auto event = [&](int module, bool incoming, bool stop, int ob = 82) {
    HSystemEvent h;
    h.time = d.time;
    h.original_time = d.time;
    h.ob = ob;
    h.code = ob == 83 ? (incoming ? kOb83Removed : kOb83Inserted)
                      : (incoming ? kOb82Incoming : kOb82Outgoing);
    h.incoming = incoming;
    h.source = HSystemEvent::Source::Diagnosis;
    h.system = sys;
    h.line = d.line;
    h.station = d.station;
    h.module = module;
    h.mdl_addr = module_address(sys, d.station, module);
    h.mdl_stop = stop;
    char buf[192];
    std::snprintf(buf, sizeof buf,
                  "OB %d W#16#%04X %s %s, DP master system %zu, station %u, %s, MDL_ADDR "
                  "%u, MDL_STOP %d",
                  ob, static_cast<unsigned>(h.code), ob == 83 ? "module" : "diagnosis", incoming ? "incoming" : "outgoing", s + 1,
                  static_cast<unsigned>(d.station),
                  module < 0 ? "station" : ("module " + std::to_string(module)).c_str(),
                  static_cast<unsigned>(h.mdl_addr), stop ? 1 : 0);
    h.text = buf;
    io_ob(std::move(h));
  };
  // Station level first (F15): the slave's CPU changed its operating mode.
  const auto skey = module_key(sys, d.station, 0xFFFF);
  if (v.stop != contains(m_stopped, skey)) {
    set(m_stopped, skey, v.stop);
    event(-1, v.stop, v.stop);
  }
  for (std::size_t mod = 0; mod < img.modules(); ++mod) {
    const dp::ModuleLayout& ml = img.module(mod);
    const auto key = module_key(sys, d.station, mod);
    const auto slot = static_cast<std::uint8_t>(mod + 1);
    const bool alarm = std::find(v.alarm_slots.begin(), v.alarm_slots.end(), slot) !=
                       v.alarm_slots.end();  // the alarm in this diagnosis is the module's OB
    // Pulled / plugged (DP-V1 Module_Status): OB 83 unless the pull/plug alarm is its OB.
    const bool pulled =
        std::find(v.no_module.begin(), v.no_module.end(), mod) != v.no_module.end();
    if (pulled != contains(m_pulled, key)) {
      set(m_pulled, key, pulled);
      if (!alarm) {
        event(static_cast<int>(mod), pulled, false, 83);
        if (!pulled) reparameterise(sys, d.station, mod);
      }
    }
    if (pulled) continue;  // a pulled module's identifier bit is OB 83's, not a fault
    bool faulty = std::find(v.faulty_modules.begin(), v.faulty_modules.end(), mod) !=
                  v.faulty_modules.end();
    for (std::size_t id : v.faulty_ids)
      if (id >= ml.first_id && id < ml.first_id + std::max<std::size_t>(ml.id_count, 1))
        faulty = true;
    if (faulty == contains(m_faulty, key)) continue;
    set(m_faulty, key, faulty);
    if (!alarm) event(static_cast<int>(mod), faulty, false);
  }
}

bool HSystemModel::set_module_parameters(std::size_t system, std::uint8_t station,
                                         std::size_t module, std::uint8_t index,
                                         std::vector<std::uint8_t> record) {
  if (system >= m_systems.size() || record.empty() || record.size() > 240 ||
      m_map.find(static_cast<int>(system), station, module) == nullptr)
    return false;
  const auto key = module_key(static_cast<int>(system), station, module);
  // One entry per (module, index): a module may have several records (S7 modules: 0 and 1).
  std::erase_if(m_module_prm, [&](const ModulePrm& p) { return p.key == key && p.index == index; });
  m_module_prm.push_back({key, index, std::move(record)});
  return true;
}

void HSystemModel::reparameterise(int system, std::uint8_t station, std::size_t module) {
  const auto key = module_key(system, station, module);
  for (const ModulePrm& p : m_module_prm) {
    if (p.key != key) continue;
    redundancy::MasterSystem& ms = m_systems[static_cast<std::size_t>(system)]->system();
    const auto slot = static_cast<std::uint8_t>(module + 1);
    if (ms.write(station, slot, p.index, p.record, [](const dp::AcyclicResult&) {},
                 m_sched.now()) != 0)
      ++m_reparams;
  }
}

void HSystemModel::direct_access(bus::Ticks now, std::vector<std::uint8_t>& pii) {
  for (std::size_t n = 0; n < m_direct.size(); ++n) {
    const CopyNetwork& c = m_direct[n];
    if (!c.direct) continue;
    for (int write = 0; write < 2; ++write) {
      const std::size_t from = write ? c.to_output : c.from_input;
      const std::size_t to = from + c.length;
      const HIoEntry* hit = nullptr;
      for (const HIoEntry& e : m_map.entries()) {
        const std::size_t a = write ? e.out_addr : e.in_addr;
        const std::size_t len = write ? e.out_len : e.in_len;
        if (len == 0 || a >= to || a + len <= from || module_reachable(e)) continue;
        if (hit == nullptr) hit = &e;
        if (!write)  // the value read is 0 (only where the module is missing)
          for (std::size_t i = std::max(a, from); i < std::min(a + len, to) && i < pii.size(); ++i)
            pii[i] = 0;
      }
      if (hit == nullptr) continue;
      ++m_access_errors;
      HSystemEvent h;
      h.time = now;
      h.original_time = now;
      h.ob = 122;
      h.code = write ? kOb122Write : kOb122Read;
      h.source = HSystemEvent::Source::Access;
      h.system = hit->system;
      h.station = hit->central ? static_cast<std::uint8_t>(hit->rack) : hit->address;
      h.module = static_cast<int>(hit->module);
      h.mdl_addr = static_cast<std::uint16_t>(from);
      char buf[192];
      if (hit->central)  // system -1, station = the rack number (as the rack's OB 86/85)
        std::snprintf(buf, sizeof buf,
                      "OB 122 W#16#%04X I/O access error %s, copy %zu, %s %zu, expansion rack %d, "
                      "module %zu",
                      static_cast<unsigned>(h.code), write ? "writing" : "reading", n,
                      write ? "PQB" : "PIB", from, hit->rack, hit->module);
      else
        std::snprintf(buf, sizeof buf,
                      "OB 122 W#16#%04X I/O access error %s, copy %zu, %s %zu, DP master system "
                      "%d, station %u, module %zu",
                      static_cast<unsigned>(h.code), write ? "writing" : "reading", n,
                      write ? "PQB" : "PIB", from, hit->system + 1,
                      static_cast<unsigned>(hit->address), hit->module);
      h.text = buf;
      io_ob(std::move(h));
    }
  }
}

}  // namespace pbvbus::devices
