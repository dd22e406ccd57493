#pragma once
// Reports of a conformance run (battery.hpp): readable text, JSON and JUnit XML
// (conformance/src/report_text.cpp, report_json.cpp, report_junit.cpp).
//
// Text: a header (DUT kind, GSD path and model, ident, modules, address, main baud, mutant or pty
// with its speed, and for a pty the tests whose timing is not meaningful, with why), then per
// group one line per test "  ID  VERDICT  NAME"; a failed test adds its message and its evidence,
// one telegram per line: direction (">" tester → DUT, "<" DUT → tester), start time in bit times
// of the session's baud, the octets in hex, and the note; a reply also its TSDR. A n/a test adds
// its reason. Totals at the end.
//
// JSON, schema "pbvbus.conformance/1" (stable: fields are only ever added). One object:
//   { "schema": "pbvbus.conformance/1",
//     "dut": {
//       "kind": "model" | "pty",
//       "gsd": str,                  // the GSD path as given
//       "model_name": str,           // GSD Model_Name
//       "ident": str,                // "0x0A01"
//       "modules": [ str ],          // as chosen ("" list = the compact station's module)
//       "address": int,
//       "baud": str,                 // main baud, "1.5M" (GSD spelling)
//       "mutant": str | null,        // slave_mutant_name(), model only
//       "pty": str | null,           // the pty path, outside slave only
//       "speed": str | null },       // "1/1000" for a pty (virtual/wall), else null
//     "dut_error": str,              // "" unless the DUT could not be built (then no tests)
//     "passed": bool,                // no dut_error, no failed test and no error
//     "totals": { "tests": int, "pass": int, "fail": int, "error": int, "na": int },
//     "timing_not_meaningful": [ str ],   // ids (pty DUT only; else [])
//     "timing_note": str,            // why, for a pty DUT; else ""
//     "timing": { "tsl_bits": int,   // the run's TimingPlan (battery.hpp): slot time,
//       "reply_wall_ms": int,        //   wall time a pty program gets per reply (0: a model),
//       "exchange_span_us": int,     //   the longest exchange,
//       "twd_us": int, "wd_margin_us": int },  // the watchdog tests' TWD and check margin
//     "tests": [ {
//       "id": str, "group": str, "name": str, "requirement": str,
//       "verdict": "pass" | "fail" | "n/a" | "error",  (error: precondition not established)
//       "message": str,              // why (fail, n/a, error); on pass what was seen
//       "timing_not_meaningful": bool,
//       "evidence": [ {              // the telegrams that decided it, in order
//         "note": str,
//         "baud": int,               // bit/s of the session
//         "request": str,            // hex "68 05 05 68 ..."
//         "request_start_bits": int, "request_end_bits": int,   // virtual time in bit times
//         "expects_reply": bool,
//         "answered": bool,
//         "response": str,           // hex, "" if none
//         "response_flags": int,     // bus::RxFlag bits of the reply (0 = intact)
//         "response_start_bits": int | null,
//         "tsdr_bits": int | null,   // idle bit times request end → reply start
//         "sender": int } ] } ] }    // SA the tester used
//
// JUnit XML (what Jenkins, GitLab and other CI servers read; tests/data/junit/junit.xsd):
//   <testsuites name="pbvbus conformance" tests failures errors skipped time>
//     <testsuite name=GROUP tests failures errors="0" skipped time="0"> per group, in order
//       <testcase classname=GROUP name="ID NAME" time="0">
//         <failure message=MESSAGE type="conformance">evidence as in the text report</failure>
//         | <skipped message=REASON/>   (n/a)
//         <system-out>the requirement</system-out>
//   A DUT that could not be built: one testsuite "DUT" with one testcase carrying <error>.
// Every attribute and text is XML-escaped; characters XML 1.0 forbids are dropped.

#include <string>
#include <vector>

#include "pbvbus/conformance/battery.hpp"

namespace pbvbus::conformance {

/// Why timing checks are meaningless behind a pty (the report's note).
extern const char* const kPtyTimingNote;

/// "model" DUT line etc.: one-line description of the DUT ("PBVB0A01.gsd (pbvbus CS16 ...) @3,
/// 1.5M, model, mutant ignore_fcb").
std::string describe_dut(const DutSpec& spec);

std::string to_text(const BatteryReport& report);
std::string to_json(const BatteryReport& report);
std::string to_junit(const BatteryReport& report);

/// One exchange as text lines (the evidence format of the text and JUnit reports), each line
/// prefixed by `indent`.
std::string evidence_text(const std::vector<Exchange>& evidence, const std::string& indent);

}  // namespace pbvbus::conformance
