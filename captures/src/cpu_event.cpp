// H-system CPU events in captures (cpu_event.hpp).
#include "pbvbus/captures/cpu_event.hpp"

namespace pbvbus::captures {

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
