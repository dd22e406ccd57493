#pragma once
// Subcommands of the `pbvbus` command line. Each takes its arguments (without the subcommand
// name) and the streams to write to, and returns the process exit code: 0 success, 1 the
// operation failed (e.g. a conformance failure), 2 bad usage or bad input.

#include <iosfwd>
#include <string>
#include <vector>

namespace pbvbus::tools {

using Args = std::vector<std::string>;

int cmd_run(const Args& args, std::ostream& out, std::ostream& err);
int cmd_gsd(const Args& args, std::ostream& out, std::ostream& err);
int cmd_inspect(const Args& args, std::ostream& out, std::ostream& err);
int cmd_timeline(const Args& args, std::ostream& out, std::ostream& err);
int cmd_timing(const Args& args, std::ostream& out, std::ostream& err);
int cmd_gateway(const Args& args, std::ostream& out, std::ostream& err);
int cmd_conformance(const Args& args, std::ostream& out, std::ostream& err);

}  // namespace pbvbus::tools
