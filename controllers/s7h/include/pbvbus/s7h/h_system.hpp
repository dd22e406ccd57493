#pragma once
// The H-system model (docs/h-system.md "The H-system model (CPU pair + DP master
// systems)"; seeds-digest.md §1, §2, §6, §7 F1, F5–F7, F9–F14, §11): an HCpuPair (owned) driving
// N redundant DP master systems (RedundantMasterSystemModel, not owned; rack r <-> line r of
// each) on a bus::Scheduler, with the user program (OB 1) on the process images.
//
// Decisions (the reasons are in the doc):
// - Reconciliation after every operation, every pair deadline and at construction: per rack r
//   and per master system the side-r DP master follows its CPU:
//     CPU off -> the master's attachment is unpowered (set_cpu_power) and, if the line ran,
//       MasterSystem::line_lost(r, LineLoss::CpuFailure): one W#16#39C3 for that system, no
//       per-station event; W#16#38C3 when that CPU's DP master runs again;
//     powered, !dp_master_running(r) (STOP/LINK-UP as standby, ERROR-SEARCH, DEFECTIVE ...) ->
//       master Stop and, if the line ran, line_lost(r, MasterStop): one 39C3; back -> 38C3;
//     running -> Operate while the master CPU's program runs (dp_master_operate(master())),
//       else Clear (a master CPU in STOP/STARTUP still accesses the switched I/O, digest §1,
//       with the outputs disabled). With two masters (F6/F7) each side follows its own CPU
//       (dp_master_operate(r)). Except the standby in UPDATE: Clear until t4, Operate from t4
//       (below); one program, write_outputs writes both images.
//   A side whose master never ran is idle (MasterSystem::mark_line_idle): no 39C3, no 73A3 for
//   its channels; when it starts its channels come up without any event. Order: when a side
//   goes away the MasterSystem is told first (it switches every station on that line to the
//   other one at once), then the master is stopped / unpowered (as stop_master() does).
// - The program: set_program(hook, scan_time). OB 1 starts every scan_time (start to start)
//   while some CPU operates as master (dp_master_operate of a master rack); each scan: the PII
//   from the active images through io_map(), the hook, the PIQ through write_outputs (both
//   lines alike). No hook: no scans, outputs untouched. The first scan runs at the instant the
//   master CPU starts operating (as a scheduler event after the operation). set_io_gate(g):
//   when g(now) is false the scan is skipped entirely (not counted), the next one is still
//   scheduled. With two masters one program runs (the same user program on both CPUs; their
//   divergence is not modelled).
// - The real program: set_program(ProgramSpec) builds a RedundantExecution with the I/O map's
//   PII/PIQ sizes (bad spec: std::invalid_argument "program: <validate()'s first message>",
//   the model unchanged). Each OB 1: the PII from the map -> set_inputs (both CPUs, the sync
//   point), scan(now, running, master) with running[r] = dp_master_operate(r) (RUN: the master,
//   or the standby in Redundant), the output rack's PIQ -> write_outputs. The comparison's
//   difference -> HCpuPair::inject_comparison_error (F16; the OB 72 text names area, offset and
//   both bytes). A sync error (F18) -> the standby's switch_to_stop (exactly: standby STOP,
//   Solo, OB 72 StandbyStop on the master; a STOP -> RUN restarts it, as after any fault STOP)
//   plus a "sync error" entry in both diagnostic buffers; F18 is checked before F16 (the sync
//   error happens during the run, the comparison at its end). Program events (7960) ->
//   events() with source Program, code 0x7960, no OB. Two masters (F6/F7): each CPU scans alone
//   (no comparison) and its PIQ goes to its own side only (line r's master images, the racks
//   of side r); with a hook (one program) the same PIQ to both. set_program(hook) replaces a spec and vice versa.
// - Update phases (400H, pair rules: io_frozen, outputs_held_by_both, interrupts_held): no OB 1
//   and no I/O update (inputs or outputs) while io_frozen() ([t3, t5)); a scan due then is
//   dropped and OB 1 restarts AT t5 (or the abort) — a late OB 1 starts at once — so the
//   measured no-I/O window (first scan after - last scan before) is <= W + one scan time (the
//   last scan before t3 started less than one scan time before t3). A pair deadline and a scan
//   at the same instant: the deadline first. The standby's side of every master system is Clear
//   from the start of its UPDATE until t4 and Operate from t4 (the output copy: both CPUs drive
//   during T_PH); at t4 the execution's copy_state(master, standby) (the update copies images
//   and memory). Clear before t4 is no pulse: every station is active on the master's line (the
//   standby's line only just started, silently), and a station whose only channel is the
//   standby's was failed and is just returning. T_PH = 0: t4 = t5. update_measures() records
//   each update (h_update_measure.hpp).
// - Interrupts (digest §4): the MasterSystems' DP-V1 alarms (on_alarm, once each) become OB
//   events (source Alarm): type 1 OB 82, 2 OB 40, 3/4 OB 83, 5 OB 55, 6 OB 56, others OB 57, on
//   the CPUs running the program; while interrupts_held() ([t1, t5)) they are stored and
//   delivered at t5 (or the abort) in their order (time = delivery, original_time = receipt).
// - Data-record jobs (R7, h_system_records.hpp): refused at once during the update
//   (pair().record_job_result: 80C3); a job running when an update starts returns 80C3, held
//   until t5 if it completes inside; SFC 51 -> 8085 during the update.
// - OB 85 (source Image): at a scan, a mapped station with no active image that the master
//   system counts as failed opens an episode (W#16#39B1, once); at the first scan that finds
//   it back: W#16#38B1. An idle line's one-sided slave is not failed: no OB 85.
// - Events: events() merges, in time order, the pair's OB events (72, 121; source Cpu) and
//   every S7 event of the master systems (OB 70/86; source Io). An I/O OB runs on every CPU that
//   runs a program (dp_master_operate): rack -1 when both do (Redundant), the one rack in Solo;
//   when no CPU runs a program no OB runs: the event is only a diagnostic-buffer entry (not in
//   events()). Every powered CPU logs each I/O event in its diagnostic buffer (digest §7 F3:
//   "both CPUs log"); diag_buffer(r) merges the pair's entries and these by time, the pair's
//   first at equal times (the CPU's change comes first, the I/O reaction follows it), the newest
//   diag_capacity entries.
// - LEDs: leds(r) = the pair's CpuLeds plus BUSxF per master system (dark when the CPU is off):
//   On when side r's line is lost by a short circuit or its master module failed (bus or
//   interface fault); Flashing when a station of that line failed (one-sided slave 39C4) or a
//   switched station lost its channel on that line (73A3 owed back) while the line runs; Off
//   otherwise, also when the line is lost only because its CPU/master stopped.
// - The lines must be started (bus::Line::start powers every attachment) before the model is
//   constructed: the construction unpowers the masters of the CPUs that are off.
// - F4 connections, SSL (block at the end of the class, h_system_comms.cpp): an HConnections
//   follows the pair at every reconcile(); its events go into both powered CPUs' buffers;
//   repair_cp() re-establishes the standard connections the CP lost (000 §9.1.4 step 3).
//   read_ssl(id, index) answers SFC 51 byte-exact for xy71, 0F71, 0C75, 0019, 0174, 0222 and
//   0232 index 4 (h_ssl.hpp: layouts, RET_VAL 8082/8083/8085 and every decision).

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_config_change.hpp"
#include "pbvbus/s7h/h_connections.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"
#include "pbvbus/s7h/h_expansion_rack.hpp"
#include "pbvbus/s7h/h_diag_address.hpp"
#include "pbvbus/s7h/h_io_map.hpp"
#include "pbvbus/s7h/h_program_spec.hpp"
#include "pbvbus/s7h/h_rack_power.hpp"
#include "pbvbus/s7cpu/cpu_memory.hpp"
#include "pbvbus/s7h/h_redundant_execution.hpp"
#include "pbvbus/s7h/h_redundant_io.hpp"
#include "pbvbus/s7h/h_s7_memory.hpp"
#include "pbvbus/s7h/h_s7_session.hpp"
#include "pbvbus/s7h/h_sfc90.hpp"
#include "pbvbus/s7h/h_ssl.hpp"
#include "pbvbus/s7h/h_system_records.hpp"
#include "pbvbus/s7h/h_update_measure.hpp"
#include "pbvbus/switched_io/redundant_master_system.hpp"

