#pragma once
// The CPU pair of an S7-400H-style H-system (docs/h-system.md
// and 5; seeds-digest.md §1, §4, §6, §7; docs/h-system.md has the states, the rules and every
// decision): two CPUs, rack 0 and rack 1, joined by a sync link of two fibres (0 = upper,
// 1 = lower). Per CPU: operating state, role (master/standby), mode switch, diagnostic buffer,
// LEDs; for the pair: the system mode derived as in the digest's table, and events with their
// virtual time, rack and role (state and role changes, system-mode changes, OB 72, OB 121).
//
// Sans-I/O: no threads, no clock, no bus. The owner calls on_time(now) at next_deadline() and
// the operations at a virtual time; every operation first runs the deadlines due at `now`
// (on_time(now)), so a deadline and an operation at the same instant see the deadline first.
// The DP master systems, the user program and the process images are not here: the owner reads
// is_master(), accesses_switched_io(), dp_master_running() and dp_master_operate() and the
// events, and drives devices::RedundantMasterSystemModel from them.
//
// Decisions (summary; the reasons are in docs/h-system.md):
// - Roles are decided at power-on ("started" = power_on(), independent of the mode switch).
//   A CPU that powers on while its partner is linked and master becomes standby. A CPU alone
//   (partner off or the sync link not whole) becomes master at once, unless it remembers being
//   standby: then it waits `role_window` (3 s) for its partner; if the partner powers on within
//   the window (now < own power-on + 3 s) the remembered assignment stays (rack roles as
//   before: "simultaneous power-on"), else at power-on + 3 s it becomes master (R2: the standby
//   started >= 3 s before the master swaps the roles; a master powering on at exactly +3 s
//   finds the swap done). Roles are remembered across power cycles. A first-ever power-on has
//   no memory: the first power_on() call is master; power_on_both() is the simultaneous
//   power-on and makes rack 0 master when nothing is remembered.
// - The mode switch: switch_to_run(r) is a STOP -> RUN request (the PG/ES restart too);
//   switch_to_stop(r) is the switch at STOP. A CPU stopped by a fault (fibre cut, aborted
//   link-up, refused link-up) stays in STOP until the next switch_to_run(). power_on() starts
//   the CPU when its switch is at RUN and it was not in STOP when it lost power (digest §4).
// - STARTUP (startup_time) runs on the master only; a standby whose switch is at RUN waits in
//   STOP until the master is in RUN (Solo), then goes LINK-UP (link_up_time) -> UPDATE
//   (W, below) -> RUN (Redundant). The master stays RUN throughout (Table 4-1).
// - The update in phases (400H; digest §3.1 timeline, §4 "Update steps"): t1 = the standby
//   enters UPDATE (end of LINK-UP): data-record jobs refused (record_job_result: 80C3/8085),
//   messages/communication and OB 1/classes <= 15 delayed, DP interrupts held
//   (interrupts_held). t3 = t1: the delay stages take no time in this model. [t3, t5) is the
//   no-I/O window (io_frozen: no OB, no I/O update on either CPU) of length
//   W = MAX(T_P15_AWP(update_db_kb) = 75 ms + 0.7 ms/KB (or update_time), 50 ms + T_PH), the
//   50 ms + T_PH term only with a configured T_PH > 0. t4 = t5 - T_PH: output hold
//   (outputs_held_by_both; empty with T_PH = 0); t4 is a deadline of its own. t5 = Redundant
//   mode or the swap. The pair only reports the phases; holding/delivering interrupts, pausing
//   the program and driving outputs is the owner's. dp_master_operate() is not changed by the
//   window (a Clear would drive safe values; the owner asks io_frozen()).
// - Update timeout (F19/R6): the first monitored (set, not 0) limit among T_P15, max
//   communication delay, max cycle extension that is < W aborts the update at t3 + limit (each
//   covers W from t1 = t2 = t3 here; a valid set makes T_P15 the first). Abort: standby STOP
//   (re-reads its SDBs), Solo with the same master, OB 72 UpdateTimeout on the master, buffer
//   entries on both, any pending swap dropped; the standby retries by itself exactly 60 s later
//   (a plain link-up), at most kUpdateMaxTries tries per series; switch_to_run(), power-on, the
//   re-link after ERROR-SEARCH and request_master_swap() start a new series. Not modelled: the
//   cycle monitoring time that bounds an update with no H parameters.
// - F20/R9: the standby powered off or switched to STOP in LINK-UP gets a reset request
//   (W#16#6523 if within the first load_memory_copy_time of LINK-UP, default half of it); it
//   stays in STOP (switch_to_run refused, no start at power-on) until memory_reset(), which
//   does not start it. Aborts caused by the partner or the link set no reset request.
// - R8: connect(r) counts S7 connections; refused on a CPU off/ERROR-SEARCH/DEFECTIVE and on
//   both CPUs while a CPU is in LINK-UP or UPDATE; link-up breaks the standby's, keeps the
//   master's; power-off drops a CPU's. accepts_connections(r) is that admission rule, shared
//   with HConnections (h_connections.hpp: the configured connections over the CPs, F4); the
//   counter here is the ad-hoc connections only.
// - F2 load_memory_error(r): r -> STOP + reset request (the F20 mechanism: STOP until
//   memory_reset(), then a STOP -> RUN), entry "load-memory access error" (no event ID in the
//   seeds: code 0); the partner's reaction is the one to a STOP of r (no new HReason: the OB 72
//   reads MasterStop/StandbyStop, the buffer entry names the cause). Refused on off/DEFECTIVE.
// - F22 load_change(): Allowed -> buffer entry; a structural FB-interface or global-DB change
//   in Redundant -> both CPUs STOP (no OB 72), in Solo -> loaded; refused unless Solo or
//   Redundant (no block load during link-up/update). F23: with set_standby_parameter_change
//   (true) request_master_swap() is refused at the request: standby stays in STOP, W#16#5966
//   in both buffers.
// - Leaving Redundant: master power-off or STOP -> the standby becomes master in Solo, OB 72 on
//   it; standby power-off or STOP -> Solo, OB 72 on the master. During link-up/update: the
//   link-up is aborted (the standby to STOP; if the master was lost, the survivor becomes
//   master in STOP). A lone powered CPU whose linked partner powers off is master.
// - Sync link: both fibres are needed for link-up and Redundant mode. One fibre cut while
//   linked (F5): the standby STOPs, OB 72 on the master if it runs. cut_both_fibres() (F6):
//   a standby in RUN becomes a second master in RUN, OB 72 on both; a standby still linking
//   up STOPs. Two cut_fibre() calls are two events, the first one F5. Fibres cut before
//   power-on (F7): each CPU is alone, so both may run as master. A repair does not start a
//   link-up (a STOP -> RUN is needed) and does not end a split: a master switched to STOP
//   while the other master runs over a whole link becomes its standby.
// - Comparison error (F16, Redundant only): the standby goes ERROR-SEARCH (or STOP, per
//   `comparison_reaction`), OB 72 on the master (Solo). In the first cyclic self-test period
//   after an ERROR-SEARCH that found nothing, a new comparison error STOPs the standby (000
//   Table 4-4). One-sided OB 121 (F17, Redundant only): OB 121 on that CPU, which goes
//   ERROR-SEARCH (the partner becomes master if needed, OB 72 on it); a second one on the same
//   CPU within `defective_window` (7 days, inclusive) -> DEFECTIVE at once.
// - ERROR-SEARCH lasts `self_test_time`; a latent fault (inject_hardware_fault) -> DEFECTIVE,
//   else the CPU links up again (LINK-UP -> UPDATE) and at the end of the update the roles swap
//   (001 §5.3.6): both RUN in Redundant mode, OB 72 on both (digest §10 item 1: OB 72).
//   DEFECTIVE persists across power cycles until repair_cpu(); a DEFECTIVE CPU is never master
//   (a linked standby takes the role). A standby that sees over a whole link that its partner
//   is off becomes master in its current state.
// - request_master_swap() (PG/ES "switch to CPU with modified configuration"; Solo, standby in
//   STOP): link-up and update, then the old standby is master in RUN (Solo) and the old master
//   STOPs; OB 72 on the new master.
// - S7-1500R/H profile: STOP -> STARTUP (primary only) -> RUN-Solo -> SYNCUP (both CPUs,
//   link_up_time + W, no phases, no timeout, no reset request, io_frozen() etc. false) ->
//   RUN-Redundant; roles named primary/backup; no HOLD; a
//   comparison error or one-sided OB 121 STOPs the CPU (no ERROR-SEARCH in the 1500 excerpt).

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_update_timing.hpp"

