#include "pbvbus/scenario/prm_record_plan.hpp"

#include <algorithm>

#include "pbvbus/dp/dpv1_pdu.hpp"

namespace pbvbus::tools {
namespace {
int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}
}  // namespace

std::optional<std::vector<std::uint8_t>> parse_hex_octets(std::string_view text, std::string* why) {
  std::vector<std::uint8_t> out;
  std::size_t i = 0;
  const auto fail = [&](std::string msg) -> std::optional<std::vector<std::uint8_t>> {
    if (why) *why = std::move(msg);
    return std::nullopt;
  };
  while (i < text.size()) {
    if (text[i] == ' ') {
      ++i;
      continue;
    }
    const int hi = hex_digit(text[i]);
    if (hi < 0) return fail("\"" + std::string(1, text[i]) + "\" at " + std::to_string(i + 1) + " is not a hex digit");
    if (i + 1 >= text.size() || hex_digit(text[i + 1]) < 0)
      return fail("octet at " + std::to_string(i + 1) + " needs two hex digits");
    out.push_back(static_cast<std::uint8_t>(hi * 16 + hex_digit(text[i + 1])));
    i += 2;
  }
  if (out.empty()) return fail("no octets");
  return out;
}

std::vector<DpPrmRecordPlan> plan_prm_records(const scenario::DpSlave& s,
                                              const std::vector<std::string>& modules, bool c1,
                                              std::vector<std::pair<int, std::string>>& errors) {
  std::vector<DpPrmRecordPlan> out;
  for (int k = 0; k < s.parameter_record_size(); ++k) {
    const scenario::ModulePrmRecord& r = s.parameter_record(k);
    if (!c1) {
      errors.emplace_back(k, "parameter_record: the station is not a DP-V1 slave with "
                             "C1_Read_Write_supp (it takes no data records)");
      return {};
    }
    DpPrmRecordPlan p;
    using MR = scenario::ModulePrmRecord;
    if (r.module_ref_case() == MR::MODULE_REF_NOT_SET) {
      errors.emplace_back(k, "parameter_record needs a module: module: \"name\" or module_index: n");
      continue;
    }
    if (r.module_ref_case() == MR::kModuleIndex) {
      if (r.module_index() >= modules.size()) {
        errors.emplace_back(k, "parameter_record: module_index " + std::to_string(r.module_index()) +
                                   " is not below the " + std::to_string(modules.size()) +
                                   " modules of the station");
        continue;
      }
      p.module = r.module_index();
    } else {
      const auto it = std::find(modules.begin(), modules.end(), r.module());
      if (it == modules.end()) {
        errors.emplace_back(k, "parameter_record: module \"" + r.module() +
                                   "\" is not one of the station's modules");
        continue;
      }
      p.module = static_cast<std::size_t>(it - modules.begin());
    }
    if (r.index() > 254) {
      errors.emplace_back(k, "parameter_record: index " + std::to_string(r.index()) +
                                 " is above 254 (255 is reserved)");
      continue;
    }
    p.index = static_cast<std::uint8_t>(r.index());
    std::string why;
    auto d = parse_hex_octets(r.data(), &why);
    if (!d) {
      errors.emplace_back(k, "parameter_record: data \"" + r.data() + "\": " + why);
      continue;
    }
    if (d->size() > dp::kMaxRecordData) {
      errors.emplace_back(k, "parameter_record: " + std::to_string(d->size()) +
                                 " octets, at most 240 (C1_Max_Data_Len)");
      continue;
    }
    p.data = std::move(*d);
    const bool twice = std::any_of(out.begin(), out.end(), [&](const DpPrmRecordPlan& q) {
      return q.module == p.module && q.index == p.index;
    });
    if (twice) {
      errors.emplace_back(k, "parameter_record: module " + std::to_string(p.module) + " record " +
                                 std::to_string(p.index) + " is given twice");
      continue;
    }
    out.push_back(std::move(p));
  }
  return out;
}

}  // namespace pbvbus::tools