namespace pbvbus::devices {

struct HSystemEvent {
  /// Cpu: the pair's OB 72/121; Io: the master systems' S7 events (OB 70/86) and OB 85;
  /// Program: the program's own events (error 7960); Alarm: DP-V1 alarms as OBs (40/82/83 ...);
  /// Image: OB 85 (process-image transfer error); Diagnosis: OB 82 from a diagnosis change
  /// (DP-V0 slave, a slave in STOP); Access: OB 122 (direct access to unreachable I/O).
  enum class Source : std::uint8_t { Cpu, Io, Program, Alarm, Image, Diagnosis, Access };
  bus::Ticks time = 0;
  int rack = -1;                  ///< the CPU the OB runs on; -1 = both
  CpuRole role = CpuRole::None;   ///< the role of that CPU (both: Master)
  int ob = 0;                     ///< 70, 72, 86, 121
  std::uint16_t code = 0;         ///< W#16#73A3 ... for I/O events; 0 for OB 72/121
  std::string text;
  Source source = Source::Cpu;
  int system = -1;                ///< master system index (Io), -1 for CPU events
  int line = -1;                  ///< Io: the line concerned
  std::uint8_t station = 0xFF;    ///< Io: the station, 0xFF for the whole master system
  /// When it happened: = time, except for an alarm held during an update (time = delivery
  /// after t5 or the abort, original_time = when the master system received it).
  bus::Ticks original_time = 0;
  bool incoming = true;  ///< Program (7960) and OB 85: false = outgoing ("gone")
  // ---- F3/F15/OB 122 ---- OB start information any OB may fill (docs/h-system.md
  // "Interrupts, ..."): OB 82/83: OB8x_MDL_ADDR = the module's logical address from the I/O
  // map (its input address if it has inputs, else its output address; a station-level event:
  // the station's first module's); OB 122: OB122_MEM_ADDR (the IB/QB address accessed).
  std::uint16_t mdl_addr = 0;
  bool mdl_stop = false;  ///< OB 82: OB82_MDL_STOP (F15: the slave's CPU is in STOP)
  int module = -1;        ///< the module (slot order) concerned, -1 = the station / none
  // ---- end F3/F15/OB 122 ----
};

enum class BusLed : std::uint8_t { Off, On, Flashing };
std::string_view to_string(BusLed l);

struct HSystemLeds {
  CpuLeds cpu;
  std::vector<BusLed> busf;  ///< one per master system (BUS1F, BUS2F, ...)
};

class HSystemModel final : public bus::EventTarget {
 public:
  using Program = std::function<void(std::span<const std::uint8_t> pii,
                                     std::span<std::uint8_t> piq, bus::Ticks now)>;
  using IoGate = std::function<bool(bus::Ticks now)>;
  enum class SideMode : std::uint8_t { Unpowered, Stop, Clear, Operate };

  /// Null entries in `systems` are dropped. The lines must already be started.
  HSystemModel(bus::Scheduler& sched, HCpuPairParams params,
               std::vector<RedundantMasterSystemModel*> systems);
  HSystemModel(const HSystemModel&) = delete;
  HSystemModel& operator=(const HSystemModel&) = delete;
  ~HSystemModel();

  // ---- the program ----
  /// scan_time <= 0 is replaced by 1 ms. An empty hook stops the scans.
  void set_program(Program hook, bus::Ticks scan_time);
  /// The real program (h_program.hpp) on both CPUs with comparison (RedundantExecution) over
  /// the I/O map's PII/PIQ; scan time from the spec. Replaces a hook. Throws
  /// std::invalid_argument("program: " + validate()'s first message).
  void set_program(const ProgramSpec& spec);
  /// The running RedundantExecution, nullptr without a spec.
  const RedundantExecution* execution() const { return m_exec.get(); }
  /// Flips bits of one byte on one CPU only (scenario fault "comparison_error"): the comparison
  /// finds it at the next Redundant scan. False without a spec, bad rack or offset.
  bool inject_divergence(int rack, Area area, std::uint32_t offset, std::uint8_t xor_mask);
  void set_io_gate(IoGate gate) { m_gate = std::move(gate); }

