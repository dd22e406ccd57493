#pragma once
// Where `pbvbus run --capture` listens (design.md "Captures"; bus/line.hpp "probe taps").
//
// A capture is what an analyzer clipped onto the cable at one point sees. Each line is captured
// at one or more probe positions, each next to a station:
//  - the scenario's `capture { line: "A" at: 14 }` entries, in file order (PlanLine::probes);
//    an entry without `at` stands for the default position;
//  - every line without an entry gets one probe at the default position.
// The default position is the line's first station in cable order; `pbvbus run --probe
// first|last|ADDR` picks another (ADDR: the station with that FDL address, which every line
// taking the default must have, else the run is refused).
//
// Interfaces: one pcapng interface per probe, in line order and, within a line, in the order of
// the capture entries. A line with one probe keeps the line's name ("A"); with several each is
// named "LINE@ADDR" ("A@1", "A@14"). The description says where the probe is: "PROFIBUS-DP
// 1.5 Mbit/s, probe at station 14". A line without stations has nothing to listen to: it gets a
// bare interface (named after the line) and no tap, so that interface ids stay in line order.
// A default that falls on the position of an explicit probe of the same line is not doubled.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::captures {
class PcapngWriter;
}

namespace pbvbus::tools {

/// The default probe position (pbvbus run --probe).
struct ProbeDefault {
  enum class Kind : std::uint8_t { First, Last, Address };
  Kind kind = Kind::First;
  std::uint8_t address = 0;  ///< Kind::Address
};
/// "first", "last" or an FDL address 0..126; nullopt for anything else.
std::optional<ProbeDefault> parse_probe_default(std::string_view text);

/// One probe of a run's capture.
struct CaptureProbe {
  std::size_t line = 0;          ///< index into ScenarioPlan::lines
  bus::AttachmentId position = 0;  ///< cable position (Simulation attaches in plan order)
  std::string name;              ///< pcapng if_name
  std::string where;             ///< "station 14" (for if_description "..., probe at station 14")
};

/// Every probe of the run, in interface order. nullopt with the reason in `error` if the default
/// cannot be placed on a line that takes it (--probe 14 and a line without station 14).
std::optional<std::vector<CaptureProbe>> plan_capture_probes(const ScenarioPlan& plan,
                                                             const ProbeDefault& def,
                                                             std::string* error = nullptr);

/// Declares line `li`'s interfaces on `writer` and puts its probes on `line`.
void attach_capture(captures::PcapngWriter& writer, bus::Line& line, std::size_t li,
                    const std::vector<CaptureProbe>& probes);

}  // namespace pbvbus::tools
