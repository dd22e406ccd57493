// The DP system function calls of a scenario program: SFC 11 DPSYC_FR, SFC 12 D_ACT_DP,
// SFC 14 DPRD_DAT, SFC 15 DPWR_DAT (docs/h-dp-sfc.md; h_dp_sfc.hpp has the RET_VALs). Only the
// form is checked here: a time, values that fit their octet. What the CPU's run answers (a
// wrong length, an unknown LADDR, a MODE SFC 11/12 refuses) is a RET_VAL, not a load error;
// which lines an s7_cpu may name is s7_plan.cpp's, and an h_system refuses SFC 11/12
// (h_config_rules.cpp).
#include <optional>
#include <string>

#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

namespace {

template <typename Call>
std::optional<bus::Ticks> at_of(const Call& n, const char* list, int k, const ProgramError& error_at) {
  if (n.at().empty()) return bus::Ticks{0};
  const auto t = bus::parse_duration(n.at());
  if (!t || *t < 0) {
    error_at({{list, k}, {"at"}}, "bad duration \"" + n.at() + "\" for at (e.g. \"3s\")");
    return std::nullopt;
  }
  return t;
}

bool octet(std::uint32_t v, const char* list, int k, const char* field, const std::string& what,
           const ProgramError& error_at) {
  if (v <= 0xFF) return true;
  error_at({{list, k}, {field}}, what + " " + std::to_string(v) + " does not fit an octet");
  return false;
}

}  // namespace

void plan_dp_sfc_calls(const scenario::HProgram& pr, devices::ProgramSpec& spec,
                       const ProgramError& error_at) {
  for (int k = 0; k < pr.dpsyc_fr_size(); ++k) {
    const auto& n = pr.dpsyc_fr(k);
    const auto at = at_of(n, "dpsyc_fr", k, error_at);
    // Both checked, so that both errors are reported at once.
    const bool group_ok = octet(n.group(), "dpsyc_fr", k, "group", "SFC 11: GROUP", error_at);
    const bool mode_ok = octet(n.mode(), "dpsyc_fr", k, "mode", "SFC 11: MODE", error_at);
    const bool good = group_ok && mode_ok;
    if (!at || !good) continue;
    devices::DpSyncFreezeCall c;
    c.at = *at;
    c.line = n.line();
    c.group = static_cast<std::uint8_t>(n.group());
    c.mode = static_cast<std::uint8_t>(n.mode());
    if (n.has_ret_val()) c.ret_val = n.ret_val();
    spec.dpsyc_fr.push_back(std::move(c));
  }
  for (int k = 0; k < pr.d_act_dp_size(); ++k) {
    const auto& n = pr.d_act_dp(k);
    const auto at = at_of(n, "d_act_dp", k, error_at);
    bool good = octet(n.mode(), "d_act_dp", k, "mode", "SFC 12: MODE", error_at);
    if (n.station() > 126) {
      error_at({{"d_act_dp", k}, {"station"}},
               "SFC 12: station " + std::to_string(n.station()) + " is no PROFIBUS slave address (0..125)");
      good = false;
    }
    if (!at || !good) continue;
    devices::DpActivateCall c;
    c.at = *at;
    c.line = n.line();
    c.station = static_cast<std::uint8_t>(n.station());
    c.mode = static_cast<std::uint8_t>(n.mode());
    if (n.has_ret_val()) c.ret_val = n.ret_val();
    spec.d_act_dp.push_back(std::move(c));
  }
  for (int k = 0; k < pr.dprd_dat_size(); ++k) {
    const auto& n = pr.dprd_dat(k);
    const auto at = at_of(n, "dprd_dat", k, error_at);
    if (!at) continue;
    devices::DpReadCall c;
    c.at = *at;
    c.laddr = n.laddr();
    c.record = n.record();
    c.length = n.length();
    if (n.has_ret_val()) c.ret_val = n.ret_val();
    spec.dprd_dat.push_back(c);
  }
  for (int k = 0; k < pr.dpwr_dat_size(); ++k) {
    const auto& n = pr.dpwr_dat(k);
    const auto at = at_of(n, "dpwr_dat", k, error_at);
    if (!at) continue;
    devices::DpWriteCall c;
    c.at = *at;
    c.laddr = n.laddr();
    c.record = n.record();
    c.length = n.length();
    if (n.has_ret_val()) c.ret_val = n.ret_val();
    spec.dpwr_dat.push_back(c);
  }
}

}  // namespace pbvbus::tools