  // ---- operations (at scheduler.now(), then reconciliation) ----
  void power_on(int rack);
  void power_on_both();
  void power_off(int rack);
  void switch_to_run(int rack);
  void switch_to_stop(int rack);
  void cut_fibre(int fibre);
  void cut_both_fibres();
  void repair_fibre(int fibre);
  bool hold(int rack);
  bool release_hold(int rack);
  bool inject_comparison_error();
  bool one_sided_ob121(int rack);
  void inject_hardware_fault(int rack);
  void repair_cpu(int rack);
  bool request_master_swap();
  // The pair's link-up/update operations (h_system_ops.cpp), for the scenario's H faults.
  void set_changed_db_kb(std::uint32_t kb);  ///< F19: the next update copies `kb` KB
  HChangeResult load_change(HChange kind);   ///< F22
  void set_standby_parameter_change(bool may_not_change);  ///< F23 (then a swap: W#16#5966)
  bool memory_reset(int rack);                              ///< F20: clears a reset request
  /// F2: HCpuPair::load_memory_error on `rack` (false: bad rack, CPU off or DEFECTIVE).
  bool load_memory_error(int rack);
  /// A checksum error found by `rack`'s cyclic self-test: HCpuPair::checksum_error(rack,
  /// Cyclic) (001 Table 5-6; h_system_power.cpp, docs/h-changes.md). false: bad rack, CPU off
  /// or DEFECTIVE.
  bool checksum_error(int rack);
  /// F1 with a PS 407 10A R pair per rack (h_system_power.cpp, docs/h-changes.md): half `half`
  /// of `rack`'s PS fails. The other half supplies: an entry W#16#3923 on that CPU, nothing
  /// else (false); none left: power_off(rack) (true). A half already failed: false.
  bool ps_failure(int rack, int half);
  /// That half replaced: W#16#3823 if the other half had kept the CPU on, power_on(rack) if
  /// both had failed (true); false if the half had not failed.
  bool ps_repair(int rack, int half);
  /// An entry in `rack`'s buffer at now from a part built on the model (h_dp_startup.hpp's
  /// W#16#6547); nothing for a bad rack or a CPU that is off.
  void log_entry(int rack, std::string text, std::uint16_t code = 0);
  /// F18 without a program: exactly the reaction of the program's sync error (the standby's
  /// switch_to_stop: standby STOP, Solo, OB 72 StandbyStop on the master; a "sync error (F18)"
  /// entry in both buffers). false (nothing happens) unless the system is Redundant.
  bool inject_sync_error();
  /// Every event of the pair (state, role, system mode, OB) as it happens, after the model
  /// took it in (for a runtime's capture; events() keeps only the OBs).
  void set_pair_event_handler(std::function<void(const HEvent&)> h) {
    m_pair_handler = std::move(h);
  }
  // ---- data-record jobs, SFC 51 (R7; h_system_records.hpp) ----
  /// SFC 59 over MasterSystem::read. Returns 0 (started: `cb` gets the final result later) or
  /// a code at once (cb not called): W#16#80C3 during the update, W#16#8090 for a bad
  /// system/station or no active channel.
  std::uint16_t read_record(std::size_t system, std::uint8_t station, std::uint8_t slot,
                            std::uint8_t index, std::uint8_t length, RecordJobCallback cb);
  /// SFC 58 over MasterSystem::write; as read_record.
  std::uint16_t write_record(std::size_t system, std::uint8_t station, std::uint8_t slot,
                             std::uint8_t index, std::span<const std::uint8_t> data,
                             RecordJobCallback cb);
  /// SFC 51 for the H-system state: W#16#8085 during the update.
  HSystemState read_system_state(bus::Ticks now);

  /// Brings every side in line with its CPU now (the operations do it themselves).
  void reconcile();

  // ---- queries ----
  const HCpuPair& pair() const { return m_pair; }
  std::span<RedundantMasterSystemModel* const> master_systems() const { return m_systems; }
  /// Master system `system`, nullptr if there is none.
  RedundantMasterSystemModel* model(std::size_t system) {
    return system < m_systems.size() ? m_systems[system] : nullptr;
  }
  const HIoMap& io_map() const { return m_map; }
  /// D1: the DP diagnostic addresses (h_diag_address.hpp), from the top of the CPU's I/O
  /// address area (default 16383, a 417-4H). An OB 86 of a station (39C4/38C4 ...) carries
  /// the slave's one in mdl_addr, one of the whole master system its master's.
  void set_diag_address_top(std::uint16_t top);
  const HDiagAddresses& diag_addresses() const { return m_diag; }
  /// OB 1 scans run so far.
  std::uint64_t scans() const { return m_scans; }
  std::span<const std::uint8_t> pii() const { return m_pii; }
  std::span<const std::uint8_t> piq() const { return m_piq; }
  /// What side `rack` of master system `system` was last set to.
  SideMode side_mode(std::size_t system, int rack) const;
  const std::vector<HSystemEvent>& events() const { return m_events; }
  /// Every update's measured times, oldest first (h_update_measure.hpp).
  const std::vector<UpdateMeasure>& update_measures() const { return m_measures; }
  /// Called with every event as it is added to events() (for a runtime's report or capture).
  /// The model owns the MasterSystems' on_event callbacks: read them through this or
  /// MasterSystem::events().
  void set_event_handler(std::function<void(const HSystemEvent&)> h) { m_handler = std::move(h); }
  std::vector<DiagEntry> diag_buffer(int rack) const;
  HSystemLeds leds(int rack) const;

  void on_event(bus::Ticks now, std::uint64_t tag) override;

  // ---- F8 expansion racks, OB 80 ----
  // Decisions (docs/h-system.md "Expansion racks (F8) and OB 80"; h_expansion_rack.hpp has the
  // configuration rules and the event IDs; code in h_system_racks.cpp, h_system_cycle.cpp):
  // - The racks' modules are one-sided central I/O of CPU `side`, appended to the I/O map after
  //   every DP module (h_io_map.hpp: central entries, rack number). A rack is reachable while it
  //   is on and its CPU runs the program (dp_master_operate(side)). At each OB 1 a reachable
  //   rack's inputs go into the PII (in Redundant the PII is shared: the one-sided inputs reach
  //   the partner over the sync link, digest §2, so both CPUs see the same bytes); an
  //   unreachable one keeps its last PII bytes. After OB 1 a reachable rack's modules take
  //   their PIQ bytes (rack_outputs). Counter inputs without a period count the rack's reads.
  // - OB 85 (as for DP, same codes W#16#39B1/38B1, source Image, system -1, station = the rack
  //   number, line = its side): at an OB 1, a rack that was reachable once and is not now
  //   (off, or its CPU not running the program: the partner's Solo, a failed CPU) opens an
  //   episode; the first OB 1 that reaches it again closes it. A rack whose CPU never ran the
  //   program (the standby before its first link-up) is idle: no OB 85.
  // - expansion_rack_off/on (F8): OB 86 W#16#39C1 incoming / W#16#38C1 outgoing at once (source
  //   Io, system -1, station = rack number, line = side), an entry in every powered CPU's
  //   diagnostic buffer; the OB runs on the CPUs running the program (rack -1 in Redundant:
  //   "OB 86 on both") when the rack's own CPU runs it, else only the entries (no running CPU
  //   sees the rack). Nobody notices a change while the rack's CPU is off. No CPU changes state.
  // - OB 80 (time error W#16#3501, source Program: the program's cycle; ob 80): each OB 1 start
  //   arms the cycle monitoring at start + max_cycle_time; if no OB 1 started since, none is due
  //   at that instant (a cycle of exactly the maximum is no overrun) and the program still runs, OB 80 runs on the CPUs running the program (-1 in Redundant) and both
  //   powered CPUs log it, once per overrun cycle. cycle_overload(extra): the next OB 1 lasts
  //   scan_time + extra. A cycle that an update falls into ([t1, t5) began after its start or
  //   is running) is monitored with max_cycle_time + the "max scan-cycle extension" H parameter
  //   (digest §3.1: normal cycle monitoring is suspended during the update); with no extension
  //   configured (0 or unset) such a cycle is not monitored. Not modelled: the STOP when OB 80
  //   is called twice in one cycle (a cycle > 2 x max gives one OB 80).

