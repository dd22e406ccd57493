#pragma once
// The H-system part of a run's report (docs/h-system.md; docs/h-scenarios.md): per
// simulated CPU pair the final state, role and LEDs of each CPU and its diagnostic buffer, a
// timeline per CPU, the I/O events (OB 70/85/86... filled by the H-system runtime) and the
// measured update windows beside the planned T_P15 / T_PH; as text for a commissioning
// engineer and as JSON; and the capture's event records for the pair's events.
//
// Decisions:
// - A timeline row is one event of devices::HCpuPair: a state or role change or an OB of that
//   CPU, or a change of the pair's system mode (in both CPUs' tables). Each row shows what holds
//   after the event: the CPU's state and role, the pair's system mode (HCpuPair::system_mode(),
//   the master's view), REDF and MSTR derived from them as HCpuPair::leds() does (REDF from the
//   pair's mode for a powered CPU: 0.5 Hz Link-up/SYNCUP, 2 Hz Update, off Redundant, on
//   otherwise; dark when off; MSTR = powered master). The final LEDs are the pair's own.
// - Times: text in s with ms ("12.345"); JSON in ns (exact, bus::ticks_to_ns) and ms (three
//   decimals, i.e. µs resolution, as a JSON number).
// - An update window: t1 = the standby enters UPDATE (SYNCUP in the 1500 profile; the cycle
//   extension starts), t5 = it reaches RUN (Redundant or the swap) or the update ends without
//   it (aborted). t3 (T_P15 starts) and t4 (T_PH starts) are filled by the H-system runtime
//   once the update has phases; until then they are absent and the windows are "not measured".
//   Verdict: the measured window t5 - t3 (t5 - t4) is "within" when it is not longer than the
//   planned T_P15 (T_PH), else "EXCEEDED" (the update's monitoring would abort it).
// - JSON: the report part is `"h_systems_run":[...]` (one object per pair), keys in a fixed
//   order, enum values as the names to_string() gives in the 400H profile (stable keys), the
//   profile's own names in the text.
// - Capture records (EventCategory::Cpu, captures/cpu_event.hpp): code = HEvent::Kind, a = rack,
//   b = role after the event, value = S7 event ID | OB << 16 | reason << 24 | to << 32 |
//   from << 40; text as in the timeline ("CPU 0: STOP -> STARTUP").
#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::tools {

struct HTimelineRow {
  bus::Ticks at = 0;
  devices::HEvent::Kind kind = devices::HEvent::Kind::State;
  std::string change;  ///< h_event_text(): "CPU 0: STOP -> STARTUP", "system mode Solo -> Link-up"
  // What holds after the event:
  devices::CpuState state = devices::CpuState::Off;
  devices::CpuRole role = devices::CpuRole::None;
  devices::SystemMode mode = devices::SystemMode::Stop;
  devices::Redf redf = devices::Redf::Off;
  bool mstr = false;
  int ob = 0;              ///< Kind::Ob: 72, 121
  std::uint16_t code = 0;  ///< S7 event ID, 0 = none given
  devices::HReason reason = devices::HReason::None;
};

struct HCpuReport {
  int rack = 0;
  devices::CpuState state = devices::CpuState::Off;
  devices::CpuRole role = devices::CpuRole::None;
  devices::SystemMode mode = devices::SystemMode::Stop;  ///< as this CPU sees it
  devices::CpuLeds leds;
  /// BUS1F, BUS2F, ... per driven DP master system ("off", "on", "flashing"; devices::BusLed),
  /// filled by the runtime; empty without one.
  std::vector<std::string> busf;
  /// Merged with the I/O events' entries by the runtime (HSystemModel::diag_buffer).
  std::vector<devices::DiagEntry> diag;
  std::vector<HTimelineRow> timeline;
};

/// An I/O event of the pair (OB 70, OB 85, OB 86 ... with its event ID); the runtime fills them.
struct HIoEvent {
  bus::Ticks at = 0;
  std::vector<int> racks;  ///< the CPUs on which the OB ran
  int ob = 0;
  std::uint16_t code = 0;
  std::string text;
  /// OB 82/83/122 (F3/F15): OB8x_MDL_ADDR / OB122_MEM_ADDR and OB82_MDL_STOP (JSON only for
  /// these OBs; the text names them too).
  std::optional<std::uint16_t> mdl_addr;
  bool mdl_stop = false;
};

