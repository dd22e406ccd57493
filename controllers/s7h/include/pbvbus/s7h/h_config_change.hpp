#pragma once
// Changes in operation on the S7-400H (docs/h-changes.md): the PG/ES "Switch to CPU with
// modified configuration / expanded memory configuration / modified operating system"
// (000 §5.2.2 L1104-1160, §5.2.3 L1239-1269, ch. 10 L3364-3416; 001 L4479-4530, §6.2.3
// L4673-4720), what the update copies, the I/O at the swap and at the return to Redundant, the
// new master's OB 1 start identifier, and CiR (001 L2745-2757: processing held <= 2.5 s).
// Sans-I/O, built on HCpuPair (request_master_swap() does the link-up, update and swap): the
// owner calls observe() after the pair's operations and deadlines.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_cpu_pair.hpp"

namespace pbvbus::devices {

/// The option of the STEP 7 "Switch to" dialog (000 L1106-1110).
enum class HSwitchVariant : std::uint8_t { ModifiedConfiguration, ExpandedMemory, ModifiedOs };

enum class LoadMemoryType : std::uint8_t { Ram, Flash };

/// What the "Switch to" checks of one CPU see.
struct HCpuConfig {
  std::uint32_t work_memory_kb = 0;
  std::uint32_t load_memory_kb = 0;
  LoadMemoryType load_memory = LoadMemoryType::Ram;
  std::uint32_t os_version = 0;  ///< e.g. 0x030100 = V3.1.0; larger = newer
};

struct HSwitchCheck {
  bool allowed = false;
  /// The user program blocks (OB, FC, FB, DB, SDB) are copied (expanded memory, modified OS).
  bool copy_user_program = false;
  /// ... from the load memory too (not with FLASH cards: only the work-memory blocks).
  bool copy_load_memory = false;
  std::string text;  ///< the refusal (a diagnostic-buffer entry on both CPUs), or the note
};

/// The checks of 000 L1112-1160 / 001 L4486-4530. `modified_os_usable` false: 001 L4486 (the
/// modified-OS option unusable) — digest §10 item 8; the default follows 000 (usable).
HSwitchCheck check_switch(HSwitchVariant v, const HCpuConfig& master, const HCpuConfig& standby,
                          bool modified_os_usable = true);

/// A data block as 5.2.3 sees it.
struct HDbBlock {
  int number = 0;
  std::uint32_t interface_stamp = 0;  ///< the interface time stamp in the load memory
  bool read_only = false;
  bool unlinked = false;
  bool created_by_sfc = false;     ///< generated at run time by SFC 22 (not in the load memory)
  bool comm_sfb_instances = false;  ///< holds instances of S7-communication SFBs
  std::uint32_t kb = 0;
};

/// What the update of a "switch to CPU with modified configuration" copies (000 §5.2.3).
struct HModifiedConfigCopy {
  bool aborted = false;  ///< the link-up is interrupted with a diagnostic-buffer entry
  std::string abort_text;
  std::vector<int> copied;     ///< contents copied (same interface stamp, not RO/unlinked)
  std::vector<int> created;    ///< SFC-generated DBs of the master, transferred
  std::vector<int> deleted;    ///< SFC-generated DBs of the standby, reset (deleted)
  std::vector<int> sfb_reset;  ///< modified DBs with S7-comm SFB instances: instances reset
  std::size_t diag_entries = 0;  ///< master entries transferred (the newest ones)
};

/// 5.2.3: load memory never copied; DB contents, SFC DBs, process images, timers, counters,
/// memory markers and the diagnostic buffer are. `standby_free_kb`: the standby's free work
/// memory for the master's SFC DBs (too little: aborted).
HModifiedConfigCopy plan_modified_configuration_copy(const std::vector<HDbBlock>& master,
                                                     const std::vector<HDbBlock>& standby,
                                                     std::uint32_t standby_free_kb,
                                                     std::size_t master_diag_entries,
                                                     std::size_t standby_diag_capacity);

/// Whose I/O (000 ch. 10 tables "Behavior of the I/O").
enum class HIoOwner : std::uint8_t { OldMaster, NewMaster, Switched };
enum class HIoPresence : std::uint8_t { Added, Kept, AddedStation };
/// What an output module does.
enum class HOutput : std::uint8_t {
  NotAddressed,           ///< not addressed by the CPU (was not configured for it)
  SubstituteValues,       ///< no longer addressed: the configured substitute/holding values
  SubstituteThenUpdated,  ///< parameterised: briefly the substitute values, then updated
  ZeroThenUpdated,        ///< central: reset and re-parameterised: briefly 0, then updated
  Updated,                ///< (re-)parameterised and updated, no visible interruption
  Uninterrupted,          ///< switched I/O: continues without interruption
};
std::string_view to_string(HOutput o);

/// At the swap (000 L3382-3388, "Step 6").
HOutput output_at_switch(HIoOwner owner, HIoPresence presence, bool central);
/// At the return to Redundant: `owner` NewMaster = the master, OldMaster = the standby that
/// links up with the new configuration (000 L3410-3416, "Step 7").
HOutput output_at_redundant(HIoOwner owner, HIoPresence presence, bool central);

struct HConfigChangeParams {
  bool modified_os_usable = true;  ///< digest §10 item 8 (see check_switch)
  /// How long the new master's central outputs stay 0 after the swap ("briefly", 000 L3388):
  /// decision: one OB 1 cycle, the first OB 1 writes the re-parameterised modules' PIQ at its
  /// end. The owner sets its OB 1 cycle.
  bus::Ticks first_cycle_time = 10 * bus::kTicksPerMs;
  /// CiR synchronisation time: processing held at most 2.5 s, configurable (001 L2747-2750).
  bus::Ticks cir_hold_time = 2500 * bus::kTicksPerMs;
};

/// OB1_SCAN_1 (System Software for S7-300/400, OB 1; 000 L1209 / 001 L4635: "OB 1 has its own
/// identifier" in the first cycle after a master/standby swap).
inline constexpr std::uint8_t kOb1ScanFreeCycle = 0x03;
inline constexpr std::uint8_t kOb1ScanAfterSwap = 0x05;
/// 001 L2747: "processing is stopped for at most 2.5 s".
inline constexpr bus::Ticks kCirMaxHold = 2500 * bus::kTicksPerMs;

struct HCirResult {
  bool accepted = false;
  bus::Ticks hold_from = 0, hold_until = 0;  ///< [from, until): no OB 1, outputs kept
  std::string text;
};

class HConfigChange {
 public:
  /// Throws std::invalid_argument for a CiR hold outside (0, 2.5 s].
  explicit HConfigChange(HCpuPair& pair, HConfigChangeParams p = {});

