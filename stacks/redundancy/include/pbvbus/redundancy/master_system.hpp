#pragma once
// The redundant DP master system (seeds-digest.md §2, §7 F9–F14, F24; protocol-facts.md §G;
// docs/redundancy.md): two DP masters class 1, one per line (line 0 = A, line 1 = B), configured as ONE
// logical master system with the same slave addresses. Together they parameterise every
// switched station on both lines, choose its active channel with PrmCmd Primary_Request,
// supervise both channels and switch over: per station when the active interface or its path
// fails, for every station at once when a whole line is lost. One-sided slaves on either line
// are plain DP slaves of that line's master.
//
// assumption: PI 2.212 System Redundancy on the wire (the Siemens H master's protocol is not
// public). Sans-I/O: the owner forwards each master's events (on_master_event), tells it when a
// whole line is lost or back (line_lost/line_back: the transceiver's read-back sees a short
// circuit, the master was stopped or failed) and calls on_time() at next_deadline() (or more
// often). It never touches the lines; what goes on the wire is the dp::Masters'.
//
// Decisions (docs/redundancy.md, "The redundant DP master system"):
// - A channel is UP from the master's DataExchangeEntered and DOWN from its StationFailure
//   (the master's own failure detection: no response after the retries, or leaving data
//   exchange). The active channel is what the station says: the Red_State_1 Primary bit of the
//   Red_Status block in that line's diagnosis (read at start-up and after every DH).
// - Start-up: line `preferred`'s Set_Prm carries Primary_Request, the other's does not. A
//   channel that reaches data exchange while the station has no primary on an UP channel and
//   no switchover under way gets Primary_Request (the preferred line is missing).
// - Station-level switchover: the active channel goes DOWN while the other is UP → Primary_
//   Request on the other line at once (a pure PrmCmd as that slave's next request), and the
//   stored Set_Prm of the failed line loses its Primary_Request, so a later re-start-up there
//   never steals the primary role back (no switch back). OB 70 W#16#73A3 at the failure, on
//   the failed channel's line. The passive channel going DOWN: 73A3, no switchover.
// - Repair: the DOWN channel reaching data exchange again while the other is UP → OB 70
//   W#16#72A3; the active channel stays.
// - Both channels DOWN → OB 86 W#16#39C4 (once), on the line that failed last; the first
//   channel back → W#16#38C4 (the station runs without redundancy: 72A3 when the second one
//   comes). At start-up a channel that never reached data exchange counts as DOWN once its
//   master reports it absent: one channel missing → 73A3 when the other comes up, both → 39C4.
// - Switchover supervision (F24): after a Primary_Request the station must show Primary on the
//   requested line within `switch_supervision` (but at least 2 × the station's T_SLAVE_UM);
//   otherwise the command is repeated, and after `switch_attempts` tries the station is lost
//   (39C4, cause SwitchoverTimeout). A total station loss during a switchover (the new channel
//   fails too) is the both-DOWN case above.
// - Whole line lost (system-level): every switched station whose active channel is on that
//   line gets Primary_Request on the other line at once (one pass of the other master; the
//   slowest station's T_SLAVE_UM bounds them all). Events by cause (digest §7):
//     ShortCircuit, MasterStop (F14): exactly one W#16#39C3 (master system failure) on that
//       line, no per-station events; the line's channels are DOWN silently, and their return
//       is silent too (W#16#38C3 when the line is back);
//     MasterFailure (F9, the master module itself fails): per station as if each channel on
//       the line had failed: 73A3 for switched stations, 39C4 for one-sided slaves; their
//       returns as usual (72A3, 38C4).
//   While a line is lost, the masters' own StationFailure reports from it are bookkeeping only.
//     CpuFailure (H-system, the CPU owning the line's master is off): as ShortCircuit.
// - A line that has not started (mark_line_idle(): the standby CPU's DP master before its first
//   link-up, or a CPU never powered) is NOT lost: no 39C3/38C3 for it, line_lost()/line_back()
//   and the master's ModeChange are ignored, and the StationFailure reports of its master are
//   bookkeeping only (a station whose other channel comes up meanwhile gets no 73A3: the I/O
//   was never redundant). start_line() ends it silently: the line's channels come up as its
//   master reaches data exchange with them, without 72A3/38C4 (the owed returns are silent);
//   from then on the line reports like any other, and when it stops it is lost as above.
//   mark_line_idle() is refused (false) for a line that has run (a channel was up on it) or is
//   lost: a line that ran and stops is a lost line.
// - Outputs: write_outputs() writes the same octets into BOTH masters' images (one program,
//   two channels), so whichever channel is active carries the newest value and a switchover
//   can never bring an older one. Inputs (and the diagnosis the program uses) come from the
//   active channel's master image (active_image()).
// - Switchover records (no OB): one whenever the system commands a channel, and one whenever the
//   station's reported primary changes without a command (its first primary at start-up,
//   cause StartUp; an autonomous switch, cause Station), so the record stream always says
//   which channel is active (captures, timeline).
// - Seq_Nr: one counter per station, incremented for every PrmCmd that changes a block.
// - Alarms (S8, "no interrupt lost, none twice"): the station raises an alarm on its PRIMARY
//   only and raises it again on the new PRIMARY when the primary changes before the master's
//   Alarm_Ack reached it (RedundantSlave). The system delivers each alarm to the program once
//   (on_alarm/alarms()): an alarm read on a channel stays "unacknowledged" until that master's
//   Alarm_Ack is confirmed (dp AlarmAcknowledged); if its channel goes down first, the same
//   alarm (type, slot, specifier bits, data) from the station within `alarm_repeat_window`
//   is the station's repeat: acknowledged by its master as usual, not delivered again. DP-V1
//   allows one outstanding alarm per type and slot, so a second one with the same type and slot
//   before the first is acknowledged can only be that repeat.
// - Data records (S6, S8): read()/write() go to the active channel's master (MSAC_C1). A job
//   the switchover interrupts (NoResponse, NotAvailable, Timeout or Rejected on the old
//   channel) is repeated on the new active channel as soon as the station shows one, at most
//   `record_attempts` times in all; the callback runs once, with the final result (id = the
//   system's job id). A Read is idempotent; a Write repeated after an interruption may reach the
//   station twice — as on the S7-400H, where the record job is repeated by the system.
// - Diagnosis changes (S7 masters call OB 82 when a DP-V0 slave's diagnosis changes; H-system
//   F3/F15): on_diagnosis() gets the station's Slave_Diag whenever its CONTENT changed on the
//   ACTIVE channel (one-sided: its own line). Content = the extended-diagnosis blocks without
//   the redundancy status PDUs (Prm_Cmd_Ack 0x9E, Red_Status 0x9F, which differ per line and
//   change at every switchover); the six standard octets are not compared (master-set bits,
//   WD_On ...). The baseline is "no blocks" at construction; start-up reads raise nothing
//   (dp::Master raises Diagnosis only in data exchange), so a station that comes up with a
//   fault is reported at its first change. A passive channel's diagnosis is never delivered
//   (the program reads the active one), so a switchover alone raises nothing.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/dp/master.hpp"
#include "pbvbus/redundancy/prm_cmd.hpp"
#include "pbvbus/redundancy/red_status.hpp"

