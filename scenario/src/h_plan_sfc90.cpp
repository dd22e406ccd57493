// The `h_ctrl` calls of a scenario program: SFC 90 H_CTRL at a virtual time (docs/h-sfc90.md;
// h_sfc90.hpp has the MODE/SUBMODE table).
#include <string>

#include "pbvbus/scenario/h_plan.hpp"
#include "pbvbus/s7h/h_sfc90.hpp"
#include "pbvbus/scenario/scenario.hpp"

namespace pbvbus::tools {

void plan_h_ctrl_calls(const scenario::HProgram& pr, devices::ProgramSpec& spec,
                       const ProgramError& error_at) {
  for (int k = 0; k < pr.h_ctrl_size(); ++k) {
    const auto& n = pr.h_ctrl(k);
    devices::HCtrlCall c;
    bool good = true;
    if (!n.at().empty()) {
      const auto t = bus::parse_duration(n.at());
      if (!t || *t < 0) {
        error_at({{"h_ctrl", k}, {"at"}}, "bad duration \"" + n.at() + "\" for at (e.g. \"3s\")");
        good = false;
      } else {
        c.at = *t;
      }
    }
    if (n.mode() > 255 || n.submode() > 255 ||
        devices::decode_h_ctrl(static_cast<std::uint8_t>(n.mode()),
                               static_cast<std::uint8_t>(n.submode())).ret_val != 0) {
      const bool bad_mode = n.mode() > 255 ||
                            devices::decode_h_ctrl(static_cast<std::uint8_t>(n.mode()), 0).ret_val ==
                                devices::kHCtrlBadMode;
      if (bad_mode)
        error_at({{"h_ctrl", k}, {"mode"}},
                 "SFC 90: MODE " + std::to_string(n.mode()) +
                     " is not 0, 1, 3, 4, 10, 11 or 12 (W#16#8090)");
      else
        error_at({{"h_ctrl", k}, {"submode"}},
                 "SFC 90: SUBMODE " + std::to_string(n.submode()) + " is not valid for MODE " +
                     std::to_string(n.mode()) + " (W#16#8091)");
      good = false;
    }
    c.mode = static_cast<std::uint8_t>(n.mode() & 0xFFU);
    c.submode = static_cast<std::uint8_t>(n.submode() & 0xFFU);
    if (good) spec.h_ctrl_calls.push_back(c);
  }
}

}  // namespace pbvbus::tools