namespace pbvbus::devices {

enum class CpuState : std::uint8_t {
  Off,  ///< powered off (CPU or PS failure)
  Stop,
  Startup,
  Run,  ///< Solo or Redundant (the system mode tells which); 1500: RUN-Solo / RUN-Redundant
  LinkUp,
  Update,
  Hold,
  ErrorSearch,
  Defective,
  SyncUp,  ///< S7-1500R/H profile only
};
std::string_view to_string(CpuState s);

enum class CpuRole : std::uint8_t { None, Master, Standby };
/// "master"/"standby" (S7-400H) or "primary"/"backup" (S7-1500R/H).
enum class HProfile : std::uint8_t { S7_400H, S7_1500RH };
std::string_view to_string(CpuRole r, HProfile p = HProfile::S7_400H);

enum class SystemMode : std::uint8_t {
  Stop,
  Startup,
  Solo,
  LinkUp,
  Update,
  Redundant,
  Hold,
  SyncUp
};
std::string_view to_string(SystemMode m, HProfile p = HProfile::S7_400H);

enum class Redf : std::uint8_t { Off, Flash0_5Hz, Flash2Hz, On };
std::string_view to_string(Redf r);

enum class ComparisonReaction : std::uint8_t { ErrorSearch, Stop };

/// Why an OB 72 ran (the seeds give no event IDs for OB 72: HEvent::code stays 0).
enum class HReason : std::uint8_t {
  None,
  MasterLost,       ///< the master failed or was powered off: the standby took over
  MasterStop,       ///< the master went to STOP in Redundant mode: the standby took over
  StandbyLost,      ///< the standby failed or was powered off
  StandbyStop,      ///< the standby went to STOP
  LinkLost,         ///< one fibre (F5) or both fibres (F6) of the sync link
  ComparisonError,  ///< F16
  OneSidedOb121,    ///< F17
  MasterSwap,       ///< automatic swap after ERROR-SEARCH or the operator's swap
  UpdateTimeout,    ///< F19/R6: the update exceeded a configured monitoring time
  ChecksumError,    ///< a checksum error on one CPU in Redundant mode (001 Table 5-6)
};
std::string_view to_string(HReason r);

struct HEvent {
  enum class Kind : std::uint8_t { State, Role, SystemMode, Ob };
  Kind kind = Kind::State;
  bus::Ticks at = 0;
  int rack = 0;
  CpuRole role = CpuRole::None;  ///< the CPU's role after the event
  CpuState from_state = CpuState::Off, to_state = CpuState::Off;        ///< Kind::State
  CpuRole from_role = CpuRole::None;                                    ///< Kind::Role (to = role)
  SystemMode from_mode = SystemMode::Stop, to_mode = SystemMode::Stop;  ///< Kind::SystemMode
  int ob = 0;                                                           ///< Kind::Ob: 72 or 121
  std::uint16_t code = 0;  ///< event ID where the digest gives one, else 0
  HReason reason = HReason::None;
};

struct DiagEntry {
  bus::Ticks at = 0;
  CpuRole role = CpuRole::None;
  std::uint16_t code = 0;
  std::string text;
};

struct CpuLeds {
  bool mstr = false;   ///< this CPU accesses the switched I/O (master, powered)
  bool rack0 = false;  ///< powered CPU in rack 0
  bool rack1 = false;
  Redf redf = Redf::Off;
  bool ifm1f = false;  ///< upper fibre fault (cut, or no partner on it)
  bool ifm2f = false;  ///< lower fibre fault
};

struct HCpuPairParams {
  HProfile profile = HProfile::S7_400H;
  bus::Ticks startup_time = 1000 * bus::kTicksPerMs;  ///< STARTUP (OB 100) on the master
  bus::Ticks link_up_time = 2000 * bus::kTicksPerMs;  ///< LINK-UP (program compare/copy)
  /// KB of data blocks the update copies (for the default update_time).
  /// KB of changed data blocks the next update copies (T_P15_AWP's KB; set_changed_db_kb()
  /// changes it at run time).
  std::uint32_t update_db_kb = 100;
  /// Overrides the copy time T_P15_AWP(update_db_kb) = 75 ms + 0.7 ms per KB (digest §3.1, T7)
  /// in the no-I/O window W; cleared by set_changed_db_kb().
  std::optional<bus::Ticks> update_time;
  /// The four configured H parameters (µs; all unset = none configured). Checked with
  /// check_h_parameters() in the constructor: an Error throws std::invalid_argument.
  HParameters h_parameters;
  /// The load-memory copy at the start of LINK-UP (F20/R9: W#16#6523). Default: half of
  /// link_up_time (T8: the default 2 s are 1 MB x 1 s of copy + 1 s base). 0..link_up_time.
  std::optional<bus::Ticks> load_memory_copy_time;
  bus::Ticks role_window = 3000 * bus::kTicksPerMs;       ///< R2
  bus::Ticks self_test_time = 90 * bus::kTicksPerSecond;  ///< full self-test in ERROR-SEARCH
  bus::Ticks cyclic_self_test_period = 90 * 60 * bus::kTicksPerSecond;
  bus::Ticks defective_window = 7 * 24 * 3600 * bus::kTicksPerSecond;  ///< F17 repetition
  ComparisonReaction comparison_reaction = ComparisonReaction::ErrorSearch;
  std::array<bool, 2> switch_run{true, true};  ///< mode switch positions at construction
  std::size_t diag_capacity = 120;             ///< entries per CPU, oldest dropped
  /// Ad-hoc connections per CPU (connect()): the MPI interface's connection resources (digest
  /// §9 "MPI 32/44" for the 414/417; the 417's here). The reservation of one for a PG and one
  /// for an OP is not modelled. 0 = no limit.
  int max_connections = 44;
};

/// 75 ms + 0.7 ms per KB (exact in ticks: 0.7 ms = 2 545 200 ticks).
constexpr bus::Ticks default_update_time(std::uint32_t kb) {
  return 75 * bus::kTicksPerMs + static_cast<bus::Ticks>(kb) * (7 * bus::kTicksPerMs / 10);
}

/// A program change loaded into the H system (F22).
enum class HChange : std::uint8_t {
  Allowed,                ///< a change allowed in any mode: nothing happens but a buffer entry
  StructuralFbInterface,  ///< a structural change of an FB interface
  GlobalDb,               ///< a change of a global DB's structure
};
std::string_view to_string(HChange c);

enum class HChangeResult : std::uint8_t {
  Loaded,       ///< loaded (Solo, or an allowed change)
  BothStopped,  ///< F22: not allowed in Redundant mode: both CPUs went to STOP
  Refused,      ///< not loadable now: no master in RUN, or during link-up/update (digest §4)
};
std::string_view to_string(HChangeResult r);

/// The times of one update (400H): t1 start of UPDATE (= t3 here), t3 start of the no-I/O
/// window (T_P15), t4 start of the output hold (T_PH), t5 Redundant mode / swap, or the abort.
struct UpdateWindow {
  bus::Ticks t1 = 0, t3 = 0, t4 = 0, t5 = 0;
  bool aborted = false;    ///< ended before the planned t5 (timeout, CPU or link lost): t5 = then
  bool timed_out = false;  ///< aborted by the update monitoring (F19)
};

/// F19/R6: the standby retries the link-up this long after an update timeout (>= 1 min).
inline constexpr bus::Ticks kUpdateRetryDelayTicks = to_ticks(kUpdateRetryDelay);

/// Where a checksum error was found (001 L4023-4065, Table 5-6; docs/h-changes.md).
enum class HChecksumContext : std::uint8_t {
  PowerOnTest,  ///< the self-test of the start-up after an unbuffered power-on
  Cyclic,       ///< the cyclic self-test (STOP, Solo, Redundant; in ERROR-SEARCH: the full test)
};

class HCpuPair {
 public:
  explicit HCpuPair(HCpuPairParams p = {});