namespace pbvbus::redundancy {

/// One switched station of the system (present on both lines with the same address).
struct SwitchedStationRef {
  std::uint8_t address = 0;
  bus::Ticks t_slave_um = 0;  ///< the station's own switchover time (0 = not known)
  bool flying = false;        ///< Flying Redundancy: Address_Offset64 in the PrmCmd Properties
};

struct MasterSystemParams {
  int preferred = 0;                     ///< the line whose channel is made active at start-up
  std::uint16_t output_hold_time = 100;  ///< PrmCmd Output_Hold_Time, 10 ms units (1 s)
  bus::Ticks switch_supervision = 200 * bus::kTicksPerMs;
  int switch_attempts = 2;
  bus::Ticks alarm_repeat_window = 2000 * bus::kTicksPerMs;
  int record_attempts = 3;
  bus::Ticks record_wait = 2000 * bus::kTicksPerMs;  ///< for a new active channel, then failed
};

/// A DP-V1 alarm as the program receives it (once, from the active channel).
struct SystemAlarm {
  bus::Ticks time = 0;
  std::uint8_t station = 0;
  int line = -1;
  std::uint8_t type = 0;
  std::uint8_t slot = 0;
  std::uint8_t specifier = 0;
  std::vector<std::uint8_t> data;
};

/// A change of a station's diagnosis content on its active channel (see above).
struct SystemDiagnosis {
  bus::Ticks time = 0;
  std::uint8_t station = 0;
  int line = -1;
  std::vector<std::uint8_t> diag;  ///< the whole Slave_Diag DU as the master stored it
  std::vector<std::uint8_t> previous;  ///< the last delivered one (empty: none before)
};
/// The extended-diagnosis blocks of a Slave_Diag DU without Prm_Cmd_Ack/Red_Status PDUs (the
/// content on_diagnosis compares); empty for a DU of six octets or a broken block length.
std::vector<std::uint8_t> diagnosis_content(std::span<const std::uint8_t> diag);

/// Why a whole line is lost.
enum class LineLoss : std::uint8_t {
  ShortCircuit,   ///< the master's transceiver reads back garbage (F14)
  MasterStop,     ///< the line's master went to Stop/Offline (F14: CP RUN → STOP)
  MasterFailure,  ///< the master module itself failed (F9)
  /// The CPU that owns the line's master failed or lost power (H-system F1: "a CPU failure is
  /// a master-system failure for its side's DP lines"): like ShortCircuit/MasterStop, one
  /// W#16#39C3 and no per-station events; W#16#38C3 when the CPU's DP master runs again.
  CpuFailure,
};
std::string_view to_string(LineLoss c);

/// An event of the master system, with the S7 code users know.
struct SystemEvent {
  enum class Kind : std::uint8_t {
    RedundancyLoss,       ///< OB 70 W#16#73A3
    RedundancyReturn,     ///< OB 70 W#16#72A3
    StationFailure,       ///< OB 86 W#16#39C4
    StationReturn,        ///< OB 86 W#16#38C4
    MasterSystemFailure,  ///< OB 86 W#16#39C3
    MasterSystemReturn,   ///< OB 86 W#16#38C3
    Switchover,           ///< the system commanded a new active channel (no OB of its own)
  };
  enum class Cause : std::uint8_t {
    None,
    ChannelFailure,     ///< the master reported the channel failed
    ChannelMissing,     ///< start-up: the channel never reached data exchange
    LineLost,           ///< a whole line lost (MasterFailure: per-station events)
    SwitchoverTimeout,  ///< F24: the station did not take the commanded role in time
    StartUp,            ///< Switchover: first choice of an active channel
    Station,            ///< Switchover record: the station changed its primary by itself
  };
  Kind kind = Kind::RedundancyLoss;
  bus::Ticks time = 0;
  int line = -1;                 ///< the line concerned (Switchover: the new active line)
  std::uint8_t station = 0xFF;   ///< 0xFF for the whole master system
  int from = -1;                 ///< Switchover: the previous active line, or -1
  Cause cause = Cause::None;
  std::uint16_t code() const;    ///< 0x73A3 ...; 0 for Switchover
  int ob() const;                ///< 70, 86; 0 for Switchover
  bool s7() const { return kind != Kind::Switchover; }
};
std::string_view to_string(SystemEvent::Kind k);
std::string_view to_string(SystemEvent::Cause c);

/// The Red_Status block (0x9F) in a Slave_Diag DU, if there is a well-formed one.
std::optional<RedStatusBlock> find_red_status(std::span<const std::uint8_t> diag);

class MasterSystem {
 public:
  /// `a` and `b` are the masters of line A and B; every switched station must be configured on
  /// both (the same address, an 8-octet SlaveParams::prm_cmd), every other slave on one only.
  /// Throws std::invalid_argument otherwise. Sets the start-up PrmCmd blocks (not sent).
  MasterSystem(dp::Master& a, dp::Master& b, std::vector<SwitchedStationRef> switched,
               MasterSystemParams p = {});
  MasterSystem(const MasterSystem&) = delete;
  MasterSystem& operator=(const MasterSystem&) = delete;

