// Names of the pair's enumerations (hsby_pair.hpp), as the seed's panels and manuals write them.
#include "pbvbus/quantum/hsby_pair.hpp"

namespace pbvbus::quantum {

std::string_view to_string(CpuState s) {
  switch (s) {
    case CpuState::Off:
      return "off";
    case CpuState::Offline:
      return "offline";
    case CpuState::Primary:
      return "primary";
    case CpuState::Standby:
      return "standby";
  }
  return "?";
}

std::string_view to_string(KeySwitch k) {
  switch (k) {
    case KeySwitch::OffLine:
      return "Off Line";
    case KeySwitch::Xfer:
      return "Xfer";
    case KeySwitch::Run:
      return "Run";
  }
  return "?";
}

std::string_view to_string(Designation d) {
  return d == Designation::A ? "A" : "B";
}

std::string_view to_string(FibreState f) {
  switch (f) {
    case FibreState::Ok:
      return "ok";
    case FibreState::TxRxNotCrossed:
      return "Tx/Rx not crossed";
    case FibreState::Cut:
      return "cut";
  }
  return "?";
}

std::string_view to_string(Led l) {
  switch (l) {
    case Led::Off:
      return "off";
    case Led::On:
      return "on";
    case Led::Blinking:
      return "blinking";
  }
  return "?";
}

std::string_view to_string(SwitchoverCause c) {
  switch (c) {
    case SwitchoverCause::PrimaryPowerOff:
      return "primary power off";
    case SwitchoverCause::PrimaryCpuStop:
      return "primary CPU stop";
    case SwitchoverCause::LinkSilent:
      return "fibre and line silent";
    case SwitchoverCause::KeyOffLine:
      return "primary key to Off Line";
    case SwitchoverCause::CommandRegister:
      return "command register run bit 0";
  }
  return "?";
}

std::string_view to_string(PairEventKind k) {
  switch (k) {
    case PairEventKind::Power:
      return "power";
    case PairEventKind::Key:
      return "key";
    case PairEventKind::State:
      return "state";
    case PairEventKind::Switchover:
      return "switchover";
    case PairEventKind::TransferLost:
      return "transfer lost";
    case PairEventKind::LogicMismatch:
      return "logic mismatch";
    case PairEventKind::DuplicateDesignation:
      return "duplicate designation";
    case PairEventKind::Fibre:
      return "fibre";
    case PairEventKind::Update:
      return "update";
    case PairEventKind::Override:
      return "override";
    case PairEventKind::Cpu:
      return "cpu";
    case PairEventKind::Ignored:
      return "ignored";
  }
  return "?";
}

}  // namespace pbvbus::quantum