  // ---- operations (each at virtual time `now`, non-decreasing) ----
  void power_on(int rack, bus::Ticks now);
  /// Both racks at the same instant (the simultaneous POWER ON of the manual).
  void power_on_both(bus::Ticks now);
  void power_off(int rack, bus::Ticks now);  ///< CPU or PS failure, or switched off
  void switch_to_run(int rack, bus::Ticks now);
  void switch_to_stop(int rack, bus::Ticks now);
  void cut_fibre(int fibre, bus::Ticks now);
  void cut_both_fibres(bus::Ticks now);
  void repair_fibre(int fibre, bus::Ticks now);
  /// false if HOLD is not reachable (only the master in STARTUP or Solo RUN; not in 1500).
  bool hold(int rack, bus::Ticks now);
  bool release_hold(int rack, bus::Ticks now);
  /// RAM/output-image comparison error (F16); false unless the system is Redundant.
  bool inject_comparison_error(bus::Ticks now);
  /// OB 121 on `rack` only (F17); false unless the system is Redundant.
  bool one_sided_ob121(int rack, bus::Ticks now);
  /// F2: a load-memory access error on `rack`: that CPU -> STOP with a reset request (no start
  /// until memory_reset()), a buffer entry on it; the partner reacts as to any STOP of it
  /// (master in Redundant: the standby becomes master in Solo, OB 72 MasterStop; standby: Solo,
  /// OB 72 StandbyStop on the master; the lone master: system STOP; during link-up/update: the
  /// link-up is aborted). The mode switch stays where it is. A CPU already in STOP only gets the
  /// reset request and the entry. false (nothing happens) on a CPU that is off or DEFECTIVE.
  bool load_memory_error(int rack, bus::Ticks now);
  /// A latent hardware fault on `rack` that the next full self-test finds (-> DEFECTIVE).
  void inject_hardware_fault(int rack, bus::Ticks now);
  /// The CPU is replaced or its fault removed: clears the fault, the OB 121 history and
  /// DEFECTIVE (the CPU goes to STOP if powered).
  void repair_cpu(int rack, bus::Ticks now);
  /// PG/ES "switch to CPU with modified configuration"; false unless Solo with the master in
  /// RUN and the standby powered in STOP over a whole link.
  bool request_master_swap(bus::Ticks now);
  /// The next update copies `kb` KB of changed DBs (the program changed DBs since the last
  /// update): W grows by 0.7 ms per KB; a running update keeps its plan. Clears update_time.
  void set_changed_db_kb(std::uint32_t kb, bus::Ticks now);
  /// MRES on `rack` (powered, STOP/DEFECTIVE excluded): clears a reset request (F20/R9). The CPU
  /// stays in STOP; a switch_to_run() starts it. false if not possible.
  bool memory_reset(int rack, bus::Ticks now);
  /// R8: open an S7 connection to `rack`; false on a CPU that is off, in ERROR-SEARCH or
  /// DEFECTIVE, and on both CPUs from the start of a link-up to the end of the update (400H);
  /// false too when its max_connections are all in use.
  bool connect(int rack, bus::Ticks now);
  /// The client closes an ad-hoc connection opened with connect(): one less on `rack` (never
  /// below 0; a connection the pair already broke was not counted any more).
  void disconnect(int rack);
  /// Changes whenever the pair breaks every ad-hoc connection of `rack` (R8 link-up of the
  /// standby; the CPU off, in ERROR-SEARCH or DEFECTIVE): a connection opened at an earlier
  /// epoch is gone (controllers/s7h h_s7_session.hpp). 0 for a bad rack.
  std::uint64_t connection_epoch(int rack) const {
    return rack == 0 || rack == 1 ? m_cpu[rack].connection_epoch : 0;
  }
  /// R8's admission rule, the one truth for connect() and HConnections (h_connections.hpp): a
  /// new S7 connection to `rack` is accepted now (powered, not ERROR-SEARCH/DEFECTIVE, and no
  /// CPU in LINK-UP or UPDATE). Does not run deadlines: call after on_time()/an operation.
  bool accepts_connections(int rack) const;
  /// F22: load a program change (into the master; in Redundant mode into both).
  HChangeResult load_change(HChange kind, bus::Ticks now);
  /// F23: the standby's configuration has a changed parameter that may not change; a
  /// request_master_swap() is then refused (standby stays in STOP, W#16#5966 on both).
  void set_standby_parameter_change(bool may_not_change) { m_param_change = may_not_change; }
  /// R7: the result of a data-record SFC started at `now`: W#16#80C3 for SFC 13, 55..59 and
  /// W#16#8085 for SFC 51 while an update runs ([t1, t5)), else 0.
  std::uint16_t record_job_result(int sfc, bus::Ticks now);
  /// A checksum error found on `rack` (001 Table 5-6, h_cpu_pair_checksum.cpp): PowerOnTest or
  /// in ERROR-SEARCH -> DEFECTIVE; cyclic in STOP/Solo -> corrected (entry only); cyclic in
  /// Redundant -> corrected, that CPU ERROR-SEARCH, the partner master in Solo with OB 72
  /// ChecksumError; a repetition within defective_window -> DEFECTIVE. false (nothing happens)
  /// on a CPU that is off or DEFECTIVE, or in the 1500 profile.
  bool checksum_error(int rack, HChecksumContext where, bus::Ticks now);
  /// An entry from a part built on the pair (h_config_change, h_rack_power, h_dp_startup): the
  /// deadlines due at `now` run first, then `rack`'s buffer gets `text` with `code`.
  void log_entry(int rack, bus::Ticks now, std::string text, std::uint16_t code = 0);

