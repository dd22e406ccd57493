#include "tshark_helpers.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace pbvbus::test {

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q += "'\\''";
    else
      q += c;
  }
  return q + "'";
}

CommandResult run_command(const std::string& command) {
  CommandResult r;
  char tmpl[] = "/tmp/pbvbus_cmd_stderr_XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd < 0) return r;
  close(fd);
  const std::string full = command + " 2>" + shell_quote(tmpl);
  std::FILE* p = popen(full.c_str(), "r");
  if (!p) {
    std::remove(tmpl);
    return r;
  }
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(tmpl);
  std::stringstream ss;
  ss << err.rdbuf();
  r.err = ss.str();
  std::remove(tmpl);
  return r;
}

std::optional<std::string> find_program(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (!path) return std::nullopt;
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const std::filesystem::path p = std::filesystem::path(dir) / name;
    if (access(p.c_str(), X_OK) == 0) return p.string();
  }
  return std::nullopt;
}

bool tshark_available() {
  return find_program("tshark").has_value();
}

std::string dissector_path() {
  return std::string(PBVBUS_SOURCE_DIR) + "/captures/lua/pbvbus.lua";
}

CommandResult tshark(const std::string& file, const std::vector<std::string>& args,
                     bool with_dissector) {
  std::string cmd = "tshark -n";
  if (with_dissector) cmd += " -X " + shell_quote("lua_script:" + dissector_path());
  cmd += " -r " + shell_quote(file);
  for (const std::string& a : args) cmd += " " + shell_quote(a);
  return run_command(cmd);
}

namespace {
bool lua_error(const CommandResult& r) {
  return r.err.find("Lua") != std::string::npos || r.out.find("Lua Error") != std::string::npos;
}
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s) {
    if (c == sep) {
      out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}
}  // namespace

std::vector<std::vector<std::string>> tshark_fields(const std::string& file,
                                                    const std::vector<std::string>& fields,
                                                    const std::string& filter) {
  std::vector<std::string> args;
  if (!filter.empty()) {
    args.push_back("-Y");
    args.push_back(filter);
  }
  for (const char* a :
       {"-T", "fields", "-E", "separator=|", "-E", "occurrence=a", "-E", "aggregator=,"})
    args.push_back(a);
  for (const std::string& f : fields) {
    args.push_back("-e");
    args.push_back(f);
  }
  const CommandResult r = tshark(file, args);
  if (r.exit_code != 0 || lua_error(r))
    ADD_FAILURE() << "tshark failed (" << r.exit_code << "): " << r.err << r.out;
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : split(r.out, '\n'))
    if (!line.empty()) rows.push_back(split(line, '|'));
  return rows;
}

std::vector<std::string> tshark_info(const std::string& file) {
  std::vector<std::string> out;
  for (auto& row : tshark_fields(file, {"_ws.col.Info"})) out.push_back(row.empty() ? "" : row[0]);
  return out;
}

}  // namespace pbvbus::test
