// Quantum Hot Standby pair events in captures (hsby_event.hpp).
#include "pbvbus/captures/hsby_event.hpp"

namespace pbvbus::captures {

std::string hsby_kind_name(int kind) {
  static const char* const kNames[kHsbyEventKinds] = {
      "power", "key",    "state",    "switchover", "transfer lost", "logic mismatch",
      "duplicate designation", "fibre", "update", "override", "cpu", "ignored"};
  if (kind >= 0 && kind < kHsbyEventKinds) return kNames[kind];
  return "kind " + std::to_string(kind);
}

std::string hsby_state_name(int state) {
  static const char* const kNames[kHsbyRackStates] = {"off", "offline", "primary", "standby"};
  if (state == -1) return "none";
  if (state >= 0 && state < kHsbyRackStates) return kNames[state];
  return "state " + std::to_string(state);
}

EventRecord hsby_event_record(const HsbyEventFields& f) {
  EventRecord r;
  r.category = EventCategory::Hsby;
  r.code = static_cast<std::uint16_t>(f.kind);
  r.line = -1;
  r.a = f.rack;
  r.b = f.state;
  r.value = f.takeover_ns;
  r.text = f.text;
  return r;
}

std::optional<HsbyEventFields> hsby_event_fields(const EventRecord& r) {
  if (r.category != EventCategory::Hsby || r.code >= kHsbyEventKinds) return std::nullopt;
  HsbyEventFields f;
  f.kind = static_cast<HsbyEventKind>(r.code);
  f.rack = r.a;
  f.state = r.b;
  f.takeover_ns = r.value;
  f.text = r.text;
  return f;
}

std::string hsby_pair_name(const std::string& text, int rack) {
  if (rack < 0) {
    const auto p = text.find(": ");
    return p == std::string::npos ? std::string() : text.substr(0, p);
  }
  const std::string who = "rack " + std::to_string(rack) + ": ";
  if (text.compare(0, who.size(), who) == 0) return "";
  const auto p = text.find(": " + who);
  return p == std::string::npos ? std::string() : text.substr(0, p);
}

}  // namespace pbvbus::captures