  /// The model with expansion racks: as set_expansion_racks (a bad configuration throws before
  /// anything is scheduled).
  HSystemModel(bus::Scheduler& sched, HCpuPairParams params,
               std::vector<RedundantMasterSystemModel*> systems, std::vector<HExpansionRack> racks);
  /// The expansion racks (before the run): appended to the I/O map, the images grow. Throws
  /// std::invalid_argument("expansion racks: " + the first problem) for a bad configuration
  /// (check_expansion_racks), after set_program(ProgramSpec) or once an OB 1 ran (the images'
  /// sizes are fixed then); the model is then unchanged. Replaces racks set before.
  void set_expansion_racks(std::vector<HExpansionRack> racks);
  const std::vector<HExpansionRack>& expansion_racks() const { return m_rack_cfg; }
  /// F8: rack `number` loses power / its IM 460-461 link; false (nothing happens) if there is no
  /// such rack or it is off already.
  bool expansion_rack_off(int number);
  /// F8 repair: power back; false if there is no such rack or it is on.
  bool expansion_rack_on(int number);
  /// false also for an unknown rack.
  bool expansion_rack_is_on(int number) const;
  /// On and its CPU runs the program.
  bool expansion_rack_reachable(int number) const;
  /// An OB 85 episode is open for the rack.
  bool expansion_rack_ob85(int number) const;
  /// The octets a module's outputs got at the last OB 1 that reached the rack (zeros before);
  /// empty for an unknown rack/module.
  std::span<const std::uint8_t> rack_outputs(int number, std::size_t module) const;
  /// The module's inputs as last read into the PII; empty for an unknown rack/module.
  std::span<const std::uint8_t> rack_inputs(int number, std::size_t module) const;

  /// OB 80's maximum cycle time (S7 default 150 ms). <= 0: std::invalid_argument.
  void set_max_cycle_time(bus::Ticks t);
  bus::Ticks max_cycle_time() const { return m_max_cycle; }
  /// cycle_overload: the next OB 1 to start lasts scan_time + extra (the one after starts that
  /// much later); several before one OB 1 add up. false (nothing) if extra <= 0.
  bool cycle_overload(bus::Ticks extra);
  /// OB 80 calls so far.
  std::uint64_t ob80_count() const { return m_ob80; }

 private:
  struct RackState {
    bool on = true;
    bool ran = false;   ///< its CPU ran the program once (before: idle, no OB 85)
    bool ob85 = false;  ///< OB 85 episode open
    std::uint64_t reads = 0;
    std::vector<std::vector<std::uint8_t>> in, out;  ///< per module
  };
  static std::vector<RedundantMasterSystemModel*> racks_checked(
      std::vector<RedundantMasterSystemModel*> systems, const std::vector<HExpansionRack>& racks);
  int rack_index(int number) const;
  bool rack_reachable(std::size_t k) const;
  void rack_event(std::size_t k, bool failed);
  void read_racks(bus::Ticks now);  ///< at each OB 1: OB 85, the reachable racks' inputs
  void write_racks();               ///< after OB 1: the PIQ into the reachable racks' modules
  /// The same with a PIQ per side (two masters: each rack takes its own CPU's outputs).
  void write_racks(std::span<const std::uint8_t> piq0, std::span<const std::uint8_t> piq1);
  bus::Ticks end_cycle(bus::Ticks start);  ///< the next OB 1's start; arms the monitoring
  void cycle_check(bus::Ticks start, bool extended);
  std::vector<HExpansionRack> m_rack_cfg;
  std::vector<RackState> m_racks;
  bus::Ticks m_max_cycle = 150 * bus::kTicksPerMs;
  bus::Ticks m_pending_extra = 0;
  bus::Ticks m_cycle_start = bus::kNever;  ///< start of the last OB 1 (also a gated one)
  bus::Ticks m_cycle_next = bus::kNever;   ///< when the next OB 1 is planned
  std::uint64_t m_ob80 = 0;
  // ---- end F8 expansion racks, OB 80 ----

 private:
  struct Side {
    SideMode mode = SideMode::Operate;  ///< unknown at construction: forced by the first pass
    bool known = false;
    bool ran = false;
  };
  void after_op();
  void arm_deadline();
  void arm_scan(bus::Ticks at);
  bool program_runs() const;
  bool has_program() const { return m_program || m_exec; }
  SideMode target(int rack) const;
  void apply(std::size_t system, int rack, SideMode to);
  void scan(bus::Ticks now);
  void scan_execution(bus::Ticks now);  // h_system_program.cpp
  /// F18's reaction (h_system_ops.cpp): diag entries on both CPUs, the standby to STOP.
  void sync_error_reaction(int standby, bus::Ticks now, std::string_view cause);
  void track_update(bus::Ticks now);    // h_system_update.cpp
  void on_alarm(std::size_t system, const redundancy::SystemAlarm& a);  // h_system_alarms.cpp
  void deliver_alarm(HSystemEvent h, bus::Ticks now);
  void deliver_held(bus::Ticks now);
  std::uint16_t start_record(std::size_t system, std::uint8_t station, bool write,
                             std::uint8_t slot, std::uint8_t index, std::uint8_t length,
                             std::span<const std::uint8_t> data, RecordJobCallback cb);
  void check_process_image(bus::Ticks now);  // OB 85, h_system_alarms.cpp
  void on_program_event(const ProgramEvent& e, std::array<bool, 2> ran);
  void on_pair_event(const HEvent& e);
  void on_io_event(std::size_t system, const redundancy::SystemEvent& e);
  void add_event(HSystemEvent e);
  /// Every powered CPU logs an entry with its role (F3 "both CPUs log").
  void log_on_powered(bus::Ticks now, std::uint16_t code, const std::string& text);
  bool valid_rack(int r) const { return r == 0 || r == 1; }