  /// PG/ES "Switch to CPU with ...": the checks of check_switch() at the request (as F23:
  /// refused -> an entry in both buffers, the standby stays in STOP, the master in RUN, false);
  /// else request_master_swap() (false if the pair refuses: not Solo, standby not in STOP).
  /// `added_switched` = switched modules (their addresses) the new configuration adds: OB 83
  /// on both CPUs when Redundant is reached again.
  bool request(HSwitchVariant v, const HCpuConfig& master, const HCpuConfig& standby,
               bus::Ticks now, std::vector<int> added_switched = {});
  /// Reads the pair's new events: the swap (OB 72 MasterSwap on the new master after request())
  /// and the next Redundant mode (OB 83 entries). Call after every pair step.
  void observe();

  std::optional<bus::Ticks> swap_time() const { return m_swap_at; }
  int new_master() const { return m_new_master; }
  /// OB1_SCAN_1 of an OB 1 starting at `start` on `rack`: B#16#05 for the new master's first
  /// OB 1 at or after the swap, else B#16#03. Stateful: the first such call consumes it.
  std::uint8_t ob1_scan_1(int rack, bus::Ticks start);
  /// The new master's central output modules output 0: [swap, swap + first_cycle_time).
  bool central_outputs_zero(int rack, bus::Ticks t) const;
  /// The old master's one-sided outputs are not addressed: substitute/holding values, from the
  /// swap until it runs again (Redundant).
  bool one_sided_substitute(int rack, bus::Ticks t) const;
  /// OB 83 (plug interrupt, to be ignored by the program) for each added switched module, on
  /// both CPUs, when the system is Redundant again (000 L3412); the time, -1 none yet.
  bus::Ticks ob83_time() const { return m_ob83_at; }
  const std::vector<int>& ob83_modules() const { return m_added; }

  /// CiR (001 L2745-2757): a configuration change of the distributed I/O in RUN (Solo or
  /// Redundant): processing is held [now, now + cir_hold_time), the outputs keep their values.
  /// Refused: central I/O, no master in RUN, during link-up/update.
  HCirResult cir_change(bus::Ticks now, bool central_io = false);

 private:
  HCpuPair& m_pair;
  HConfigChangeParams m_p;
  std::size_t m_seen = 0;
  bool m_pending = false;
  bool m_first_ob1 = false;
  std::optional<bus::Ticks> m_swap_at;
  std::optional<bus::Ticks> m_redundant_at;
  int m_new_master = -1;
  bus::Ticks m_ob83_at = -1;
  std::vector<int> m_added;
};

}  // namespace pbvbus::devices
