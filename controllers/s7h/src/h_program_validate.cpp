// validate(ProgramSpec) (devices/h_program.hpp): every problem of a scenario's program, one
// message each, naming the network and the address. All range arithmetic is done in 64 bits
// so that a huge offset or length cannot wrap into range.
#include <cstdint>
#include <string>
#include <vector>

#include "pbvbus/s7h/h_program.hpp"

namespace pbvbus::devices {
namespace {

using U64 = std::uint64_t;

struct Range {
  U64 begin;
  U64 end;  // exclusive
};

bool overlap(Range a, Range b) { return a.begin < b.end && b.begin < a.end; }

std::string ib(U64 a) { return "IB " + std::to_string(a); }
std::string qb(U64 a) { return "QB " + std::to_string(a); }
std::string span_text(const std::string& first, U64 len) {
  return first + " (" + std::to_string(len) + (len == 1 ? " octet)" : " octets)");
}

class Checker {
 public:
  Checker(std::size_t pii, std::size_t piq) : pii_(pii), piq_(piq) {}
  std::vector<std::string> out;

  void inside_pii(const std::string& who, const char* field, U64 at, U64 len) {
    if (at + len > pii_)
      out.push_back(who + ": " + field + " " + span_text(ib(at), len) + " lies outside the PII (" +
                    std::to_string(pii_) + " bytes, IB 0.." + ib_last(pii_) + ")");
  }
  void inside_piq(const std::string& who, const char* field, U64 at, U64 len) {
    if (at + len > piq_)
      out.push_back(who + ": " + field + " " + span_text(qb(at), len) + " lies outside the PIQ (" +
                    std::to_string(piq_) + " bytes, QB 0.." + qb_last(piq_) + ")");
  }

