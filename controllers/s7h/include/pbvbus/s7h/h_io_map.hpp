#pragma once
// The H-system's I/O map (docs/h-system.md "The H-system model"): where each DP slave module's
// inputs and outputs lie in the CPU's process images (PII, PIQ) as the user program sees them.
//
// Decision (the seeds give no address assignment; STEP 7 lets the user choose): addresses are
// consecutive bytes from 0, separately in the PII and the PIQ, in this order: master systems in
// the order given to HSystemModel, within one system the slaves by PROFIBUS address (a switched
// station once: both channels are one station with one I/O address, digest §2), within one
// slave the modules in slot order (configuration order). A module without inputs has in_len 0
// (and in_addr = the next free input byte), likewise for outputs. One I/O address per module
// whatever its channel, so a switchover never moves data in the images.
//
// Inputs come from the active channel's master image (MasterSystem::active_image); a slave
// without an active channel (failed, or no line runs) keeps its last PII bytes, as an S7
// process image keeps the last values of a failed station (the program learns of it from
// OB 86). Outputs go out through MasterSystem::write_outputs: both lines' images alike.
//
// Central I/O (F8 expansion racks, h_expansion_rack.hpp): HSystemModel appends the modules of
// its expansion racks after every DP entry (add_central: racks in the order given, modules in
// rack order), so the DP entries and their addresses never move. A central entry has
// central = true, rack = the expansion rack number, system = -1, address = 0, module = the
// module's index in its rack; read_inputs/write_outputs skip it (HSystemModel serves it).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pbvbus::devices {

class RedundantMasterSystemModel;

struct HIoEntry {
  int system = 0;             ///< index of the master system
  std::uint8_t address = 0;   ///< PROFIBUS address of the slave
  std::size_t module = 0;     ///< module index (slot order)
  std::size_t in_addr = 0;    ///< first PII byte
  std::size_t in_len = 0;
  std::size_t out_addr = 0;   ///< first PIQ byte
  std::size_t out_len = 0;
  bool central = false;  ///< a module of an expansion rack (F8), not DP
  int rack = 0;          ///< central: the expansion rack number (1..21)
  bool operator==(const HIoEntry&) const = default;
};

class HIoMap {
 public:
  HIoMap() = default;
  /// Builds the map from the systems' configurations (each slave's layout from a master that
  /// has it configured).
  explicit HIoMap(std::span<RedundantMasterSystemModel* const> systems);

  const std::vector<HIoEntry>& entries() const { return m_entries; }
  std::size_t pii_size() const { return m_pii; }
  std::size_t piq_size() const { return m_piq; }
  /// The entry of (system, address, module), or nullptr.
  const HIoEntry* find(int system, std::uint8_t address, std::size_t module) const;

  /// Appends a central module of expansion rack `rack` after the entries so far.
  const HIoEntry& add_central(int rack, std::size_t module, std::size_t in_len,
                              std::size_t out_len);
  /// The central entry of (rack, module), or nullptr.
  const HIoEntry* find_central(int rack, std::size_t module) const;

  /// PII from the active images; bytes of slaves without an active channel are left as they are.
  /// Nothing happens if pii is not pii_size() long.
  void read_inputs(std::span<RedundantMasterSystemModel* const> systems,
                   std::span<std::uint8_t> pii) const;
  /// Every output module's PIQ bytes written with MasterSystem::write_outputs.
  void write_outputs(std::span<RedundantMasterSystemModel* const> systems,
                     std::span<const std::uint8_t> piq) const;
  /// The same into line `line`'s master images only (MasterSystem::write_outputs(line, ...)):
  /// two masters (F6/F7), each CPU's PIQ to its own side.
  void write_outputs(std::span<RedundantMasterSystemModel* const> systems,
                     std::span<const std::uint8_t> piq, int line) const;

 private:
  std::vector<HIoEntry> m_entries;
  std::size_t m_pii = 0, m_piq = 0;
};

}  // namespace pbvbus::devices