  // ---- SFC 90 H_CTRL blocks (h_sfc90.hpp decodes the SFC; docs/h-sfc90.md) ----
  /// MODE 0/1. Disabled: a standby's start request (switch, power-on, F19 retry, the re-link
  /// after ERROR-SEARCH) waits in STOP and links up when re-enabled; an operator master swap is
  /// refused; a running link-up/update goes on. false: it already was so.
  bool set_link_up_enabled(bool on, bus::Ticks now);
  /// MODE 3/4. Disabled: a standby whose link-up is done waits in LINK-UP (system mode Link-up,
  /// no t1 yet) and enters UPDATE at the re-enable; a running update goes on. false: no change.
  bool set_update_enabled(bool on, bus::Ticks now);
  bool link_up_enabled() const { return !m_link_up_disabled; }
  bool update_enabled() const { return !m_update_disabled; }
  /// A standby has done its link-up and waits for the update to be re-enabled.
  bool update_waiting() const { return m_cpu[0].update_waiting || m_cpu[1].update_waiting; }

  bus::Ticks next_deadline() const;
  void on_time(bus::Ticks now);

  // ---- queries ----
  CpuState state(int rack) const { return m_cpu[rack].state; }
  CpuRole role(int rack) const { return m_cpu[rack].role; }
  bool is_master(int rack) const { return m_cpu[rack].role == CpuRole::Master; }
  /// The master's rack, -1 if none; with two masters (F6/F7) rack 0.
  int master() const;
  int master_count() const;
  /// The pair's system mode, seen by the master (rack 0's if two masters); Stop if none.
  SystemMode system_mode() const;
  /// The system mode as rack r sees it (Stop if off or without a master it is linked to).
  SystemMode system_mode(int rack) const;
  /// Rack r may access the switched I/O: a powered master (also in STOP, digest §1).
  bool accesses_switched_io(int rack) const;
  /// Rack r's DP master(s) run: a powered master that is not DEFECTIVE; a standby from the end
  /// of its link-up (UPDATE, RUN), as it registers the DP slaves then (001 Fig. 6-1).
  bool dp_master_running(int rack) const;
  /// Rack r's DP master(s) send outputs (Operate): the CPU's program runs (RUN, SYNCUP).
  bool dp_master_operate(int rack) const;
  bool fibre_ok(int fibre) const { return m_fibre_ok[fibre]; }
  bool link_whole() const { return m_fibre_ok[0] && m_fibre_ok[1]; }
  bool switch_at_run(int rack) const { return m_cpu[rack].switch_run; }
  CpuLeds leds(int rack) const;
  const std::deque<DiagEntry>& diag_buffer(int rack) const { return m_cpu[rack].diag; }
  const std::vector<HEvent>& events() const { return m_events; }
  void on_event(std::function<void(const HEvent&)> cb) { m_cb = std::move(cb); }
  const HCpuPairParams& params() const { return m_p; }
  /// W of the next update: MAX(T_P15_AWP(KB) or update_time, 50 ms + T_PH).
  bus::Ticks update_time() const;
  /// Inside [t3, t5) of a running update (400H): no program scan, no I/O update on either CPU.
  bool io_frozen() const;
  /// Inside [t4, t5) of a running update (400H): both CPUs drive the outputs (T_PH).
  bool outputs_held_by_both() const;
  /// From t1 to t5 of a running update: DP interrupts are stored, delivered after (by the owner).
  bool interrupts_held() const;
  /// The running update, or the last completed/aborted one.
  std::optional<UpdateWindow> update_window() const { return m_window; }
  /// Link-up/update tries in the current series (F19: at most kUpdateMaxTries); a new start
  /// request (switch_to_run, power-on, re-link, master swap) starts a new series.
  int update_tries() const { return m_tries; }
  int connections(int rack) const { return m_cpu[rack].connections; }
  bool reset_request(int rack) const { return m_cpu[rack].reset_request; }

