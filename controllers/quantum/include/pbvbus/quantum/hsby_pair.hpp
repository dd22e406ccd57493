#pragma once
// The Modicon Quantum Hot Standby pair (seed 003 pp. 16-22 and 86-95, seeds-digest.md §8, §11
// Q5-Q7): two racks, each with power, a CPU, a CHS 110 hot-standby module (keyswitch, A/B
// designation slide switch, update button, LEDs) and a remote I/O head (io_head.hpp), the fibre
// link between the CHS modules, and the per-scan state RAM transfer of a TransferPlan
// (transfer_plan.hpp). Sans-I/O on a bus::Scheduler: every operation acts at scheduler.now()
// and is followed by the reconciliation (as the H-system model does); scans, transfer
// completions, the standby's transfer watchdog and the program update are scheduler events.
// docs/quantum-hsby-pair.md ("The pair") has every decision and its reason; in short:
//
// - States per rack: Off (unpowered), Offline, Primary, Standby. A stopped CPU (stop_cpu) is
//   Offline with cpu_running() false until start_cpu().
// - Power-on (the designation slide switch is read here): the first unit to power with its
//   key at Run (override: its run bit) becomes Primary. A later unit becomes Standby if it
//   wants to run, the fibre is Ok, the designations differ and the logic matches (or the
//   mismatch option is set); same designation -> Offline, Com Act blinking (Q6); fibre not
//   crossed -> Offline (Com Err); key at Off Line -> Offline.
// - Keyswitch (ignored under override): primary to Off Line -> planned switchover at the
//   primary's next scan boundary when the other unit is Standby (alone: it stays Primary and
//   the event log says so); primary to Xfer -> ignored (Q7); a standby or offline unit's Xfer
//   alone changes nothing; Xfer + update button -> program update (below); Offline unit to Run
//   -> Standby (other Primary and conditions hold) or Primary (no other Primary).
// - Keyswitch override: the run bits of the command register (4x index `command_register` of
//   the primary's state RAM, read at every scan start and at once when override is enabled):
//   0x0002 (Modicon bit 15) = designation A, 0x0004 (bit 14) = designation B. The primary's bit
//   0 -> planned switchover, the old primary goes Offline; both 0 -> the same, and the new
//   primary (whose bit is 0 too) continues, alone (Q5, seed p. 90). A standby's bit 0 -> it goes
//   Offline; an Offline unit's bit 1 -> Standby when the conditions hold. No program update.
// - Logic mismatch (program identities differ): default -> the other unit stays/goes Offline,
//   so no switchover is possible; option -> it stays Standby and takes over with its own program.
// - Unplanned failures: the standby expects a transfer at each of the primary's scan starts;
//   when none starts it asks its IoHead: hears_active_master -> fibre fault: the standby goes
//   Offline (Com Err), the primary runs alone; silent -> takeover at that instant (the new
//   primary's first scan), i.e. within one scan of the failure (Q7). A standby failure: the
//   primary runs alone. A transfer in flight at a failure is lost (event TransferLost).
//   (line_check_delay: a second question to the head after its silence bound, see below.) A
//   standby that has not received a completed transfer since it joined does not take over: it
//   goes Offline (its state RAM is from before its outage). Two
//   primaries (fibre and line silent) meeting again over the fibre: the later goes Offline.
// - A planned handover ends a scan: a new primary always runs its first scan before it may
//   hand control back.
// - Scan (primary only, every scan_time): the snapshot of the plan's every_scan ranges plus the
//   additional slice (scan number mod slices) without the non-transfer area, then
//   read_inputs, the logic hook, write_outputs. The snapshot lands in the standby's state RAM
//   at scan start + transfer_time; the non-transfer area's registers 1-2 go the other way
//   (standby -> primary) at the same instant; register 3 is each unit's own status register.
//   The standby runs no logic. Offline and unpowered units keep their state RAM.

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/time.hpp"
#include "pbvbus/quantum/io_head.hpp"
#include "pbvbus/quantum/state_ram.hpp"
#include "pbvbus/quantum/transfer_plan.hpp"

