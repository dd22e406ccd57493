// Names and the one-line text of the redundant-I/O events (h_redundant_io_events.hpp).
#include "pbvbus/s7h/h_redundant_io_events.hpp"

#include <cstdio>

#include "pbvbus/s7h/h_redundant_io.hpp"

namespace pbvbus::devices {

std::string_view to_string(RedIoKind k) {
  switch (k) {
    case RedIoKind::DI: return "DI";
    case RedIoKind::AI: return "AI";
    case RedIoKind::DO: return "DO";
    case RedIoKind::AO: return "AO";
  }
  return "?";
}

std::string_view to_string(RedIoCause c) {
  switch (c) {
    case RedIoCause::None: return "none";
    case RedIoCause::DiDiscrepancy: return "DI discrepancy";
    case RedIoCause::AiDiscrepancy: return "AI discrepancy";
    case RedIoCause::Ob82: return "OB 82";
    case RedIoCause::Ob85: return "OB 85";
    case RedIoCause::Overflow: return "overflow";
  }
  return "?";
}

std::string_view to_string(DepassivationTrigger t) {
  switch (t) {
    case DepassivationTrigger::Startup: return "start-up (OB 100)";
    case DepassivationTrigger::Redundant: return "Redundant mode (OB 72)";
    case DepassivationTrigger::Modification: return "change in operation";
    case DepassivationTrigger::Fc451: return "FC 451 RED_DEPA";
  }
  return "?";
}

std::string describe(const RedIoEvent& e) {
  char head[64];
  std::snprintf(head, sizeof head, "W#16#%04X redundant %s pair %zu: ", e.code,
                std::string(to_string(e.kind)).c_str(), e.pair);
  const bool input = e.kind == RedIoKind::DI || e.kind == RedIoKind::AI;
  const char* area = input ? "IB" : "QB";
  const char* mod = e.module == 0 ? "module_L" : "module_H";
  char body[160];
  switch (e.code) {
    case kRedIoDiDiscrepancy:
      std::snprintf(body, sizeof body,
                    "discrepancy time at digital input expired, error not yet localized "
                    "(IB %u bit %u)",
                    e.address + e.bit / 8, e.bit % 8);
      break;
    case kRedIoDepassivated:
      std::snprintf(body, sizeof body, "depassivation completed, %u module(s) depassivated",
                    e.count);
      return std::string(head, 10) + "redundant I/O: " + body;
    case kRedIoDiPassivated:
      std::snprintf(body, sizeof body, "%s (%s %u) passivated: no signal change (bit %u)", mod,
                    area, e.address, e.bit);
      break;
    case kRedIoAiPassivated:
      std::snprintf(body, sizeof body,
                    "%s (%s %u) passivated: channel %u outside the tolerance window", mod, area,
                    e.address, e.bit);
      break;
    default:
      std::snprintf(body, sizeof body, "%s (%s %u) passivated (%s)", mod, area, e.address,
                    e.code == kRedIoOb82Passivated   ? "OB 82 diagnostic interrupt"
                    : e.code == kRedIoOb85Passivated ? "OB 85 access error"
                    : e.code == kRedIoOverflowPassivated ? "overflow/underflow"
                                                         : "?");
      break;
  }
  return std::string(head) + body;
}

}  // namespace pbvbus::devices
