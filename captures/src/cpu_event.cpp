// H-system CPU events in captures (cpu_event.hpp).
#include "pbvbus/captures/cpu_event.hpp"

namespace pbvbus::captures {

namespace {
std::string name_of(int v, const char* const* names, int count, const char* what) {
  if (v >= 0 && v < count) return names[v];
  return std::string(what) + " " + std::to_string(v);
}
}  // namespace

std::string cpu_state_name(int state) {
  static const char* const kNames[] = {"OFF",  "STOP", "STARTUP",      "RUN",       "LINK-UP",
                                       "UPDATE", "HOLD", "ERROR-SEARCH", "DEFECTIVE", "SYNCUP"};
  return name_of(state, kNames, 10, "state");
}

std::string cpu_role_name(int role) {
  static const char* const kNames[] = {"none", "master", "standby"};
  return name_of(role, kNames, 3, "role");
}

std::string cpu_system_mode_name(int mode) {
  static const char* const kNames[] = {"Stop",   "Startup",   "Solo", "Link-up",
                                       "Update", "Redundant", "Hold", "SYNCUP"};
  return name_of(mode, kNames, 8, "mode");
}

EventRecord cpu_event_record(const CpuEventFields& f) {
  EventRecord r;
  r.category = EventCategory::Cpu;
  r.code = static_cast<std::uint16_t>(f.kind);
  r.line = -1;
  r.a = f.rack;
  r.b = f.role;
  r.value = std::uint64_t{f.event_id} | std::uint64_t{f.ob} << 16 | std::uint64_t{f.reason} << 24 |
            std::uint64_t{f.to} << 32 | std::uint64_t{f.from} << 40;
  r.text = f.text;
  return r;
}

std::optional<CpuEventFields> cpu_event_fields(const EventRecord& r) {
  if (r.category != EventCategory::Cpu || r.code > static_cast<std::uint16_t>(CpuEventKind::Ob))
    return std::nullopt;
  CpuEventFields f;
  f.kind = static_cast<CpuEventKind>(r.code);
  f.rack = r.a;
  f.role = r.b;
  f.event_id = static_cast<std::uint16_t>(r.value & 0xFFFFU);
  f.ob = static_cast<std::uint8_t>((r.value >> 16) & 0xFFU);
  f.reason = static_cast<std::uint8_t>((r.value >> 24) & 0xFFU);
  f.to = static_cast<std::uint8_t>((r.value >> 32) & 0xFFU);
  f.from = static_cast<std::uint8_t>((r.value >> 40) & 0xFFU);
  f.text = r.text;
  return f;
}

}  // namespace pbvbus::captures