namespace pbvbus::quantum {

enum class CpuState : std::uint8_t { Off, Offline, Primary, Standby };
enum class KeySwitch : std::uint8_t { OffLine, Xfer, Run };
enum class Designation : std::uint8_t { A, B };
/// The fibre between the two CHS 110 modules. TxRxNotCrossed: no communication at all (seed
/// p. 24: the primary runs without a backup, the standby stays offline).
enum class FibreState : std::uint8_t { Ok, TxRxNotCrossed, Cut };
/// A CHS 110 LED (seed p. 19): the seed says "steady" and "blinking"/"flashing".
enum class Led : std::uint8_t { Off, On, Blinking };

std::string_view to_string(CpuState s);
std::string_view to_string(KeySwitch k);
std::string_view to_string(Designation d);
std::string_view to_string(FibreState f);
std::string_view to_string(Led l);

/// The five indicators of one CHS 110 module (seed p. 19), all Off while the rack is unpowered.
struct ChsLeds {
  Led ready = Led::Off;    ///< On: powered and passed its diagnostics
  Led com_act = Led::Off;  ///< On: the CHS modules communicate; Blinking: startup error (Q6)
  Led primary = Led::Off;  ///< On: this unit is Primary
  Led com_err = Led::Off;  ///< On: CHS communication failure detected
  Led standby = Led::Off;  ///< On: Standby ready to take over; Blinking: program update
  bool operator==(const ChsLeds&) const = default;
};

/// The user logic: what the primary's CPU solves each scan on its state RAM.
using UserLogic = std::function<void(StateRam& ram, bus::Ticks now)>;

struct RackParams {
  Designation designation = Designation::A;  ///< the slide switch (read at power-on)
  KeySwitch key = KeySwitch::Run;            ///< the keyswitch's initial position
  std::uint32_t logic_checksum = 0;          ///< program identity: equal = logic match
  std::uint32_t firmware = 1;                ///< the CPU's executive version
};

struct HsbyPairParams {
  StateRamSizes sizes;  ///< both racks alike
  TransferPlan plan;    ///< ready, e.g. from transfer_area.hpp's plan_transfer
  /// The command register as a 0-based 4x index (400001 = 0). Must be < sizes.holding.
  std::uint32_t command_register = 0;
  /// Configuration bits of the command register that the pair takes as plain flags (the lead
  /// wires command_register.hpp's decoding in): keyswitch override, and the standby staying
  /// online on a logic mismatch.
  bool keyswitch_override = false;
  bool standby_stays_on_logic_mismatch = false;
  /// "Advanced Options" (seed p. 96): a standby may go online with an executive (firmware)
  /// version other than the primary's; by default it may not.
  bool allow_different_firmware = false;
  bus::Ticks scan_time = 100 * bus::kTicksPerMs;  ///< the primary's scan, start to start
  /// Fibre transfer duration (CHS -> CHS while the primary solves logic); 0 = scan_time / 4.
  /// Must be <= scan_time.
  bus::Ticks transfer_time = 0;
  /// Program update (Xfer + update button) duration, from the button's release. 0 = 1 s.
  bus::Ticks update_time = 0;
  /// A passive head only knows the line has been silent for its own silence bound. When the
  /// transfer due at the primary's scan start is missing and the head still hears the active
  /// master, the standby asks again `line_check_delay` later (set it to the head's bound):
  /// heard again (IoHead::heard_since: a frame that STARTED after the first question, so a frame
  /// already on the wire at the failure does not count) = the primary lives, the fibre failed
  /// (the standby goes Offline); silent = the
  /// primary failed less than 2 × line_check_delay before the takeover. A head that is silent
  /// at the due instant means a takeover at once. So every takeover is within
  /// max(scan_time, 2 × line_check_delay) of the failure: within one scan (Q7) while
  /// 2 × line_check_delay <= scan_time, which the constructor demands. 0 = no second question
  /// (heard at the due instant = fibre fault).
  bus::Ticks line_check_delay = 0;
  std::array<RackParams, 2> racks{RackParams{Designation::A}, RackParams{Designation::B}};
};

enum class SwitchoverCause : std::uint8_t {
  PrimaryPowerOff,  ///< unplanned: the primary rack lost power
  PrimaryCpuStop,   ///< unplanned: the primary's CPU stopped
  LinkSilent,       ///< unplanned: no transfer and the line silent, the primary's fate unknown
  KeyOffLine,       ///< planned: the primary's key to Off Line
  CommandRegister,  ///< planned: override, the primary's run bit 0 (both 0 included)
};
std::string_view to_string(SwitchoverCause c);

struct SwitchoverRecord {
  bus::Ticks cause_time = 0;  ///< the failure or the request
  bus::Ticks time = 0;        ///< the new primary's first scan start
  SwitchoverCause cause = SwitchoverCause::PrimaryPowerOff;
  int old_rack = -1;
  int new_rack = -1;
  bus::Ticks takeover_ticks = 0;  ///< time - cause_time
  double takeover_scans = 0;      ///< takeover_ticks / scan_time (<= 1: within one scan)
};

enum class PairEventKind : std::uint8_t {
  Power,
  Key,
  State,
  Switchover,
  TransferLost,
  LogicMismatch,
  DuplicateDesignation,
  Fibre,
  Update,
  Override,
  Cpu,
  Ignored,
};
std::string_view to_string(PairEventKind k);

struct PairEvent {
  bus::Ticks time = 0;
  int rack = -1;  ///< -1: the pair / the fibre
  PairEventKind kind = PairEventKind::State;
  std::string text;
  CpuState state = CpuState::Off;  ///< `rack`'s state after the event (a State event: the new one)
};

/// The program update of one unit (seed pp. 21-22): button held, key to Xfer (Armed: Com Act
/// off), key to the mode wanted after (Requested: Standby flashing), button released (Running:
/// Standby flashing for update_time), then the unit goes to its key's mode.
enum class UpdatePhase : std::uint8_t { None, Armed, Requested, Running };

class HsbyPair final : public bus::EventTarget {
 public:
  /// Heads may be null (no I/O: a silent standby then decides from the model's own truth, see
  /// the doc). Throws std::invalid_argument for a command register outside 4x, a transfer_time
  /// > scan_time, a line_check_delay < 0 or above scan_time / 2, or scan_time <= 0. Both racks start
  /// unpowered. The pair must outlive the scheduler's runs (its events point at it).
  HsbyPair(bus::Scheduler& sched, HsbyPairParams params, std::array<IoHead*, 2> heads);
  HsbyPair(const HsbyPair&) = delete;
  HsbyPair& operator=(const HsbyPair&) = delete;

