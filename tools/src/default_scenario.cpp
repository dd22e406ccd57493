// The scenario `pbvbus run` runs without a file. It must run unattended and end by itself: no
// serial attachment, a fixed duration. (To be replaced by an H-system scenario once the
// redundancy layer exists.)
//
// GSD paths: the built-in scenario has no file to be relative to, so "@EXAMPLES@" stands for
// the source tree's examples/ folder, compiled in as PBVBUS_EXAMPLES_DIR. A binary moved away
// from its source tree then reports the missing GSD file like any scenario would.
#include <string>

#include "pbvbus/tools/scenario.hpp"

#ifndef PBVBUS_EXAMPLES_DIR
#define PBVBUS_EXAMPLES_DIR "examples"
#endif

namespace pbvbus::tools {

namespace {
constexpr char kDefault[] = R"pb(# Built-in default scenario of `pbvbus run`.
name: "default"
description: "A DP master system at 1.5 Mbit/s: DP master 1 with a compact, a modular and a DP-V1 slave, a second (FDL) master in the token ring polling a passive station; slave 4 loses power from 1.0 s to 1.5 s."
seed: 1
duration: "2s"

line { name: "PROFIBUS_DP_1" baud: "1.5M" }

dp_master {
  address: 1
  line: "PROFIBUS_DP_1"
  mode: OPERATE
  data_control_time: "120ms"
  watchdog: "100ms"
}
dp_slave { address: 3 line: "PROFIBUS_DP_1" gsd: "@EXAMPLES@/gsd/PBVB0A01.gsd" master: 1 }
dp_slave {
  address: 4
  line: "PROFIBUS_DP_1"
  gsd: "@EXAMPLES@/gsd/PBVB0A02.gsd"
  modules: ["8DI DC24V", "8DO DC24V/0.5A", "2AO U/I 16 bit"]
  master: 1
  tsdr_bits: 30
  inputs: ECHO
}
dp_slave {
  address: 5
  line: "PROFIBUS_DP_1"
  gsd: "@EXAMPLES@/gsd/PBVB0A03.gsd"
  modules: ["8DI with process alarm", "8DO DC24V/0.5A", "2AI U/I consistent"]
  master: 1
}
master {
  address: 2
  line: "PROFIBUS_DP_1"
  poll { address: [20] length: 8 priority: LOW }
}
passive_station { address: 20 line: "PROFIBUS_DP_1" response_length: 8 }

fault { at: "1s" repair_at: "1.5s" power_loss { line: "PROFIBUS_DP_1" address: 4 } }
)pb";
}  // namespace

std::string_view default_scenario_text() {
  static const std::string text = [] {
    std::string t = kDefault;
    const std::string key = "@EXAMPLES@";
    for (std::size_t p; (p = t.find(key)) != std::string::npos;) t.replace(p, key.size(), PBVBUS_EXAMPLES_DIR);
    return t;
  }();
  return text;
}

}  // namespace pbvbus::tools
