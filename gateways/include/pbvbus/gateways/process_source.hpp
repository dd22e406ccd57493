#pragma once
// What a gateway sees of one DP master system (docs/gateway-modbus.md; design.md "Doors to the outside"): the
// configured slaves with their module layout, each slave's state and process data, the master's
// mode and counters, and — for a redundant system — the standby side and the H-system state.
//
// A ProcessSource is the one seam between the gateways and the running installation. The
// adapters over dp::Master, RedundantMasterSystemModel and HSystemModel live in this layer
// (dp_master_source.hpp, redundant_source.hpp); tests use tests/gateways/fake_source.hpp.
//
// Threading: every call happens on the bus thread (the paced runner's thread, where the doors'
// handlers run too), between scheduler events. That is what makes the consistency rules hold
// without locks: a read copies one Data_Exchange response's image (no DP cycle can complete
// while a handler runs), and all module writes of one request are in place before the next
// Data_Exchange snapshot, so they land in one DP cycle.
//
// Sides (Quantum-style primary/standby addressing, seeds-digest Q3): Side::Primary is the view
// through the active channel (a plain master system has only this side); Side::Standby the view
// through the other line's master of a redundant system. Which line is which is decided at the
// moment of the call, so the swap at a changeover is atomic for every request.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pbvbus/dp/master.hpp"

namespace pbvbus::gateways {

/// One module of a slave, in slot order (dp::ModuleLayout plus its GSD name).
struct SourceModule {
  std::string name;             ///< GSD module name ("8DI DC24V"); "module N" if unnamed
  std::size_t in_offset = 0;    ///< first octet in the slave's input telegram
  std::size_t in_len = 0;
  std::size_t out_offset = 0;   ///< first octet in the slave's output telegram
  std::size_t out_len = 0;
  bool consistent = false;      ///< consistent over its whole length (Cfg identifier bit 7)
};

/// One configured slave of the master system (fixed for the lifetime of the source).
struct SourceSlave {
  std::uint8_t address = 0;     ///< PROFIBUS address 0..125
  std::string name;             ///< GSD Model_Name
  std::uint16_t ident = 0;      ///< Ident_Number
  std::vector<SourceModule> modules;
  std::size_t input_len = 0;    ///< octets of the whole input telegram
  std::size_t output_len = 0;
  bool switched = false;        ///< a switched station (two channels, PI 2.212)
  /// False where something else owns the outputs (an H-system CPU program): writes refused.
  bool outputs_writable = true;
};

enum class Side : std::uint8_t { Primary, Standby };

/// A slave's state as one side's master sees it now.
struct SlaveStatus {
  dp::SlaveStatusState state = dp::SlaveStatusState::Inactive;
  bool data_valid = false;            ///< in data exchange: the inputs are current
  std::vector<std::uint8_t> diag;     ///< the raw Slave_Diag the master stored last (empty: none)
  std::uint64_t data_exchanges = 0;   ///< successful Data_Exchange cycles (the life counter)
  std::uint64_t failures = 0;         ///< station failures seen
  std::uint64_t returns = 0;          ///< station returns seen
  int active_channel = -1;            ///< switched: 0 = line A, 1 = line B, -1 = none / not switched
  bool redundancy_lost = false;       ///< switched: only one channel is up
  int side_line = 0;                  ///< the line whose master this view comes from (0 = A)
};

/// Counters of the whole master system (the primary side's master for a redundant one).
struct MasterCounters {
  std::uint64_t station_failures = 0;
  std::uint64_t station_returns = 0;
  std::uint64_t diagnoses = 0;        ///< Slave_Diag reads
  std::uint64_t alarms = 0;
  std::uint64_t switchovers = 0;      ///< redundant systems: channel switchovers
};

/// The H-system's state where the master system is driven by a simulated CPU pair.
struct HStatus {
  std::array<std::uint8_t, 2> cpu_state{};  ///< devices::CpuState per rack, as its number
  std::array<std::uint8_t, 2> cpu_role{};   ///< devices::CpuRole per rack
  std::uint8_t system_mode = 0;             ///< devices::SystemMode
  int master_rack = -1;                     ///< the rack whose CPU is master, -1 = none
};

class ProcessSource {
 public:
  virtual ~ProcessSource() = default;

  /// For reports and maps: e.g. "dp_master 1 on PROFIBUS_DP_1".
  virtual std::string name() const = 0;
  /// The configured slaves, ascending by address.
  virtual std::span<const SourceSlave> slaves() const = 0;
  /// True for a redundant system (a Standby side exists).
  virtual bool redundant() const = 0;

  /// The slave's state through `side`; nullopt for an unknown address (or Standby on a plain
  /// master system).
  virtual std::optional<SlaveStatus> status(std::uint8_t address, Side side) const = 0;
  /// The whole input telegram (out.size() == input_len), all from one Data_Exchange response.
  /// Keeps the last values when the slave has left data exchange. False: unknown address/side
  /// or wrong size; nothing copied.
  virtual bool read_inputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const = 0;
  /// The whole output telegram as last written (out.size() == output_len).
  virtual bool read_outputs(std::uint8_t address, Side side, std::span<std::uint8_t> out) const = 0;
  /// Replaces one module's outputs whole (data.size() == that module's out_len), on the
  /// primary side (a redundant system writes through its active channel, as the H master
  /// does). False: unknown, not writable, or wrong length; nothing changed.
  virtual bool write_module_outputs(std::uint8_t address, std::size_t module,
                                    std::span<const std::uint8_t> data) = 0;

  /// The master's operating state (the primary side's).
  virtual dp::MasterMode mode() const = 0;
  /// Stop/Clear/Operate (Offline is refused). False if refused (e.g. an H-system's masters
  /// follow their CPUs and take no commands).
  virtual bool command(dp::MasterMode m) = 0;
  virtual MasterCounters counters() const = 0;
  /// The master's address (primary side).
  virtual std::uint8_t master_address() const = 0;
  /// Present only for a master system driven by an H-system.
  virtual std::optional<HStatus> h_status() const { return std::nullopt; }
};

}  // namespace pbvbus::gateways
