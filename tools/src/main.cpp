// pbvbus command line: dispatches to the subcommands in commands.hpp.
#include <cstring>
#include <iostream>
#include <string_view>

#include "pbvbus/tools/commands.hpp"

namespace {

struct Command {
  const char* name;
  int (*fn)(const pbvbus::tools::Args&, std::ostream&, std::ostream&);
  const char* summary;
};

// Subcommands register here as they are written.
const Command kCommands[] = {
    {"run", pbvbus::tools::cmd_run, "run a scenario (built-in default without a file)"},
    {"gsd", pbvbus::tools::cmd_gsd, "read a GSD file and print what it describes"},
    {"inspect", pbvbus::tools::cmd_inspect, "summarise a pcapng capture (frames, errors, gaps, events)"},
    {"timeline", pbvbus::tools::cmd_timeline, "draw a capture as an interactive HTML page or an SVG"},
    {"timing", pbvbus::tools::cmd_timing, "plan DP rotation and switchover times of a scenario"},
    {"gateway", pbvbus::tools::cmd_gateway, "print a scenario's gateway maps (Modbus registers, CAN PDOs)"},
    {"conformance", pbvbus::tools::cmd_conformance, "test a DP slave (model or program behind a pty) against the standard"},
};

void usage(std::ostream& os) {
  os << "usage: pbvbus <command> [args]\n\ncommands:\n";
  for (const auto& c : kCommands) os << "  " << c.name << std::string(12 - std::strlen(c.name), ' ') << c.summary << "\n";
  os << "\n'pbvbus <command> --help' describes a command.\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string_view(argv[1]) == "--help" || std::string_view(argv[1]) == "-h" ||
      std::string_view(argv[1]) == "help") {
    usage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? 2 : 0;
  }
  pbvbus::tools::Args args(argv + 2, argv + argc);
  for (const auto& c : kCommands)
    if (c.name == std::string_view(argv[1])) return c.fn(args, std::cout, std::cerr);
  std::cerr << "pbvbus: unknown command '" << argv[1] << "'\n";
  usage(std::cerr);
  return 2;
}
