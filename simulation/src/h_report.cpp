// The H-system part of the report (h_report.hpp).
#include "pbvbus/simulation/h_report.hpp"

#include <cstdio>
#include <sstream>

#include "pbvbus/captures/cpu_event.hpp"

namespace pbvbus::tools {

namespace {

using devices::CpuRole;
using devices::CpuState;
using devices::HEvent;
using devices::HProfile;
using devices::Redf;
using devices::SystemMode;

// The capture encoding (captures/cpu_event.hpp) names the devices enums by number.
static_assert(static_cast<int>(HEvent::Kind::State) == static_cast<int>(captures::CpuEventKind::State));
static_assert(static_cast<int>(HEvent::Kind::Role) == static_cast<int>(captures::CpuEventKind::Role));
static_assert(static_cast<int>(HEvent::Kind::SystemMode) ==
              static_cast<int>(captures::CpuEventKind::SystemMode));
static_assert(static_cast<int>(HEvent::Kind::Ob) == static_cast<int>(captures::CpuEventKind::Ob));
static_assert(static_cast<int>(CpuRole::Master) == 1 && static_cast<int>(CpuRole::Standby) == 2);
static_assert(static_cast<int>(CpuState::Stop) == 1 && static_cast<int>(CpuState::SyncUp) == 9);
static_assert(static_cast<int>(SystemMode::Solo) == 2 && static_cast<int>(SystemMode::SyncUp) == 7);
static_assert(static_cast<int>(devices::HReason::LinkLost) == 5 &&
              static_cast<int>(devices::HReason::MasterSwap) == 8);

/// The REDF LED as HCpuPair::leds() derives it, from the pair's mode (h_report.hpp).
Redf redf_of(bool powered, SystemMode m) {
  if (!powered) return Redf::Off;
  switch (m) {
    case SystemMode::LinkUp:
    case SystemMode::SyncUp: return Redf::Flash0_5Hz;
    case SystemMode::Update: return Redf::Flash2Hz;
    case SystemMode::Redundant: return Redf::Off;
    default: return Redf::On;
  }
}

std::string hex16(std::uint16_t v) {
  char b[16];
  std::snprintf(b, sizeof b, "W#16#%04X", static_cast<unsigned>(v));
  return b;
}

}  // namespace

std::string h_event_text(const HEvent& e, HProfile p) {
  const std::string cpu = "CPU " + std::to_string(e.rack) + ": ";
  switch (e.kind) {
    case HEvent::Kind::State:
      return cpu + std::string(devices::to_string(e.from_state)) + " -> " +
             std::string(devices::to_string(e.to_state));
    case HEvent::Kind::Role:
      return cpu + "role " + std::string(devices::to_string(e.from_role, p)) + " -> " +
             std::string(devices::to_string(e.role, p));
    case HEvent::Kind::SystemMode:
      return "system mode " + std::string(devices::to_string(e.from_mode, p)) + " -> " +
             std::string(devices::to_string(e.to_mode, p));
    case HEvent::Kind::Ob: {
      std::string s = cpu + "OB " + std::to_string(e.ob);
      if (e.code != 0) s += " " + hex16(e.code);
      if (e.reason != devices::HReason::None) s += " (" + std::string(devices::to_string(e.reason)) + ")";
      return s;
    }
  }
  return cpu;
}

captures::EventRecord h_event_record(const HEvent& e, HProfile p, std::string_view system) {
  captures::CpuEventFields f;
  f.kind = static_cast<captures::CpuEventKind>(e.kind);
  f.rack = e.rack;
  f.role = static_cast<int>(e.role);
  f.event_id = e.code;
  switch (e.kind) {
    case HEvent::Kind::State:
      f.from = static_cast<std::uint8_t>(e.from_state);
      f.to = static_cast<std::uint8_t>(e.to_state);
      break;
    case HEvent::Kind::Role:
      f.from = static_cast<std::uint8_t>(e.from_role);
      f.to = static_cast<std::uint8_t>(e.role);
      break;
    case HEvent::Kind::SystemMode:
      f.from = static_cast<std::uint8_t>(e.from_mode);
      f.to = static_cast<std::uint8_t>(e.to_mode);
      break;
    case HEvent::Kind::Ob:
      f.ob = static_cast<std::uint8_t>(e.ob);
      f.reason = static_cast<std::uint8_t>(e.reason);
      break;
  }
  f.text = system.empty() ? h_event_text(e, p) : std::string(system) + ": " + h_event_text(e, p);
  return captures::cpu_event_record(f);
}

HSystemReport make_h_report(std::string name, const devices::HCpuPair& pair) {
  HSystemReport r;
  r.name = std::move(name);
  r.profile = pair.params().profile;
  r.mode = pair.system_mode();
  for (int k = 0; k < 2; ++k) {
    HCpuReport& c = r.cpus[static_cast<std::size_t>(k)];
    c.rack = k;
    c.state = pair.state(k);
    c.role = pair.role(k);
    c.mode = pair.system_mode(k);
    c.leds = pair.leds(k);
    c.diag.assign(pair.diag_buffer(k).begin(), pair.diag_buffer(k).end());
  }
  // Replay the events: what holds after each one.
  std::array<CpuState, 2> state{CpuState::Off, CpuState::Off};
  std::array<CpuRole, 2> role{CpuRole::None, CpuRole::None};
  SystemMode mode = SystemMode::Stop;
  std::array<std::optional<HUpdateWindow>, 2> open;
  auto row = [&](int k, const HEvent& e) {
    HTimelineRow t;
    t.at = e.at;
    t.kind = e.kind;
    t.change = h_event_text(e, r.profile);
    const auto ku = static_cast<std::size_t>(k);
    t.state = state[ku];
    t.role = role[ku];
    t.mode = mode;
    const bool powered = state[ku] != CpuState::Off;
    t.redf = redf_of(powered, mode);
    t.mstr = powered && role[ku] == CpuRole::Master;
    if (e.kind == HEvent::Kind::Ob && e.rack == k) {
      t.ob = e.ob;
      t.code = e.code;
      t.reason = e.reason;
    }
    r.cpus[ku].timeline.push_back(std::move(t));
  };
  for (const HEvent& e : pair.events()) {
    const int k = e.rack == 1 ? 1 : 0;
    const auto ku = static_cast<std::size_t>(k);
    switch (e.kind) {
      case HEvent::Kind::State: {
        state[ku] = e.to_state;
        role[ku] = e.role;
        const bool updating = e.to_state == CpuState::Update ||
                              (e.to_state == CpuState::SyncUp && e.role == CpuRole::Standby);
        if (updating && !open[ku]) {
          HUpdateWindow w;
          w.rack = k;
          w.t1 = e.at;
          open[ku] = w;
        } else if (open[ku] && !updating) {
          HUpdateWindow w = *open[ku];
          w.t5 = e.at;
          w.completed = e.to_state == CpuState::Run;
          r.updates.push_back(w);
          open[ku].reset();
        }
        row(k, e);
        break;
      }
      case HEvent::Kind::Role:
        role[ku] = e.role;
        row(k, e);
        break;
      case HEvent::Kind::SystemMode:
        mode = e.to_mode;
        row(0, e);
        row(1, e);
        break;
      case HEvent::Kind::Ob:
        role[ku] = e.role;
        row(k, e);
        break;
    }
  }
  return r;
}

}  // namespace pbvbus::tools