  void on_master_event(int line, const dp::MasterEvent& e);
  void line_lost(int line, LineLoss cause, bus::Ticks now);
  void line_back(int line, bus::Ticks now);
  bool line_is_lost(int line) const { return m_line[line].lost; }
  /// Why the line is lost, or nothing if it is not (bad line: nothing).
  std::optional<LineLoss> line_loss(int line) const;
  /// Declares a line not started (see above); false if it ran already, is lost or is not 0/1.
  bool mark_line_idle(int line);
  /// The idle line starts (its master is about to run): silent; false if it was not idle.
  bool start_line(int line, bus::Ticks now);
  bool line_idle(int line) const { return (line == 0 || line == 1) && m_line[line].idle; }
  bus::Ticks next_deadline() const;
  void on_time(bus::Ticks now);

  dp::Master& master(int line) { return *m_master[line]; }
  const dp::Master& master(int line) const { return *m_master[line]; }
  bool is_switched(std::uint8_t address) const;
  /// The line whose interface the station reports PRIMARY (switched), the slave's own line
  /// (one-sided), or -1.
  int active(std::uint8_t address) const;
  /// The line a switchover is under way to, or -1.
  int switching_to(std::uint8_t address) const;
  bool channel_up(std::uint8_t address, int line) const;
  /// Per-station redundancy lost (73A3 raised, 72A3 not yet).
  bool redundancy_lost(std::uint8_t address) const;
  bool station_failed(std::uint8_t address) const;
  std::vector<std::uint8_t> addresses() const;