 private:
  enum class Pending : std::uint8_t { None, Relink, Swap };
  struct Cpu {
    CpuState state = CpuState::Off;
    CpuRole role = CpuRole::None;
    CpuRole remembered = CpuRole::None;  ///< the role before the last power-off
    bool switch_run = true;
    bool want_run = false;         ///< a start request not yet served (switch STOP -> RUN, power)
    bool restart_on_power = true;  ///< not in STOP when power was lost
    bool hw_fault = false;
    bool defective = false;
    bus::Ticks deadline = bus::kNever;        ///< end of the current timed state
    bus::Ticks pending_master = bus::kNever;  ///< alone, remembered standby: master at this time
    bus::Ticks hold_remaining = -1;  ///< STARTUP time left when HOLD was entered, -1: from RUN
    std::optional<bus::Ticks> last_ob121;
    std::optional<bus::Ticks> last_checksum;  ///< the last checksum error (7-day rule)
    Pending after_update = Pending::None;  ///< what the end of this standby's update does
    bool reset_request = false;            ///< F20/R9: STOP until memory_reset()
    bool retrying = false;                 ///< the pending start is an F19 retry
    bus::Ticks link_up_start = bus::kNever;
    bus::Ticks retry_at = bus::kNever;  ///< F19: the standby's own link-up retry
    int connections = 0;                ///< R8: open S7 connections
    std::uint64_t connection_epoch = 0;  ///< bumped when all of them are broken
    bool update_waiting = false;         ///< SFC 90: link-up done, update disabled
    bool link_up_waits = false;          ///< SFC 90: a start request waits (logged once)
    std::deque<DiagEntry> diag;
  };