struct HUpdateWindow {
  int rack = 0;  ///< the CPU being updated
  bus::Ticks t1 = 0;
  std::optional<bus::Ticks> t3, t4;
  bus::Ticks t5 = 0;
  bool completed = true;  ///< false: the update ended without RUN (aborted)
  /// Measured by the runtime from the program: the last OB 1 (with its I/O update) before t3
  /// and the first one after t5. Their distance is the gap the process sees; it is at most
  /// the no-I/O window + one scan time (the last scan before t3 started up to one scan time
  /// before it; the first one after runs at t5 itself).
  std::optional<bus::Ticks> last_io_before, first_io_after;
  bus::Ticks scan_time = 0;
};

/// One slave module in the process images (devices::HIoMap): where its inputs and outputs are.
struct HIoMapRow {
  std::uint8_t address = 0;
  std::size_t module = 0;
  std::size_t in_addr = 0, in_len = 0;
  std::size_t out_addr = 0, out_len = 0;
  int rack = 0;  ///< a central module (F8): its expansion rack number; 0 = a DP slave's module
};
/// An expansion rack (F8) at the end of the run: its state and its modules' outputs.
struct HRackReport {
  int number = 0;
  int side = 0;  ///< the CPU it hangs on
  bool on = true;
  bool reachable = false;  ///< on and its CPU runs the program
  bool ob85 = false;       ///< an OB 85 episode is open
  struct Module {
    std::string name;
    std::vector<std::uint8_t> outputs;  ///< as the last OB 1 that reached the rack wrote them
  };
  std::vector<Module> modules;
};

// ---- F4 connections: one configured S7 connection at the end of the run ----
struct HConnectionRow {
  std::string name;
  std::string kind;    ///< "standard" / "fault-tolerant"
  std::string state;   ///< "configured" / "established" / "lost"
  std::string active;  ///< "CP 443-1 rack 0 CP 0", "" unless established
  std::vector<std::pair<bus::Ticks, std::string>> events;  ///< established, switched, lost ...
};

struct HSystemReport {
  std::string name;
  devices::HProfile profile = devices::HProfile::S7_400H;
  devices::SystemMode mode = devices::SystemMode::Stop;  ///< the pair's final system mode
  std::array<HCpuReport, 2> cpus;
  std::vector<HIoEvent> io_events;
  std::vector<HUpdateWindow> updates;
  /// The planned T_P15 and T_PH (h_update_timing), set by the owner that has the plan.
  std::optional<bus::Ticks> planned_t_p15, planned_t_ph;
  /// The scenario's H faults and repairs as applied (time, text), filled by the runtime.
  std::vector<std::pair<bus::Ticks, std::string>> faults;
  /// The process-image map of the driven DP master systems, filled by the runtime.
  std::vector<HIoMapRow> io_map;
  /// F4 connections: the configured S7 connections (h_system cp/connection), by the runtime.
  std::vector<HConnectionRow> connections;
  /// F8 expansion racks, OB 80 (filled by the runtime; JSON keys only when there are racks).
  std::vector<HRackReport> racks;
  std::uint64_t ob80 = 0;  ///< OB 80 calls (the events are in io_events)
};

/// Everything the pair knows: final states, LEDs, buffers, the timeline from its events and
/// the update windows (t1, t5).
HSystemReport make_h_report(std::string name, const devices::HCpuPair& pair);

// Text and JSON forms, window_verdict, format_s_ms: pbvbus/reports/h_report.hpp.

/// The one-line text of an event as the timeline and the capture show it: "CPU 0: STOP ->
/// STARTUP", "CPU 1: role none -> standby", "system mode Solo -> Link-up", "CPU 1: OB 72
/// (master CPU lost)" (the why of a state change is in the diagnostic buffer, not the event).
std::string h_event_text(const devices::HEvent& e, devices::HProfile p);
/// The capture record of one pair event (EventCategory::Cpu; encoding in captures/cpu_event.hpp).
/// `system` prefixes the text when not empty ("H-CPU: CPU 0: ...").
captures::EventRecord h_event_record(const devices::HEvent& e, devices::HProfile p,
                                     std::string_view system = {});

}  // namespace pbvbus::tools
