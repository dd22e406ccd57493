#pragma once
// Running Debian's tshark (and capinfos) from tests: popen, output captured, the pbvbus Lua
// dissector loaded on request. Integration tests reuse these (link tests/captures/
// tshark_helpers.cpp, or copy the file into their suite as *_helpers.cpp).

#include <optional>
#include <string>
#include <vector>

namespace pbvbus::test {

struct CommandResult {
  int exit_code = -1;  ///< exit status of the command, -1 if it could not be run
  std::string out;     ///< stdout
  std::string err;     ///< stderr
};

/// Runs `command` with /bin/sh, capturing stdout and stderr separately.
CommandResult run_command(const std::string& command);
/// 'single-quoted' for the shell.
std::string shell_quote(const std::string& s);

/// Full path of a program found in PATH, or nullopt.
std::optional<std::string> find_program(const std::string& name);
/// Whether tshark can be run; use as
///   if (!tshark_available()) GTEST_SKIP() << kNoTshark;
bool tshark_available();
inline constexpr const char* kNoTshark =
    "tshark not found in PATH (Debian package tshark; CI installs it)";

/// PBVBUS_SOURCE_DIR/captures/lua/pbvbus.lua
std::string dissector_path();

/// tshark -r FILE [-X lua_script:pbvbus.lua] ARGS...
CommandResult tshark(const std::string& file, const std::vector<std::string>& args,
                     bool with_dissector = true);

/// tshark -r FILE -X lua_script:... [-Y FILTER] -T fields -E separator=| -E occurrence=a
/// -E aggregator=, -e F1 -e F2...: one row per packet, one cell per field (all occurrences of
/// a field joined with ','). Fails the calling test (ADD_FAILURE) if tshark fails or writes a
/// Lua error.
std::vector<std::vector<std::string>> tshark_fields(const std::string& file,
                                                    const std::vector<std::string>& fields,
                                                    const std::string& filter = {});

/// The info column of every packet, decoded with the dissector.
std::vector<std::string> tshark_info(const std::string& file);

}  // namespace pbvbus::test