  bus::Scheduler& m_sched;
  HCpuPair m_pair;
  std::vector<RedundantMasterSystemModel*> m_systems;
  std::vector<std::array<Side, 2>> m_side;
  HIoMap m_map;
  HDiagAddresses m_diag;  ///< D1
  std::vector<std::uint8_t> m_pii, m_piq;
  Program m_program;
  std::unique_ptr<RedundantExecution> m_exec;
  bool m_split_outputs = false;  ///< the last scan had two masters (F6/F7): outputs per side
  std::vector<UpdateMeasure> m_measures;
  bool m_update_copied = false;  ///< the last measure's output/state copy (t4) is done
  bus::Ticks m_last_scan = bus::kNever;  ///< start of the last OB 1
  std::string m_ob72_note;  ///< appended to the next OB 72 ComparisonError text (F16's place)
  std::vector<HSystemEvent> m_held_alarms;  ///< received while interrupts_held()
  struct HeldRecord {
    RecordJobCallback cb;
    RecordJobResult res;
  };
  std::vector<HeldRecord> m_held_records;  ///< jobs completed during the update (80C3 after t5)
  std::vector<std::vector<bool>> m_ob85;   ///< [system][address]: OB 85 episode open
  IoGate m_gate;
  bus::Ticks m_scan_time = bus::kTicksPerMs;
  bool m_scan_armed = false;
  std::uint64_t m_scans = 0;
  std::uint64_t m_gen = 0;  ///< generation of the armed pair deadline
  bus::Ticks m_armed_at = bus::kNever;
  std::vector<HSystemEvent> m_events;
  std::function<void(const HSystemEvent&)> m_handler;
  std::function<void(const HEvent&)> m_pair_handler;
  std::array<std::vector<DiagEntry>, 2> m_io_diag;
  std::array<std::array<bool, 2>, 2> m_ps_failed{};  ///< [rack][half]: PS 407 10A R half failed

  // ---- F4 connections, SSL ----
  // (controllers/s7h/src/h_system_comms.cpp; rules in h_connections.hpp and h_ssl.hpp). The
  // connections follow the pair at every reconcile(); their events go into both powered CPUs'
  // diagnostic buffers (000 §9.1.4: "both CPUs report the event").
 public:
  /// Configuration before the run ("" or the error text; h_connections.hpp).
  std::string add_cp(const CpConfig& cp) { return m_comms.add_cp(cp); }
  std::string add_connection(const ConnectionConfig& c);
  /// F4: the CP fails now. false: no such CP or already failed.
  bool cp_failure(int rack, int cp);
  /// The CP is replaced now: fault-tolerant connections regain the path as a reserve, and the
  /// partner re-establishes the standard connections over it that were lost (000 §9.1.4 step
  /// 3, "the system establishes the connection automatically"). false: not failed / no CP.
  bool repair_cp(int rack, int cp);
  /// The partner re-establishes a lost connection now (false: unknown, not lost, refused).
  bool reestablish(std::string_view name);
  const HConnections& comms() const { return m_comms; }
  /// SFC 51 RDSYSST: the SSL partial list `id`/`index`, answered by the master (h_ssl.hpp).
  SslResult read_ssl(std::uint16_t id, std::uint16_t index);

 private:
  void comms_update(bus::Ticks now);
  void comms_log(bus::Ticks now);
  SslResult ssl_h_state(int cpu) const;
  SslResult ssl_switched_slave(std::uint16_t index) const;
  SslResult ssl_leds(int cpu, std::uint16_t id, std::uint16_t index) const;
  SslResult ssl_interrupt(std::uint16_t index) const;
  SslResult ssl_protection(int cpu, std::uint16_t index) const;
  HConnections m_comms;
  std::size_t m_comms_logged = 0;  ///< comms events already in the diagnostic buffers

  // ---- F3/F15/OB 122 ---- (h_system_diag.cpp; docs/h-system.md "Interrupts, ...")
  // - OB 82 (W#16#3942 incoming / W#16#3842 outgoing, EV_CLASS 39/38, FLT_ID 42) from a DP-V1
  //   Diagnostic alarm AND from a change of the station's diagnosis on its active channel
  //   (MasterSystem::on_diagnosis): per mapped module, "faulty" = a channel block for one of
  //   its identifiers or its bit in the identifier-related block; a change of that state is one
  //   OB 82 for the module (mdl_addr = its address). A diagnosis that carries a DP-V1
  //   Diagnostic/Pull/Plug alarm PDU for the module's slot (slot = module + 1) updates the state
  //   silently: the alarm is that module's OB (no OB 82 twice; dp::Master reports the diagnosis
  //   before the alarm it contains). Station level: the S7 diagnostic record 0 with MDL_STOP
  //   (slave_fault.hpp; DP-V0 device block of 5 octets or Status_Message 0x81 slot 0) -> OB 82
  //   3942 mdl_stop = 1 / 3842 mdl_stop = 0 (F15), mdl_addr = the station's first module.
  // - OB 83: pull alarm W#16#3961 (module removed), plug alarm W#16#3861 (module inserted, type
  //   OK); the module counts as not reachable for OB 122 between them.
  // - OB 122 (digest D1): a copy network with `direct` (L PIB / T PQB) whose source or target
  //   bytes lie in a module that is not reachable (no active channel, or pulled) -> OB 122
  //   W#16#2942 (read) / W#16#2943 (write), once per network, direction and scan while it
  //   lasts (S7 calls it per access; one per network is what the program sees per scan); the
  //   read bytes are 0 for that scan (only for the program's run; pii() keeps the image), the
  //   write goes nowhere (the station is not there).
  // - Every one of these events is logged in both powered CPUs' diagnostic buffers (F3: "both
  //   CPUs log"); the OB runs on the CPUs running the program (rack -1 = both, synchronously).
  // - Automatic re-parameterisation (F3): after a plug (OB 83 W#16#3861, from the alarm or the
  //   Module_Status) the master writes the module's parameter data record, as the S7 CPU sends
  //   a plugged module its parameter records: MSAC_C1 Write (MasterSystem::write over the
  //   active channel) to slot = module + 1 with the index and octets the configuration gave
  //   (set_module_parameters; the GSD's module parameters). A module without a registered
  //   record gets none (the model knows no parameters for it). The result is not an OB.
 public:
  /// Registers module `module`'s parameter data record (index, octets <= 240) written after
  /// each plug (one per index, written in registration order; the same index again replaces
  /// it). False: bad system/station/module or record length.
  bool set_module_parameters(std::size_t system, std::uint8_t station, std::size_t module,
                             std::uint8_t index, std::vector<std::uint8_t> record);
  /// Parameter records written after plugs so far (the jobs started).
  std::uint64_t reparameterisations() const { return m_reparams; }
  /// OB 122 episodes so far (one per network, direction and scan).
  std::uint64_t access_errors() const { return m_access_errors; }