  int partner(int r) const { return 1 - r; }
  bool powered(int r) const { return m_cpu[r].state != CpuState::Off; }
  /// r and its partner are both powered over a whole link.
  bool linked(int r) const { return powered(r) && powered(partner(r)) && link_whole(); }
  bool is_1500() const { return m_p.profile == HProfile::S7_1500RH; }
  SystemMode mode_of_master(int m) const;

  void run_due(bus::Ticks now);
  void expire(int r, bus::Ticks now);
  void evaluate(bus::Ticks now);
  void after_step(bus::Ticks now);
  void set_state(int r, CpuState s, bus::Ticks now, std::string_view why = {});
  void set_role(int r, CpuRole role, bus::Ticks now, std::string_view why = {});
  void ob(int r, int ob_nr, HReason why, bus::Ticks now, std::uint16_t code = 0);
  void diag(int r, bus::Ticks now, std::string text, std::uint16_t code = 0);
  void emit(HEvent e);
  void begin_link_up(int s, bus::Ticks now, Pending after);
  void finish_update(int s, bus::Ticks now);
  /// Standby s's link-up/update/SYNCUP ends early: s to STOP, the master back to Solo.
  void abort_link_up(int s, bus::Ticks now, std::string_view why);
  /// A CPU leaves RUN/link-up states (power-off or STOP): the partner's reaction.
  void partner_lost(int r, bool master_was, CpuState was, bool power, bus::Ticks now);
  void stop_cpu(int r, bus::Ticks now, std::string_view why);
  void make_defective(int r, bus::Ticks now, std::string_view why);

