// `pbvbus inspect CAPTURE [--json]`: summary of a pcapng capture (design.md "Captures" and
// "Configuration and command line"): per interface the frames by FDL frame type, request
// function, response status and DP service, bad frames by reason, the time span and the shortest
// idle gap in bit times; then the events. The summary itself is captures/inspect.hpp; this file
// is only the command line around it.
//
// Decisions:
//  - An empty file is "not a pcapng file" (the reader would report zero records, which hides
//    the mistake of pointing the command at the wrong file).
//  - A read error (not pcapng, truncated block) prints nothing on stdout, only
//    "pbvbus inspect: FILE: offset N: reason" on stderr, exit 2: a partial summary of a broken
//    file would look like a complete one to a script.

#include <filesystem>
#include <ostream>
#include <string>
#include <system_error>

#include "pbvbus/captures/inspect.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

namespace {

constexpr const char* kInspectUsage =
    "usage: pbvbus inspect CAPTURE [--json]\n"
    "\n"
    "Summarises a pcapng capture (pbvbus's own, or any pcapng with USER0 (147) or\n"
    "PROFIBUS_DL (257) interfaces): per interface the frames by type (SD1..SD4, SC), by\n"
    "request function and response status, by DP service, bad frames by reason, the time span\n"
    "and the shortest idle gap between frames in bit times; then the recorded events, and for\n"
    "a Quantum Hot Standby pair its switchovers with their takeover times.\n"
    "\n"
    "  --json    print the same as one JSON object (times in ns)\n"
    "  --help    this text\n"
    "\n"
    "Exit status: 0 success, 2 bad usage or a file that cannot be read as pcapng\n"
    "(the message names the file offset of the problem).\n";

}  // namespace

int cmd_inspect(const Args& args, std::ostream& out, std::ostream& err) {
  bool json = false;
  std::string path;
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      out << kInspectUsage;
      return 0;
    }
    if (a == "--json") {
      json = true;
    } else if (a.size() > 1 && a[0] == '-') {
      err << "pbvbus inspect: unknown option '" << a << "'\n" << kInspectUsage;
      return 2;
    } else if (path.empty()) {
      path = a;
    } else {
      err << "pbvbus inspect: more than one capture given ('" << path << "', '" << a << "')\n";
      return 2;
    }
  }
  if (path.empty()) {
    err << "pbvbus inspect: no capture file given\n" << kInspectUsage;
    return 2;
  }
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0 && !ec) {
    err << "pbvbus inspect: " << path << ": offset 0: empty file, not a pcapng capture\n";
    return 2;
  }
  captures::PcapngError error;
  const auto summary = captures::inspect_file(path, error);
  if (!summary) {
    err << "pbvbus inspect: " << path << ": " << error.to_string() << "\n";
    return 2;
  }
  out << (json ? captures::to_json(*summary) + "\n" : captures::to_text(*summary));
  return 0;
}

}  // namespace pbvbus::tools