 private:
  void on_diagnosis(std::size_t system, const redundancy::SystemDiagnosis& d);
  /// OB 82/83 start information of a DP-V1 alarm (code, mdl_addr, module) and its bookkeeping.
  void alarm_start_info(std::size_t system, const redundancy::SystemAlarm& a, HSystemEvent& h);
  /// mdl_addr of module `module` of a station (-1: the station's first module).
  std::uint16_t module_address(int system, std::uint8_t station, int module) const;
  bool module_reachable(const HIoEntry& e) const;
  /// OB 122 for the direct networks; zeroes the unreachable source bytes in `pii`.
  void direct_access(bus::Ticks now, std::vector<std::uint8_t>& pii);
  /// An I/O event in both powered CPUs' buffers, then (if a program runs) as an OB.
  void io_ob(HSystemEvent h);
  static std::uint32_t module_key(int system, std::uint8_t station, std::size_t module) {
    return (static_cast<std::uint32_t>(system) << 24) | (std::uint32_t{station} << 16) |
           static_cast<std::uint32_t>(module & 0xFFFF);
  }
  std::vector<std::uint32_t> m_faulty;   ///< module_key: faulty in the last diagnosis
  std::vector<std::uint32_t> m_pulled;   ///< module_key: "no module" in the last diagnosis
  std::vector<std::uint32_t> m_pulled_alarm;  ///< module_key: pull alarm, no plug alarm yet
  std::vector<std::uint32_t> m_stopped;  ///< module_key(system, station, 0xFFFF): MDL_STOP
  std::vector<CopyNetwork> m_direct;     ///< the spec's copy networks (those with `direct` count)
  std::vector<std::uint8_t> m_direct_pii;
  std::uint64_t m_access_errors = 0;
  struct ModulePrm {
    std::uint32_t key = 0;
    std::uint8_t index = 0;
    std::vector<std::uint8_t> record;
  };
  std::vector<ModulePrm> m_module_prm;
  std::uint64_t m_reparams = 0;
  void reparameterise(int system, std::uint8_t station, std::size_t module);
  // ---- end F3/F15/OB 122 ----

  // ---- S7 communication ---- (h_system_s7.cpp; h_s7_memory.hpp, h_s7_session.hpp;
  // docs/h-system.md "S7 communication"). Every CPU serves S7 on its own memory: I = its PII,
  // Q = its PIQ, M and the DBs in its image's memory area (the program's state from MB 0),
  // counters and timers. A Write Var reaches both CPUs while the standby's copy is live
  // (Redundant, or after the update's copy at t4), so the comparison stays quiet; otherwise the
  // answering CPU only (a standby in LINK-UP/UPDATE before t4 gets it from the update's copy).
  // Sessions are checked at every reconcile() and at every use.
 public:
  /// The CPUs' S7 memory. Before the first OB 1 (a set_program(ProgramSpec) before is rebuilt
  /// with the new memory area). Until it is called: M = the program's memory exactly (no free
  /// flags), no DBs, 256 counters and timers. Throws std::invalid_argument("s7 memory: " + the first
  /// problem) for a bad configuration or after the first OB 1; the model is then unchanged.
  void set_s7_memory(HS7MemoryConfig c);
  const HS7MemoryConfig& s7_memory() const { return m_s7_cfg; }
  /// Where M and the DBs lie in each CPU's memory area now.
  const HS7Layout& s7_layout() const { return m_s7_layout; }
  /// The order number SZL 0011 reports (the configuration's, else the profile's).
  std::string s7_order_number() const;
  /// CPU `rack`'s memory as S7 sees it (a view bound to its storage now; the owner's user
  /// program and tests read and write it). Throws std::out_of_range for a bad rack.
  s7cpu::CpuMemory& s7_cpu_memory(int rack);

  /// (a) an ad-hoc S7 connection to CPU `rack` through its MPI interface (HCpuPair::connect).
  HS7Session open_s7_adhoc(int rack);
  /// (b)/(c) the configured connection `name` (standard or fault-tolerant; it must be
  /// established and not in use by another session).
  HS7Session open_s7_connection(std::string_view name);
  /// (d) S7 routing through the master to `device`, behind switched station `station` of
  /// master system `system`.
  HS7Session open_s7_routing(std::size_t system, std::uint8_t station, S7Endpoint device);
  /// Sessions not closed yet.
  std::size_t s7_sessions_alive() const;
  /// SFC 51 / Read SZL answered by CPU `rack` (powered) instead of the master: as read_ssl.
  SslResult read_ssl_on(int rack, std::uint16_t id, std::uint16_t index);

 private:
  friend class HS7Session;
  struct S7SessionState;
  struct S7SessionDeleter {
    void operator()(S7SessionState* s) const;
  };
  using S7SessionPtr = std::unique_ptr<S7SessionState, S7SessionDeleter>;
  SslResult ssl_from(int cpu, std::uint16_t id, std::uint16_t index);
  void s7_prepare();  ///< storage of the right sizes for the layout
  void s7_bind(s7cpu::CpuMemory& mem, int rack);
  bool s7_mirror_live() const;
  void s7_update(bus::Ticks now);           ///< every session's check (comms_update)
  void s7_copy_update(int from, int to);    ///< the update's copy at t4
  void s7_check(S7SessionState& s);
  int s7_answering(const S7SessionState& s) const;
  S7SessionState* s7_find(std::uint32_t id) const;
  HS7Session s7_open(S7SessionPtr s);
  void s7_finish(S7SessionState& s, S7CloseReason why, std::string text);
  std::vector<std::uint8_t> s7_handle(std::uint32_t id, std::span<const std::uint8_t> pdu);
  void s7_release(std::uint32_t id);
  /// Until set_s7_memory(): no flags beyond the program's memory and no DBs, so a model whose
  /// S7 memory is not configured keeps the images it had before S7 (the scenario's comparison
  /// fault tells a program with state from one without by an empty memory area).
  HS7MemoryConfig m_s7_cfg = unconfigured_s7_memory();
  HS7Layout m_s7_layout = layout(unconfigured_s7_memory(), 0);
  static HS7MemoryConfig unconfigured_s7_memory() {
    HS7MemoryConfig c;
    c.flags = 0;
    return c;
  }
  std::array<std::vector<std::uint8_t>, 2> m_s7_work;  ///< M + DBs without a ProgramSpec
  std::array<std::vector<std::uint16_t>, 2> m_s7_counters, m_s7_timers;
  std::array<s7cpu::CpuMemory, 2> m_s7_views;
  std::unique_ptr<ProgramSpec> m_s7_spec;  ///< the spec set_program() got (rebuilt on a change)
  std::vector<std::pair<std::uint32_t, S7SessionPtr>> m_s7_sessions;
  std::uint32_t m_s7_next = 1;
  // ---- end S7 communication ----