  /// Writes one module's outputs into both masters' images (one-sided: its master's).
  bool write_outputs(std::uint8_t address, std::size_t module, std::span<const std::uint8_t> data);
  /// The same into line `line`'s master image only (a one-sided slave of the other line: false,
  /// nothing written). For two masters each driving its own line (H-system F6/F7: each CPU
  /// runs alone and sends its own outputs).
  bool write_outputs(int line, std::uint8_t address, std::size_t module,
                     std::span<const std::uint8_t> data);
  /// The image the program reads inputs and diagnosis from: the active channel's; nullptr when
  /// there is none.
  const dp::MasterImage* active_image(std::uint8_t address) const;

  void on_event(std::function<void(const SystemEvent&)> cb) { m_cb = std::move(cb); }
  /// A further listener, called after the on_event callback for every event and never
  /// replaced by on_event (the scenario runtime's report and capture keep theirs when an
  /// H-system model takes on_event over).
  void add_event_listener(std::function<void(const SystemEvent&)> cb) {
    m_listeners.push_back(std::move(cb));
  }
  void on_alarm(std::function<void(const SystemAlarm&)> cb) { m_alarm_cb = std::move(cb); }
  const std::vector<SystemAlarm>& alarms() const { return m_alarms; }
  /// Diagnosis content changes on the active channel (see above), delivered in order.
  void on_diagnosis(std::function<void(const SystemDiagnosis&)> cb) { m_diag_cb = std::move(cb); }
  std::uint64_t diagnosis_changes() const { return m_diag_changes; }
  /// Alarms a station raised again after a switchover that were recognised and not delivered.
  std::uint64_t alarm_repeats() const { return m_alarm_repeats; }

  /// DP-V1 MSAC_C1 Read/Write over the active channel (see above). Returns the job id (> 0),
  /// or 0 if the station has no active channel or its master refuses the request now.
  std::uint32_t read(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                     std::uint8_t length, dp::AcyclicCallback cb, bus::Ticks now);
  std::uint32_t write(std::uint8_t address, std::uint8_t slot, std::uint8_t index,
                      std::span<const std::uint8_t> data, dp::AcyclicCallback cb, bus::Ticks now);
  /// Record jobs repeated on a new channel after an interruption.
  std::uint64_t record_repeats() const { return m_record_repeats; }
  const std::vector<SystemEvent>& events() const { return m_events; }
  std::uint64_t switchovers() const { return m_switchovers; }

