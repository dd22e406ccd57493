// Slave configuration checks and layout (protocol-facts.md §D.3).
#include "pbvbus/dp/slave_config.hpp"

#include "pbvbus/dp/diagnosis.hpp"
#include "pbvbus/dp/prm.hpp"

namespace pbvbus::dp {

std::string build_layout(const SlaveConfig& cfg, SlaveLayout& out) {
  out = SlaveLayout{};
  if (cfg.max_diag_len < kStdDiagLen || cfg.max_diag_len > kMaxDiagLen)
    return "max_diag_len must be 6..244";
  if (cfg.min_user_prm_len > cfg.max_user_prm_len || cfg.max_user_prm_len > kMaxUserPrmLen)
    return "user prm length limits must satisfy min <= max <= 237";
  if (cfg.features.dpv1 && cfg.min_user_prm_len < 3)
    return "a DP-V1 slave needs at least 3 user prm octets (DPV1_Status_1..3)";
  if (cfg.features.max_alarm_mode > 7) return "max_alarm_mode must be 0..7";
  if (cfg.features.c2 && (cfg.features.c2_connections == 0 || cfg.features.c2_connections > 49))
    return "c2_connections must be 1..49";
  if (cfg.modules.size() > 62 * 8) return "too many modules";
  std::vector<CfgIdentifier> ids;
  for (std::size_t m = 0; m < cfg.modules.size(); ++m) {
    const auto& mod = cfg.modules[m];
    if (mod.cfg.empty()) return "module " + std::to_string(m) + " has no identifier";
    const CfgError e = parse_cfg(mod.cfg, ids, false);
    if (e != CfgError::None) return "module " + std::to_string(m) + ": " + std::string(to_string(e));
    ModuleLayout ml;
    ml.in_offset = out.inputs;
    ml.out_offset = out.outputs;
    ml.first_id = out.identifiers.size();
    ml.id_count = ids.size();
    for (auto id : ids) {
      ml.in_len += id.input.bytes();
      ml.out_len += id.output.bytes();
      ml.consistent = ml.consistent || id.input.consistent || id.output.consistent;
      id.offset += out.cfg.size();
      out.identifiers.push_back(id);
      out.module_of_id.push_back(m);
    }
    out.inputs += ml.in_len;
    out.outputs += ml.out_len;
    out.cfg.insert(out.cfg.end(), mod.cfg.begin(), mod.cfg.end());
    out.modules.push_back(ml);
  }
  if (out.inputs > kMaxIoLen || out.outputs > kMaxIoLen)
    return "more than 244 octets of inputs or outputs";
  if (out.cfg.size() > 244) return "configuration longer than 244 octets";
  return {};
}

}  // namespace pbvbus::dp