  // ---- redundant I/O ---- (h_system_redundant_io.cpp; docs/h-redundant-io.md "In the
  // H-system model"). Module pairs of the I/O map run through RedundantIo at every OB 1:
  // RED_IN on the PII after the inputs are read, RED_OUT on what goes to the outputs (the
  // program's PIQ is unchanged). OB 82 / OB 85 of a paired module (events()) -> RED_DIAG;
  // a CPU entering STARTUP (OB 100) and the system entering Redundant (OB 72) request a
  // depassivation; red_depa() is FC 451. Its entries (796x) go into both powered CPUs'
  // buffers and into events() (source Program, ob 0) as the program's 7960 does.
 public:
  /// One module of a pair, by its place in the I/O map.
  struct RedIoModule {
    int system = 0;
    std::uint8_t station = 0;
    std::size_t module = 0;
  };
  struct RedIoPair {
    RedIoPairSpec spec;  ///< kind, times, window, reactions; addresses and length are resolved
    RedIoModule a, b;    ///< the two modules (module_L is the one at the lower address)
  };
  /// Before the run. Throws std::invalid_argument("redundant I/O: " + the first problem): an
  /// unknown module, no inputs (DI/AI) or outputs (DO/AO), different lengths, RedundantIo's
  /// validate(); the model is then unchanged.
  void set_redundant_io(const std::vector<RedIoPair>& pairs);
  /// nullptr without pairs.
  const RedundantIo* redundant_io() const { return m_red_io.get(); }
  /// FC 451 RED_DEPA (false: no pairs, or nothing passivated).
  bool red_depa();

 private:
  void red_io_in(bus::Ticks now);
  std::span<const std::uint8_t> red_io_out(std::span<const std::uint8_t> piq);
  void red_io_on_event(const HSystemEvent& e);
  void red_io_on_pair_event(const HEvent& e);
  void red_io_flush();
  std::unique_ptr<RedundantIo> m_red_io;
  std::vector<std::uint8_t> m_red_io_out;
  std::size_t m_red_io_seen = 0;  ///< RedundantIo events already in events()
  // ---- end redundant I/O ----

  // ---- SFC 90 H_CTRL, watchdog OBs during the update (R7), held S7 jobs ----
  // Code: h_system_sfc90.cpp; rules and sources: docs/h-sfc90.md.
  // - h_ctrl(MODE, SUBMODE) is SFC 90 called by the user program (h_sfc90.hpp has the table
  //   and RET_VAL). From inside an OB 1 (the hook, or a ProgramSpec's h_ctrl_calls at the first
  //   OB 1 at/after their time) its effect on the pair (the update starting at MODE 4) takes
  //   place when that OB 1 ends, at the same instant (the update delays OB 1, step 3).
  // - Watchdog OBs 30..38 (set_watchdog_ob): requested every period from their configuration
  //   while the program runs; from t1 to t5 of an update no request is made (000 L1177 step 3);
  //   at t5 (or the abort) each OB that lost at least one request runs exactly once ("a maximum
  //   of one request ... for each watchdog interrupt OB", 000 L1179) and its cycle restarts from
  //   there (equidistance lost, 000 L1198-1201); an OB that lost none keeps its phase.
  // - S7 jobs of a session with a late-answer sink (HS7Session::on_late_answer) arriving from
  //   t1 to t5 are stored (handle() answers nothing) and answered in arrival order at t5 or the
  //   abort through the sink (000 L1673-1680). Sessions without a sink are answered at once.
 public:
  std::uint16_t h_ctrl(std::uint8_t mode, std::uint8_t submode);
  const HSelfTestControl& self_test() const { return m_self_test; }
  struct HCtrlRecord {
    bus::Ticks at = 0;
    std::uint8_t mode = 0, submode = 0;
    std::uint16_t ret_val = 0;
  };
  const std::vector<HCtrlRecord>& h_ctrl_calls() const { return m_hctrl_calls; }

  struct WatchdogRun {
    int ob = 0;
    bus::Ticks at = 0;
    bool after_update = false;  ///< the single delayed request at the end of an update
  };
  /// OB 30..38 every `period` (> 0) from now; `body` runs at each execution. A second call for
  /// the same OB replaces it. Throws std::invalid_argument for another OB or period <= 0.
  void set_watchdog_ob(int ob, bus::Ticks period, std::function<void(bus::Ticks)> body = {});
  const std::vector<WatchdogRun>& watchdog_runs() const { return m_wd_runs; }
  /// S7 jobs stored now (from t1 to t5 of an update), not yet answered.
  std::size_t held_s7_jobs() const { return m_held_jobs.size(); }
  /// SFC 27 UPDAT_PO: the PIQ bytes of the expansion-rack modules of partition `part` (1..15)
  /// go to the reachable modules now. RET_VAL 0, or W#16#8090 for a PART outside 1..15.
  std::uint16_t updat_po(int part);
  /// OB 72 "redundancy restored", run on entering Redundant mode (000 L1752: the program must
  /// refresh its output partitions there with SFC 27); the times it ran.
  void set_ob72_return(std::function<void(bus::Ticks)> body) { m_ob72_return = std::move(body); }
  const std::vector<bus::Ticks>& redundancy_returns() const { return m_returns; }

 private:
  friend class HS7Session;
  struct WatchdogOb {
    int ob = 0;
    bus::Ticks period = 0;
    std::function<void(bus::Ticks)> body;
    bus::Ticks next = 0;
    bool lost = false;  ///< a request fell into the update
    std::uint64_t gen = 0;
  };
  struct HeldJob {
    std::uint32_t id = 0;
    std::vector<std::uint8_t> pdu;
  };
  void sfc90_reconcile(bus::Ticks now);  ///< from reconcile(): the update's end
  void wd_arm(std::size_t i);
  void wd_fire(std::size_t i, std::uint64_t gen);
  void wd_run(WatchdogOb& w, bus::Ticks now, bool after_update);
  void run_program_h_ctrl(bus::Ticks now);  ///< a ProgramSpec's h_ctrl_calls due at this OB 1
  void after_scan_h_ctrl();
  bool s7_hold(std::uint32_t id, std::span<const std::uint8_t> pdu);
  bool s7_holds(std::uint32_t id) const;  ///< s7_hold's rule: a job arriving now is stored
  void s7_set_sink(std::uint32_t id, std::function<void(std::vector<std::uint8_t>)> sink);
  HSelfTestControl m_self_test;
  std::vector<HCtrlRecord> m_hctrl_calls;
  bool m_in_scan = false;
  bool m_hctrl_after_scan = false;
  const ProgramSpec* m_hctrl_spec = nullptr;
  std::vector<bool> m_hctrl_done;
  std::vector<WatchdogOb> m_wd;
  std::vector<WatchdogRun> m_wd_runs;
  std::vector<HeldJob> m_held_jobs;
  std::vector<std::pair<std::uint32_t, std::function<void(std::vector<std::uint8_t>)>>> m_sinks;
  std::function<void(bus::Ticks)> m_ob72_return;
  std::vector<bus::Ticks> m_returns;
  bool m_was_redundant = false;
  // ---- end SFC 90 ----

