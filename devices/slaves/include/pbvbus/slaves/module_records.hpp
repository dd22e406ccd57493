#pragma once
// The parameter data records of a modular DP-V1 station's modules (digest §7 F3 "automatic
// re-parameterisation"; protocol-facts.md §E.2 Write/Read PDUs, §E.3 error codes).
//
// What an S7 master does after a module is plugged is to send it its parameter data record(s)
// with MSAC_C1 Write (`5F Slot Index Length Data`); the module takes them and a Read of the same
// record returns them. The GSDs of the pbvbus stations say "Module parameters are written as
// data records" and declare no per-module record list, so the rule is generic (decision,
// docs/h-reparameterisation.md):
// - A station whose GSD has DPV1_Slave = 1 and C1_Read_Write_supp = 1 installs one ModuleRecords
//   on its slave application(s) (a switched station: both interfaces share one, one backplane).
// - A Write to slot s = 1..n (module s - 1 of the configuration), index 0..254, 1..240 octets
//   (C1_Max_Data_Len; the engine refuses a Length that disagrees with the data, `DF 80 B1 00`)
//   is stored and answered positively `5F s index len`. A later Write of the same record
//   replaces it (any length).
// - A Read of a stored record returns its octets (at most the Length asked for); a Read of a
//   record never written stays "invalid index" `DE 80 B0 00`.
// - A Write to a slot with its module pulled, or beyond the last module: "invalid slot"
//   `DF 80 B2 00` (there is no module at that slot). Pulling a module forgets its records (the
//   module plugged in its place is a new one, without parameters: hence the master's write
//   after the plug); a Read of them then answers "invalid slot" while pulled, "invalid index"
//   after the plug until written again.
// - Slot 0 (the interface module itself) keeps no records: `DF 80 B0 00` as before.
// Thread: the handlers run on the bus thread; accessors may be called from any thread.

#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "pbvbus/dp/slave_application.hpp"

namespace pbvbus::devices {

class ModuleRecords {
 public:
  explicit ModuleRecords(std::size_t modules) : m_pulled(modules, false) {}
  ModuleRecords(const ModuleRecords&) = delete;
  ModuleRecords& operator=(const ModuleRecords&) = delete;

  /// Takes every Write without a handler of its own on `app` (dp::SlaveApplication::
  /// on_write_any). The application must not outlive this object's use by its engine.
  void install(dp::SlaveApplication& app);
  /// Module `module` pulled (true: its records are forgotten) or plugged again.
  void set_pulled(std::size_t module, bool pulled);
  /// The record `index` of module `module` (0-based), if written.
  std::optional<std::vector<std::uint8_t>> record(std::size_t module, std::uint8_t index) const;
  /// Writes accepted so far.
  std::uint64_t writes_accepted() const;

 private:
  dp::RecordResult write(const dp::RecordCall& c, std::span<const std::uint8_t> data);
  dp::RecordResult read(const dp::RecordCall& c, std::span<std::uint8_t> out) const;

  mutable std::mutex m_mu;
  std::vector<bool> m_pulled;  ///< per module
  std::map<std::uint16_t, std::vector<std::uint8_t>> m_records;  ///< (slot << 8 | index)
  std::vector<dp::SlaveApplication*> m_apps;
  std::uint64_t m_writes = 0;
};

}  // namespace pbvbus::devices
