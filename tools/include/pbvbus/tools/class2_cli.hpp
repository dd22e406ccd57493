#pragma once
// DP master class 2 services from the command line (`pbvbus run SCENARIO --dp2 SPEC`;
// IEC 61158-6 DP "DPM2", protocol-facts.md §D.1, §D.3, §D.4, §D.7, §E.1–§E.3, §E.6; the
// services themselves are dp::Class2Master).
//
//   --dp2 SPEC          (repeatable) one request, SPEC = TIME:SERVICE:STATION[:KEY=VALUE,...]
//     TIME              virtual time at which the request is queued (bus::parse_duration: 1s, 250ms)
//     get_cfg | slave_diag | rd_inp | rd_outp        no arguments
//     set_slave_add     new=N (0..125), ident=0xNNNN, optional no_add_chg=0|1
//     read              slot=N, index=N, len=N (1..240): MSAC_C2 Initiate, Read, then Abort
//     write             slot=N, index=N, data=HEX (1..240 octets): Initiate, Write, then Abort
//   --dp2-line NAME     the line to attach to (default: the first line of the scenario)
//   --dp2-address N     the class-2 master's FDL address (default: the lowest address not used
//                       by any station of that line, from 0 up to HSA)
//
// The class-2 master is an fdl::ActiveStation (the line's bus parameters) with a
// dp::Class2Master as its user, attached at the end of the cable before the run starts. It
// joins the token ring like any master (GAP), so requests queued before it holds the token wait.
//
// Decisions:
//  - Requests run one at a time in the order of their times (Class2Master's queue); a request
//    whose time comes while an earlier one is still running waits behind it. The report gives
//    the time of the request as asked and the virtual time of its result.
//  - One MSAC_C2 connection per slave (Class2Master): a read/write whose slave's connection is
//    still in use by an earlier read/write looks again every 10 ms of virtual time.
//  - read/write open an MSAC_C2 connection for the one request and abort it afterwards, so that
//    a slave is not left with a connection (its supervision would close it after 2 ×
//    Send_Timeout anyway). A failed Initiate is reported as the read/write's result with
//    "initiate: " before the status. The Abort's own result is not reported.
//  - Status "OK" for a positive result, otherwise dp::to_string of the AcyclicStatus ("no
//    response", "not available" + the FDL status, ...). A service that must return data
//    (Get_Cfg, Slave_Diag, Rd_Inp/Outp, Read) but got an SC or an empty reply is reported as
//    "no data (SC)": a DP slave always answers these with data, so this is a plain FDL station
//    (which acknowledges any SRD) rather than a success.
//  - A request that has not finished when the run ends is reported with status "pending".
//  - The text report is one line per request after the run report; the JSON report gets an
//    array "class2" as the last member of its top-level object (inserted before the final
//    brace, so report.cpp needs no change).

#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {

class Simulation;

enum class Class2Op : std::uint8_t { GetCfg, SlaveDiag, RdInp, RdOutp, SetSlaveAdd, Read, Write };
std::string_view to_string(Class2Op op);

struct Class2Request {
  bus::Ticks at = 0;
  Class2Op op = Class2Op::GetCfg;
  std::uint8_t station = 0;
  std::uint8_t new_address = 0;  ///< set_slave_add
  std::uint16_t ident = 0;       ///< set_slave_add
  bool no_add_chg = false;       ///< set_slave_add
  std::uint8_t slot = 0, index = 0, length = 0;  ///< read/write
  std::vector<std::uint8_t> data;                ///< write
};

/// Parses one --dp2 SPEC. nullopt with a message naming the bad part in `error`.
std::optional<Class2Request> parse_class2_spec(std::string_view spec, std::string& error);

struct Class2Options {
  std::vector<Class2Request> requests;
  std::optional<std::string> line;
  std::optional<std::uint8_t> address;
  bool empty() const { return requests.empty(); }
};

enum class Class2ArgResult : std::uint8_t { NotMine, Taken, Error };
/// For `pbvbus run`'s option loop: consumes --dp2/--dp2-line/--dp2-address at args[i] (and its
/// value, advancing i). Error sets `error` (without the "pbvbus run: " prefix).
Class2ArgResult parse_class2_arg(const Args& args, std::size_t& i, Class2Options& opts,
                                 std::string& error);

/// Lines for `pbvbus run --help`.
extern const char* const kClass2Usage;

struct Class2Outcome {
  bus::Ticks at = 0;    ///< when it was asked for
  bus::Ticks done = 0;  ///< when the result came (0 = pending)
  Class2Op op = Class2Op::GetCfg;
  std::uint8_t station = 0;
  std::string status;              ///< "OK", "NotAvailable (RS)", "pending", ...
  std::vector<std::uint8_t> bytes; ///< the response data
  std::string text;                ///< decoded: diagnosis, I/O lengths, DP-V1 error
};

/// The class-2 master of one run. Create after the Simulation and before Simulation::start().
class Class2Cli {
 public:
  ~Class2Cli();
  Class2Cli(const Class2Cli&) = delete;
  Class2Cli& operator=(const Class2Cli&) = delete;

  /// nullptr with the reason in `error` (unknown line, address in use or above HSA).
  static std::unique_ptr<Class2Cli> attach(Simulation& sim, const Class2Options& opts,
                                           std::string& error);

  std::uint8_t address() const;
  const std::string& line_name() const { return m_line_name; }
  const std::vector<Class2Outcome>& outcomes() const { return m_outcomes; }

  /// "class-2 master 0 on dp0:" then one line per request.
  void write_text(std::ostream& os) const;
  /// The "class2" array.
  std::string json() const;
  /// Inserts `,"class2":[...]` before the final '}' of a JSON object.
  void add_to_json(std::string& report_json) const;

 private:
  struct Impl;
  explicit Class2Cli(std::unique_ptr<Impl> impl);
  void submit(std::size_t k);
  void record(std::size_t k, const void* result, const char* prefix);

  std::unique_ptr<Impl> m_impl;
  std::string m_line_name;
  std::vector<Class2Request> m_requests;
  std::vector<Class2Outcome> m_outcomes;
};

std::string format_class2_line(const Class2Outcome& o);

}  // namespace pbvbus::tools