  // ---- switch to CPU with modified configuration ---- (h_system_config_change.cpp;
  // docs/h-changes.md "In the H-system model"). The operator's swap (request_master_swap(), the
  // scenario's master_swap) is HConfigChange's "switch to CPU with modified configuration" with
  // nothing changed (000 L1120; §10.4.6 L3364-3388):
  // - the new master's first OB 1 at or after the swap (t5) has OB1_SCAN_1 = B#16#05, every
  //   other OB 1 B#16#03 (ob1_scan_1() while the hook runs; first_ob1_after_swap());
  // - at t5 the new master's central output modules (its expansion racks) are reset to 0 and
  //   that first OB 1 does not write them: 0 for one OB 1 cycle (000 L3388 "briefly");
  // - the old master STOPs: its DP master stops (reconcile: side Stop), so its one-sided DP
  //   slaves go to their fail-safe/substitute values, and its central modules hold their
  //   values (no longer addressed), until it runs again (Redundant);
  // - on the return to Redundant one OB 83 W#16#3861 (plug, "to be ignored", 000 L3412) per
  //   added switched module on both CPUs (source Alarm, rack -1, mdl_addr = its address).
 public:
  /// PG/ES "Switch to CPU with ..." now (HConfigChange::request; the variant's checks, refused:
  /// entries on both CPUs, false). `added_switched`: addresses of the switched modules the new
  /// configuration adds (OB 83 at the return to Redundant).
  bool switch_to_cpu(HSwitchVariant v, const HCpuConfig& master, const HCpuConfig& standby,
                     std::vector<int> added_switched = {});
  /// The last accepted switch (or the first refused one); nullptr before any request.
  const HConfigChange* config_change() const { return m_cc.get(); }
  /// OB1_SCAN_1 of the OB 1 running now (the hook may read it), else of the last one.
  std::uint8_t ob1_scan_1() const { return m_ob1_scan_1; }
  /// Start times of the OB 1s with OB1_SCAN_1 = B#16#05.
  const std::vector<bus::Ticks>& first_ob1_after_swap() const { return m_ob1_after_swap; }
  /// The 000 §5.2.3 attributes (HDbBlock) of `rack`'s DBs: the standby's are the new
  /// configuration's (h_system_db_copy.cpp). Set for both racks, a ModifiedConfiguration switch
  /// applies plan_modified_configuration_copy() to the DBs of set_s7_memory(); else the update
  /// copies every DB (as before).
  void set_db_blocks(int rack, std::vector<HDbBlock> blocks);
  /// DB `number` in `rack`'s memory area (empty: not configured).
  std::span<std::uint8_t> s7_db(int rack, std::uint16_t number);
  /// The copy plan of the last accepted ModifiedConfiguration switch with blocks set.
  const std::optional<HModifiedConfigCopy>& db_copy_plan() const { return m_cc_plan; }

 private:
  std::span<std::uint8_t> s7_work_area(int rack);
  /// At the request: the plan (aborted: refused), the standby's memory kept aside.
  bool cc_plan_db_copy(const HCpuConfig& standby);
  void cc_apply_db_copy(int old_master, int new_master);  ///< at the update's copy (once)
  std::array<std::vector<HDbBlock>, 2> m_cc_blocks;
  std::array<bool, 2> m_cc_blocks_set{false, false};
  std::optional<HModifiedConfigCopy> m_cc_plan;
  std::vector<std::uint8_t> m_cc_standby_mem;
  void cc_observe();  ///< from reconcile(): the swap (racks reset), the return to Redundant
  void cc_ob1(bus::Ticks now);  ///< at each OB 1 start: OB1_SCAN_1, the zero cycle
  std::unique_ptr<HConfigChange> m_cc;
  std::uint8_t m_ob1_scan_1 = kOb1ScanFreeCycle;
  int m_cc_zero_side = -1;  ///< this OB 1 leaves that side's racks' outputs at 0
  bool m_cc_swap_done = false;
  bool m_cc_ob83_done = false;
  std::vector<bus::Ticks> m_ob1_after_swap;
  // ---- end switch to CPU with modified configuration ----

  // ---- the racks' power supply, RAM test ---- (h_system_rack_power.cpp; docs/h-changes.md
  // "In the H-system model")
 public:
  /// From now on power_on(), power_on_both() and power_off() go through an HRackPower on the
  /// pair (h_rack_power.hpp): an unbuffered POWER ON (the first one, or a rack without backup
  /// battery) with ram_kb > 0 runs the RAM test, ram_kb x 8 s / 1024 (000 L640, 001
  /// L1149-1153), and the pair powers the CPU only at its end; during it the CPU is off. Call it
  /// before the first power-on (replaces an earlier one).
  void set_rack_power(HRackPowerParams p);
  /// nullptr until set_rack_power().
  const HRackPower* rack_power() const { return m_rp.get(); }

 private:
  void rack_power_arm();  ///< a scheduler event at the end of the next RAM test
  std::unique_ptr<HRackPower> m_rp;
  bus::Ticks m_rp_armed = bus::kNever;
  // ---- end the racks' power supply ----

  // ---- "transfer of parameters to modules", W#16#6547 ---- (h_system_dp_startup.cpp;
  // h_dp_startup.hpp; docs/h-changes.md "In the H-system model")
 public:
  /// The monitoring time in 100 ms units (001 L8094-8114; recommended 600 = 60 s); 0 = off (the
  /// default: the model's earlier behaviour). From then on each CPU's STARTUP and each standby's
  /// UPDATE (its DP master starts parameterising, 001 Fig. 6-1) starts it over the stations its
  /// DP master(s) configure; a station not in data exchange at the end: W#16#6547 on that CPU.
  void set_param_transfer_time(std::uint32_t units_100ms);
  std::uint32_t param_transfer_time_100ms() const { return m_ptt; }
  /// The late stations of `rack`'s last ended monitoring (empty: in time, or none ended).
  const std::vector<std::uint8_t>& param_transfer_late(int rack) const {
    return m_ptt_late[rack == 1 ? 1 : 0];
  }

 private:
  void ptt_on_pair_event(const HEvent& e);
  void ptt_end(int rack, std::uint64_t gen, bus::Ticks start);
  std::uint32_t m_ptt = 0;
  std::array<std::uint64_t, 2> m_ptt_gen{0, 0};
  std::array<std::vector<std::uint8_t>, 2> m_ptt_late;
  // ---- end "transfer of parameters to modules" ----
};

}  // namespace pbvbus::devices
