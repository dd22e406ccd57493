// The scenario `pbvbus run` runs without a file. It must run unattended and end by itself: no
// serial attachment, a fixed duration. (To be replaced by an H-system scenario once the
// redundancy layer exists.)
#include "pbvbus/tools/scenario.hpp"

namespace pbvbus::tools {

namespace {
constexpr char kDefault[] = R"pb(# Built-in default scenario of `pbvbus run`.
name: "default"
description: "Two FDL masters and four passive stations on one 1.5 Mbit/s line; station 12 loses power for 500 ms."
seed: 1
duration: "2s"

line { name: "A" baud: "1.5M" }

master {
  address: 1
  line: "A"
  poll { address: [10, 11] length: 8 }
}
passive_station { address: 10 line: "A" response_length: 8 }
passive_station { address: 11 line: "A" response_length: 8 }
master {
  address: 2
  line: "A"
  poll { address: [12, 13] length: 16 priority: HIGH }
}
passive_station { address: 12 line: "A" response_length: 16 }
passive_station { address: 13 line: "A" response_length: 16 }

fault { at: "1s" repair_at: "1.5s" power_loss { line: "A" address: 12 } }
)pb";
}  // namespace

std::string_view default_scenario_text() { return kDefault; }

}  // namespace pbvbus::tools
