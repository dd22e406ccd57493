#pragma once
// F3: the modules' parameter data records of a dp_slave / switched_station (`parameter_record`,
// scenario.proto ModulePrmRecord; docs/h-reparameterisation.md). An H-system's master writes them
// (MSAC_C1 Write, HSystemModel::set_module_parameters) to a module after the module is plugged.
// Refused: a station that is not a DP-V1 slave with C1_Read_Write_supp (it could not take
// them), no module or an unknown one, an index above 254 (255 is reserved, protocol-facts.md
// §E.2), data that is not 1..240 octets of two hex digits each, the same (module, index) twice.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scenario.pb.h"

namespace pbvbus::tools {

struct DpPrmRecordPlan {
  std::size_t module = 0;  ///< 0-based in the station's module list
  std::uint8_t index = 0;
  std::vector<std::uint8_t> data;
  bool operator==(const DpPrmRecordPlan&) const = default;
};

/// "12 34", "1234", "12 3a": octets of two hex digits, blanks between octets allowed. Nullopt
/// (and *why) for an odd digit, a non-hex character, a blank inside an octet, no octets.
std::optional<std::vector<std::uint8_t>> parse_hex_octets(std::string_view text, std::string* why);

/// Plans `s.parameter_record`; `modules` = the station's module names, `c1` = the station is a
/// DP-V1 slave with C1_Read_Write_supp. Errors as (element, message).
std::vector<DpPrmRecordPlan> plan_prm_records(
    const scenario::DpSlave& s, const std::vector<std::string>& modules, bool c1,
    std::vector<std::pair<int, std::string>>& errors);

}  // namespace pbvbus::tools