  // ---- the program (per rack: a logic mismatch runs a different program) ----
  void set_logic(UserLogic logic);            ///< both racks
  void set_logic(int rack, UserLogic logic);  ///< one rack
  /// Loads a different program on one rack (program identity `checksum`), e.g. to make a
  /// mismatch; the pair reconciles (a mismatching standby goes Offline by default).
  void load_program(int rack, std::uint32_t checksum, UserLogic logic);
  /// Executive (firmware) upgrade of one rack's CPU (seed pp. 30, 86, 96). The command
  /// register's exec-upgrade bit (read from the primary's state RAM, command_register.hpp):
  /// 0 "only after application stops" — refused while any unit is Primary; 1 "without
  /// stopping application" — allowed on a unit that is not Primary (a Standby goes Offline for
  /// the download and rejoins at once: the download's duration is not modelled). The primary is
  /// never upgraded in place (hand control over first). Afterwards the unit rejoins only if its
  /// executive equals the primary's or allow_different_firmware is set. Returns "" when done,
  /// else the refusal (also logged).
  std::string upgrade_executive(int rack, std::uint32_t version);

  // ---- operations (at scheduler.now(), then reconciliation) ----
  void power_on(int rack);
  void power_off(int rack);
  void stop_cpu(int rack);   ///< the CPU fails / stops: Offline, no logic
  void start_cpu(int rack);  ///< the CPU runs again: joins like a unit turned to Run
  void set_key(int rack, KeySwitch key);
  void press_update(int rack);
  void release_update(int rack);
  /// The slide switch; read at the next power-on only.
  void set_designation(int rack, Designation d);
  void set_fibre(FibreState f);
  /// Enabling at run time reads the run bits at once (seed p. 90).
  void set_keyswitch_override(bool on);
  void set_standby_stays_on_logic_mismatch(bool on);

  // ---- observers ----
  CpuState state(int rack) const;
  /// The (first) Primary rack, -1 if none.
  int primary() const;
  /// The Standby rack, -1 if none.
  int standby() const;
  bool powered(int rack) const;
  bool cpu_running(int rack) const;
  KeySwitch key(int rack) const;
  /// The designation read at the last power-on (the slide switch's position if never powered).
  Designation designation(int rack) const;
  std::uint32_t logic_checksum(int rack) const;
  std::uint32_t firmware(int rack) const;
  bool logic_match() const;
  FibreState fibre() const { return m_fibre; }
  UpdatePhase update_phase(int rack) const;
  ChsLeds leds(int rack) const;
  HeadRole head_role(int rack) const;
  StateRam& ram(int rack);
  const StateRam& ram(int rack) const;
  const HsbyPairParams& params() const { return m_p; }
  bus::Ticks transfer_time() const { return m_transfer_time; }

  /// Scans run by each rack as primary.
  std::uint64_t scans(int rack) const;
  std::uint64_t transfers_completed() const { return m_transfers_done; }
  std::uint64_t transfers_lost() const { return m_transfers_lost; }
  /// Start time of the scan whose snapshot the last completed transfer carried (kNever: none).
  bus::Ticks last_transfer_scan_start() const { return m_last_done_scan_start; }
  const std::vector<SwitchoverRecord>& switchovers() const { return m_switchovers; }
  const std::vector<PairEvent>& events() const { return m_events; }
  /// Called with every event as it is logged (e.g. for a capture), at its virtual time.
  void set_event_handler(std::function<void(const PairEvent&)> h) { m_on_event = std::move(h); }

  // Status register word this unit writes (private encoding with the seed's 01/10/11 codes,
  // to be replaced by command_register.hpp's encode_status when merged); see the doc.
  std::uint16_t status_word(int rack) const;