 private:
  static std::string ib_last(U64 n) { return n == 0 ? "none" : ib(n - 1); }
  static std::string qb_last(U64 n) { return n == 0 ? "none" : qb(n - 1); }
  U64 pii_;
  U64 piq_;
};

}  // namespace

std::vector<std::string> validate(const ProgramSpec& spec, std::size_t pii_bytes,
                                  std::size_t piq_bytes) {
  Checker c(pii_bytes, piq_bytes);
  for (auto& m : validate_image_sizes(pii_bytes, piq_bytes)) c.out.push_back(m);
  if (spec.scan_time <= 0)
    c.out.push_back("program: scan_time " + std::to_string(spec.scan_time) +
                    " ticks must be > 0");

  // ---- copies
  std::vector<Range> copy_out;
  for (std::size_t i = 0; i < spec.copies.size(); ++i) {
    const auto& n = spec.copies[i];
    const std::string who = "copy " + std::to_string(i);
    if (n.length == 0) {
      c.out.push_back(who + ": length 0 (at least 1 octet)");
      copy_out.push_back(Range{0, 0});  // keeps the indices of the later messages right
      continue;
    }
    c.inside_pii(who, "from_input", n.from_input, n.length);
    c.inside_piq(who, "to_output", n.to_output, n.length);
    const Range r{n.to_output, U64{n.to_output} + n.length};
    for (std::size_t j = 0; j < copy_out.size(); ++j)
      if (overlap(r, copy_out[j]))
        c.out.push_back(who + ": to_output " + span_text(qb(n.to_output), n.length) +
                        " overlaps the output of copy " + std::to_string(j));
    copy_out.push_back(r);
  }

  // ---- counters
  std::vector<Range> value_out;  // index = counter; empty range if invalid
  std::vector<std::pair<U64, unsigned>> pulses;  // (byte, bit); byte = UINT64_MAX if none
  for (std::size_t i = 0; i < spec.counters.size(); ++i) {
    const auto& n = spec.counters[i];
    const std::string who = "counter " + std::to_string(i);
    const bool width_ok = n.width == 1 || n.width == 2 || n.width == 4;
    if (!width_ok)
      c.out.push_back(who + ": width " + std::to_string(n.width) +
                      " at " + qb(n.output) + " (must be 1, 2 or 4 octets)");
    else
      c.inside_piq(who, "output", n.output, n.width);
    if (n.period <= 0)
      c.out.push_back(who + ": period " + std::to_string(n.period) + " ticks at " + qb(n.output) +
                      " must be > 0");
    const bool has_pulse = n.pulse_high != 0;
    if (n.pulse_high < 0)
      c.out.push_back(who + ": pulse_high " + std::to_string(n.pulse_high) +
                      " ticks must be ≥ 0");
    if (n.pulse_high > 0 && n.period > 0 && n.pulse_high > n.period)
      c.out.push_back(who + ": pulse_high " + std::to_string(n.pulse_high) +
                      " ticks is longer than the period " + std::to_string(n.period));
    if (has_pulse) {
      c.inside_piq(who, "pulse_output", n.pulse_output, 1);
      if (n.pulse_bit > 7)
        c.out.push_back(who + ": pulse_bit " + std::to_string(n.pulse_bit) + " at " +
                        qb(n.pulse_output) + " (must be 0..7)");
    }
    const Range val = width_ok ? Range{n.output, U64{n.output} + n.width} : Range{0, 0};
    if (has_pulse && overlap(val, Range{n.pulse_output, U64{n.pulse_output} + 1}))
      c.out.push_back(who + ": pulse Q " + std::to_string(n.pulse_output) + "." +
                      std::to_string(n.pulse_bit) + " lies inside its own value " +
                      span_text(qb(n.output), n.width));
    for (std::size_t j = 0; j < value_out.size(); ++j) {
      if (overlap(val, value_out[j]))
        c.out.push_back(who + ": output " + span_text(qb(n.output), n.width) +
                        " overlaps the value of counter " + std::to_string(j));
      const auto [pbyte, pbit] = pulses[j];
      if (pbyte != UINT64_MAX && overlap(val, Range{pbyte, pbyte + 1}))
        c.out.push_back(who + ": output " + span_text(qb(n.output), n.width) +
                        " overlaps the pulse byte of counter " + std::to_string(j));
      if (has_pulse && overlap(value_out[j], Range{n.pulse_output, U64{n.pulse_output} + 1}))
        c.out.push_back(who + ": pulse " + qb(n.pulse_output) + " lies inside the value of counter " +
                        std::to_string(j));
      if (has_pulse && pbyte == n.pulse_output && pbit == n.pulse_bit)
        c.out.push_back(who + ": pulse Q " + std::to_string(n.pulse_output) + "." +
                        std::to_string(n.pulse_bit) + " is also the pulse of counter " +
                        std::to_string(j));
    }
    value_out.push_back(val);
    pulses.emplace_back(has_pulse ? U64{n.pulse_output} : UINT64_MAX, n.pulse_bit);
  }

  // ---- discrepancy monitors
  std::vector<Range> mon_out;
  for (std::size_t i = 0; i < spec.monitors.size(); ++i) {
    const auto& n = spec.monitors[i];
    const std::string who = "monitor " + std::to_string(i);
    if (n.length == 0) {
      c.out.push_back(who + ": length 0 (at least 1 octet)");
      mon_out.push_back(Range{0, 0});
      continue;
    }
    if (n.mask == 0)
      c.out.push_back(who + ": mask 0 at " + ib(n.input_a) + " monitors no bit");
    if (n.discrepancy_time < 0)
      c.out.push_back(who + ": discrepancy_time " + std::to_string(n.discrepancy_time) +
                      " ticks must be ≥ 0");
    c.inside_pii(who, "input_a", n.input_a, n.length);
    c.inside_pii(who, "input_b", n.input_b, n.length);
    c.inside_piq(who, "to_output", n.to_output, n.length);
    const Range a{n.input_a, U64{n.input_a} + n.length};
    const Range b{n.input_b, U64{n.input_b} + n.length};
    if (overlap(a, b))
      c.out.push_back(who + ": input_a " + span_text(ib(n.input_a), n.length) +
                      " overlaps input_b " + span_text(ib(n.input_b), n.length) +
                      " (two modules cannot share an address)");
    const Range r{n.to_output, U64{n.to_output} + n.length};
    for (std::size_t j = 0; j < mon_out.size(); ++j)
      if (overlap(r, mon_out[j]))
        c.out.push_back(who + ": to_output " + span_text(qb(n.to_output), n.length) +
                        " overlaps the output of monitor " + std::to_string(j));
    mon_out.push_back(r);
  }
  return std::move(c.out);
}

}  // namespace pbvbus::devices
