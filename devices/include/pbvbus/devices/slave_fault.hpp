#pragma once
// Faults a scenario can inflict on a simulated DP slave (slave_model.hpp; protocol-facts.md §D.5
// diagnosis blocks, §E.5 DP-V1 alarms). Each fault is a step; the clearing steps are separate
// kinds so that a scenario is a plain list of (time, step).

#include <cstdint>
#include <string_view>
#include <vector>

#include "pbvbus/dp/diagnosis.hpp"

namespace pbvbus::devices {

struct SlaveFault {
  enum class Kind : std::uint8_t {
    Mute,               ///< stops answering (deaf and silent)
    Unmute,
    ChannelDiagAppears,     ///< channel diagnosis on `module`/`channel`
    ChannelDiagDisappears,  ///< the same diagnosis goes away
    ModulePulled,
    ModulePlugged,
    ProcessAlarm,       ///< DP-V1 process alarm for `module`'s slot with `data`
  };
  Kind kind = Kind::Mute;
  std::size_t module = 0;   ///< 0-based module index of the slave's module list
  std::uint8_t channel = 0;  ///< 0..63
  dp::ChannelDirection direction = dp::ChannelDirection::Input;
  dp::ChannelType type = dp::ChannelType::Bit;
  std::uint8_t error = static_cast<std::uint8_t>(dp::ChannelError::ShortCircuit);  ///< 1..31
  bool alarm = false;  ///< channel diag: also a DP-V1 Diagnostic alarm
  std::vector<std::uint8_t> data;  ///< process alarm data (at most 59 octets)

  static SlaveFault of(Kind k, std::size_t m = 0) {
    SlaveFault f;
    f.kind = k;
    f.module = m;
    return f;
  }
  static SlaveFault mute() { return of(Kind::Mute); }
  static SlaveFault unmute() { return of(Kind::Unmute); }
  static SlaveFault channel_diag(std::size_t module, std::uint8_t channel, dp::ChannelError e,
                                 dp::ChannelType t = dp::ChannelType::Bit,
                                 dp::ChannelDirection d = dp::ChannelDirection::Input,
                                 bool appears = true) {
    SlaveFault f;
    f.kind = appears ? Kind::ChannelDiagAppears : Kind::ChannelDiagDisappears;
    f.module = module;
    f.channel = channel;
    f.error = static_cast<std::uint8_t>(e);
    f.type = t;
    f.direction = d;
    return f;
  }
  static SlaveFault pulled(std::size_t module) { return of(Kind::ModulePulled, module); }
  static SlaveFault plugged(std::size_t module) { return of(Kind::ModulePlugged, module); }
  static SlaveFault process_alarm(std::size_t module, std::vector<std::uint8_t> d) {
    SlaveFault f;
    f.kind = Kind::ProcessAlarm;
    f.module = module;
    f.data = std::move(d);
    return f;
  }
};

std::string_view to_string(SlaveFault::Kind k);

}  // namespace pbvbus::devices