  void begin_update(int s, bus::Ticks now);
  void update_timeout(int s, bus::Ticks now);
  void close_window(bus::Ticks now, bool aborted, bool timed_out);
  bus::Ticks load_memory_copy_time() const {
    return m_p.load_memory_copy_time.value_or(m_p.link_up_time / 2);
  }
  void output_hold_begins(bus::Ticks now);
  void retry_due(int r, bus::Ticks now);
  void set_reset_request(int r, bus::Ticks now);
  void second_link_lost(bus::Ticks now);  ///< F5: the other fibre failed earlier

  HCpuPairParams m_p;
  bus::Ticks m_now = 0;  ///< the latest time seen (queries without a time use it)
  std::optional<UpdateWindow> m_window;
  bool m_update_running = false;
  bus::Ticks m_update_abort_at = bus::kNever;  ///< F19: t3 + the first monitoring limit < W
  std::string m_update_limit;                  ///< which limit it is, for the buffer
  bus::Ticks m_phase_at = bus::kNever;         ///< t4 while it lies ahead
  int m_tries = 0;
  bool m_param_change = false;
  bool m_link_up_disabled = false;  ///< SFC 90 MODE 0
  bool m_update_disabled = false;   ///< SFC 90 MODE 3
  std::array<Cpu, 2> m_cpu;
  std::array<bool, 2> m_fibre_ok{true, true};
  bus::Ticks m_search_redundant_at = bus::kNever;  ///< Redundant reached after ERROR-SEARCH
  SystemMode m_mode = SystemMode::Stop;
  std::vector<HEvent> m_events;
  std::function<void(const HEvent&)> m_cb;
};

}  // namespace pbvbus::devices
