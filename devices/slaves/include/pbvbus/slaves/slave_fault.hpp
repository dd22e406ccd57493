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
    /// F15: an intelligent slave's own CPU goes to STOP / back to RUN (slave_model.hpp has the
    /// wire behaviour: data exchange goes on, inputs 0, S7 diagnostic record 0 with MDL_STOP).
    SlaveStop,
    SlaveRun,
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
  static SlaveFault slave_stop() { return of(Kind::SlaveStop); }
  static SlaveFault slave_run() { return of(Kind::SlaveRun); }
  static SlaveFault process_alarm(std::size_t module, std::vector<std::uint8_t> d) {
    SlaveFault f;
    f.kind = Kind::ProcessAlarm;
    f.module = module;
    f.data = std::move(d);
    return f;
  }
};

std::string_view to_string(SlaveFault::Kind k);

/// S7 diagnostic data record 0 (4 octets, the OB 82 start information bytes 8..11; "System
/// Software for S7-300/400", OB 82 local data): octet 0 bit 0 MDL_DEFECT (module fault), octet 2
/// bit 2 MDL_STOP (operating mode STOP). An intelligent slave in STOP reports {01 00 04 00}.
inline constexpr std::uint8_t kS7Rec0ModuleFault = 0x01;  ///< octet 0
inline constexpr std::uint8_t kS7Rec0MdlStop = 0x04;      ///< octet 2
inline constexpr std::size_t kS7Rec0MdlStopOctet = 2;
/// DP-V1 status type of the record as a status PDU (Status_Message, protocol-facts §E).
inline constexpr std::uint8_t kStatusMessage = 0x81;

}  // namespace pbvbus::devices
