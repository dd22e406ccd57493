#include "pbvbus/bus/tap.hpp"

namespace pbvbus::bus {

std::string_view to_string(LineEventKind k) {
  switch (k) {
    case LineEventKind::CableCut: return "cable cut";
    case LineEventKind::CableRepaired: return "cable repaired";
    case LineEventKind::ShortCircuit: return "short circuit";
    case LineEventKind::ShortRepaired: return "short circuit repaired";
    case LineEventKind::NoiseOn: return "noise on";
    case LineEventKind::NoiseOff: return "noise off";
    case LineEventKind::PowerOff: return "power off";
    case LineEventKind::PowerOn: return "power on";
    case LineEventKind::TransceiverFailed: return "transceiver failed";
    case LineEventKind::TransceiverRepaired: return "transceiver repaired";
    case LineEventKind::BabbleOn: return "babbling transmitter";
    case LineEventKind::BabbleOff: return "babbling stopped";
  }
  return "?";
}

}  // namespace pbvbus::bus