 private:
  struct Station {
    std::uint8_t address = 0;
    bool switched = false;
    int home = -1;               ///< one-sided: its line
    bus::Ticks t_slave_um = 0;
    bool flying = false;
    bool up[2] = {false, false};
    bool down[2] = {false, false};  ///< reported failed/absent (not merely not yet up)
    int active = -1;
    int target = -1;
    bus::Ticks deadline = bus::kNever;
    int attempts = 0;
    std::uint8_t seq = 0;
    bool red_lost = false;        ///< 73A3 reported, 72A3 owed
    bool failed = false;          ///< 39C4 reported, 38C4 owed
    bool silent_red_lost = false; ///< lost in a 39C3 line loss: the return is silent too
    bool silent_failed = false;
    struct Unacked {
      int line = -1;
      std::uint8_t type = 0, slot = 0, seq = 0, spec = 0;
      std::vector<std::uint8_t> data;
      bus::Ticks orphaned = bus::kNever;  ///< its channel went down before the ack
    };
    std::vector<Unacked> unacked;
    std::vector<std::uint8_t> diag_content;  ///< last delivered diagnosis content
    std::vector<std::uint8_t> diag_du;       ///< its whole DU
  };

  Station* find(std::uint8_t address);
  const Station* find(std::uint8_t address) const;
  void channel_down(Station& s, int line, bus::Ticks now, bool report,
                    SystemEvent::Cause cause = SystemEvent::Cause::ChannelFailure);
  void channel_up(Station& s, int line, bus::Ticks now, std::span<const std::uint8_t> diag);
  void observe_red_status(Station& s, int line, std::span<const std::uint8_t> diag,
                          bus::Ticks now);
  void on_alarm_event(Station& s, int line, const dp::MasterEvent& e);
  void on_alarm_ack(Station& s, int line, const dp::MasterEvent& e);
  void on_diagnosis_event(Station& s, int line, const dp::MasterEvent& e);
  struct Record {
    std::uint32_t id = 0;
    std::uint8_t address = 0;
    bool write = false;
    std::uint8_t slot = 0, index = 0, length = 0;
    std::vector<std::uint8_t> data;
    dp::AcyclicCallback cb;
    int attempts = 0;
    int line = -1;                      ///< where it runs now (-1: waiting for a channel)
    bus::Ticks waiting_since = bus::kNever;
  };
  bool start_record(Record& r);
  void record_done(std::uint32_t id, const dp::AcyclicResult& res);
  void retry_records(bus::Ticks now);
  void switch_to(Station& s, int line, bus::Ticks now, SystemEvent::Cause cause);
  std::array<std::uint8_t, kPrmCmdLen> block(const Station& s, bool primary_request) const;
  bool reporting(int line) const;
  void emit(SystemEvent::Kind k, bus::Ticks t, int line, std::uint8_t station,
            SystemEvent::Cause cause = SystemEvent::Cause::None, int from = -1);

  dp::Master* m_master[2];
  MasterSystemParams m_p;
  std::vector<Station> m_st;
  std::array<int, 128> m_index{};
  struct Line {
    bool lost = false;
    LineLoss cause = LineLoss::ShortCircuit;
    bool idle = false;  ///< not started (mark_line_idle), no events for it
    bool ran = false;   ///< a channel was up on it once
  } m_line[2];
  std::vector<SystemEvent> m_events;
  std::function<void(const SystemEvent&)> m_cb;
  std::vector<std::function<void(const SystemEvent&)>> m_listeners;
  std::uint64_t m_switchovers = 0;
  std::function<void(const SystemAlarm&)> m_alarm_cb;
  std::vector<SystemAlarm> m_alarms;
  std::uint64_t m_alarm_repeats = 0;
  std::function<void(const SystemDiagnosis&)> m_diag_cb;
  std::uint64_t m_diag_changes = 0;
  std::vector<Record> m_records;
  std::uint32_t m_next_record = 1;
  std::uint64_t m_record_repeats = 0;
  bus::Ticks m_now = 0;
};

}  // namespace pbvbus::redundancy
