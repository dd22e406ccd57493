// Fault steps of simulated DP slaves (slave_fault.hpp).
#include "pbvbus/slaves/slave_fault.hpp"

namespace pbvbus::devices {

std::string_view to_string(SlaveFault::Kind k) {
  switch (k) {
    case SlaveFault::Kind::Mute: return "mute";
    case SlaveFault::Kind::Unmute: return "unmute";
    case SlaveFault::Kind::ChannelDiagAppears: return "channel diagnosis appears";
    case SlaveFault::Kind::ChannelDiagDisappears: return "channel diagnosis disappears";
    case SlaveFault::Kind::ModulePulled: return "module pulled";
    case SlaveFault::Kind::ModulePlugged: return "module plugged";
    case SlaveFault::Kind::ProcessAlarm: return "process alarm";
    case SlaveFault::Kind::SlaveStop: return "slave STOP";
    case SlaveFault::Kind::SlaveRun: return "slave RUN";
  }
  return "?";
}

}  // namespace pbvbus::devices