  void on_event(bus::Ticks now, std::uint64_t tag) override;

 private:
  struct Rack {
    bool powered = false;
    bool cpu_run = true;
    CpuState state = CpuState::Off;
    KeySwitch key = KeySwitch::Run;
    Designation slide = Designation::A;
    Designation designation = Designation::A;
    std::uint32_t checksum = 0;
    std::uint32_t firmware = 1;
    UserLogic logic;
    StateRam ram;
    IoHead* head = nullptr;
    HeadRole head_role = HeadRole::Off;
    bool head_told = false;
    bool duplicate = false;  ///< Q6 startup error since this power-on (Com Act blinking)
    bool update_button = false;
    UpdatePhase update = UpdatePhase::None;
    std::uint64_t update_gen = 0;
    std::uint64_t scans = 0;
    std::uint64_t scan_gen = 0;
    bus::Ticks next_scan = bus::kNever;  ///< the primary's next scan start
    bus::Ticks last_scan = bus::kNever;
    bus::Ticks primary_since = 0;                  ///< when it last became Primary
    std::uint64_t scans_as_primary = 0;            ///< since it last became Primary
    std::uint64_t watch_gen = 0;                   ///< the standby's transfer watchdog
    bus::Ticks last_transfer_start = bus::kNever;  ///< as seen by this standby
    bool rechecking = false;
    bool updated = false;  ///< a transfer completed into it since it last became Standby  ///< the watchdog asks the head again after line_check_delay
    bus::Ticks first_check = 0;  ///< when it asked first (the second question: heard since?)
    std::string blocker;  ///< why it last could not join (logged on change)
  };
  struct TransferValue {
    RefType type = RefType::Coil0x;
    std::uint32_t index = 0;
    std::uint16_t value = 0;
  };
  struct InFlight {
    bool active = false;
    std::uint64_t gen = 0;
    int from = -1, to = -1;
    bus::Ticks scan_start = 0;
    std::vector<TransferValue> values;  ///< the snapshot, in the plan's order
  };
  struct PendingFailure {
    bool active = false;
    int rack = -1;
    bus::Ticks time = 0;
    SwitchoverCause cause = SwitchoverCause::PrimaryPowerOff;
  };
  struct PendingHandover {
    bool active = false;
    bus::Ticks time = 0;
    SwitchoverCause cause = SwitchoverCause::KeyOffLine;
  };

  static bool valid(int r) { return r == 0 || r == 1; }
  Rack& rk(int r) { return m_r[static_cast<std::size_t>(r)]; }
  const Rack& rk(int r) const { return m_r[static_cast<std::size_t>(r)]; }

  void log(int rack, PairEventKind kind, std::string text);
  void log_as(int rack, PairEventKind kind, std::string text, CpuState after);
  void set_state(int rack, CpuState s, std::string_view why);
  bool run_bit(int rack) const;  // the override's run bit for rack's designation
  bool wants_run(int rack) const;
  bool wants_offline(int rack) const;
  std::string join_blocker(int rack) const;  // "" = may be Standby beside the other's Primary
  void join_on_own_event(int rack);          // power-on, key to Run, CPU start, update done
  void become_primary(int rack, bus::Ticks now, const SwitchoverRecord* rec);
  void lose_in_flight(std::string_view why);
  void primary_gone(int rack, SwitchoverCause cause);
  void abort_update(int rack, std::string_view why);
  void reconcile();
  void update_heads();
  void write_status(int rack);
  void arm_scan(int rack, bus::Ticks at);
  void arm_watch(int standby_rack);
  void arm_update(int rack);
  void scan(int rack, bus::Ticks now);
  void transfer_done(std::uint64_t gen, bus::Ticks now);
  void watch(int rack, bus::Ticks now);
  void handover(int old_rack, bus::Ticks now);
  void update_done(int rack, bus::Ticks now);

  bus::Scheduler& m_sched;
  std::function<void(const PairEvent&)> m_on_event;
  HsbyPairParams m_p;
  bus::Ticks m_transfer_time = 0;
  bus::Ticks m_update_time = 0;
  std::array<Rack, 2> m_r;
  FibreState m_fibre = FibreState::Ok;
  InFlight m_flight;
  std::uint64_t m_flight_gen = 0;
  bus::Ticks m_link_fault_time = 0;
  bool m_alone_logged = false;  ///< "no standby to hand over to" logged since the last standby
  PendingFailure m_failure;
  PendingHandover m_handover;
  std::uint64_t m_transfers_done = 0;
  std::uint64_t m_transfers_lost = 0;
  bus::Ticks m_last_done_scan_start = bus::kNever;
  std::vector<SwitchoverRecord> m_switchovers;
  std::vector<PairEvent> m_events;
};

}  // namespace pbvbus::quantum
