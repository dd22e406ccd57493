// The battery's times (battery.hpp TimingPlan; docs/conformance.md "Timing").
//
// Why these numbers:
// - Slot time. A model answers within its GSD's MaxTsdr, so the DP-profile TSL (max TSDR + 15 at
//   least) is right for it. A program behind a pty answers in the operating system's time: the
//   slot time is made long enough to give it `reply_wall` of wall time at the pace (TSL in bit
//   times = reply_wall × speed × baud), within the standard's TSL <= 16 383 bit times
//   (protocol-facts.md §C.1). A larger TSL is legal: it is a bus parameter the master chooses.
// - Watchdog. A slave restarts its watchdog on every telegram from its master, and may do so at
//   the start or the end of a telegram or after its own reply; the watchdog tests must therefore
//   never let a normal exchange look like a silence: TWD >= 4 × the longest gap between two of
//   the owner's requests (TSYN + longest request + TSL + longest reply + the Data_Exchange
//   spacing). At 9.6 kbit/s a Chk_Cfg of 19 octets alone lasts 21.8 ms: a 10 ms watchdog there
//   cannot be kept by any slave. 100 ms is the floor (long against a DP cycle).
// - Margins of the before/after checks (PRM-06): a model's watchdog is exact in virtual time, so
//   1 % of TWD (at least 1 ms) suffices. A program's may start anywhere between the start of the
//   owner's last request and the end of its own reply to it, and its clock is the wall clock
//   with a scheduling jitter (30 ms on a loaded machine) scaled by the pace: the margin adds the
//   longest request, the slot time, the longest reply and twice that jitter, and TWD is raised to
//   at least 4 × the margin so that "before" and "after" stay far apart.

#include <algorithm>
#include <cstdio>

#include "pbvbus/conformance/battery.hpp"
#include "timing_plan.hpp"

namespace pbvbus::conformance {

namespace {

constexpr std::int64_t kTsynBits = 33;
/// Octets of an SD2 frame around its DU with both SAPs: SD LE LEr SD DA SA FC DSAP SSAP .. FCS ED.
constexpr std::int64_t kSd2Overhead = 11;
constexpr bus::Ticks kTen = 10 * bus::kTicksPerMs;
constexpr std::chrono::milliseconds kProgramJitter{30};

std::int64_t bits_for_wall(std::chrono::milliseconds wall, bus::Speed speed, bus::Baud baud) {
  // wall × (num/den) of virtual time, in bit times: ceil.
  const auto bps = static_cast<std::int64_t>(static_cast<std::uint32_t>(baud));
  const std::int64_t num = wall.count() * speed.num * bps;
  const std::int64_t den = 1000LL * speed.den;
  return (num + den - 1) / den;
}

bus::Ticks round_up_10ms(bus::Ticks t) { return (t + kTen - 1) / kTen * kTen; }

std::string ms_text(bus::Ticks t) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f ms", static_cast<double>(t) / static_cast<double>(bus::kTicksPerMs));
  return b;
}

}  // namespace

bus::Speed auto_speed(bus::Baud baud, std::chrono::milliseconds reply_wall) {
  static constexpr std::uint32_t kLadder[] = {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000};
  for (const std::uint32_t den : kLadder) {
    const bus::Speed s{1, den};
    if (bits_for_wall(reply_wall, s, baud) <= fdl::BusParams::kTslMax) return s;
  }
  return bus::Speed{1, 1000};
}

std::string TimingPlan::summary() const {
  std::string s = "TSL " + std::to_string(tsl_bits) + " bit times";
  if (reply_wall.count() > 0) s += " (" + std::to_string(reply_wall.count()) + " ms wall for a reply)";
  s += ", watchdog tests TWD " + ms_text(twd) + " checked " + ms_text(wd_margin) +
       " before and after its expiry (longest exchange " + ms_text(exchange_span) + ")";
  return s;
}

namespace detail {

TimingPlan plan_timing(const DutSpec& spec, const dp::SlaveParams& p, std::size_t input_len,
                       std::size_t output_len, bus::Baud baud, std::uint32_t profile_tsl,
                       bus::Ticks dx_interval) {
  TimingPlan t;
  const bool outside = spec.pty_path.has_value();
  const std::size_t req_du =
      std::max({p.set_prm_du().size(), p.chk_cfg_du().size(), output_len, std::size_t{4}});
  std::size_t reply_du = std::max({std::size_t{6}, input_len, p.chk_cfg_du().size()});
  if (spec.gsd) reply_du = std::max<std::size_t>(reply_du, spec.gsd->slave_features().max_diag_data_len);
  t.longest_request = bus::chars_to_ticks(kSd2Overhead + static_cast<std::int64_t>(req_du), baud);
  t.longest_reply = bus::chars_to_ticks(kSd2Overhead + static_cast<std::int64_t>(reply_du), baud);

  std::int64_t tsl = profile_tsl;
  if (outside) {
    tsl = std::clamp<std::int64_t>(std::max<std::int64_t>(tsl, bits_for_wall(spec.reply_wall, spec.speed, baud)),
                                   tsl, fdl::BusParams::kTslMax);
    // What the program really gets, in wall milliseconds (tsl bits at the baud, slowed by the pace).
    const auto bps = static_cast<std::int64_t>(static_cast<std::uint32_t>(baud));
    t.reply_wall = std::chrono::milliseconds(tsl * 1000 * spec.speed.den / (bps * spec.speed.num));
    t.pace_jitter = kProgramJitter.count() * bus::kTicksPerMs * spec.speed.num / spec.speed.den;
  }
  t.tsl_bits = static_cast<std::uint32_t>(tsl);
  t.exchange_span = bus::bits_to_ticks(kTsynBits + tsl, baud) + t.longest_request + t.longest_reply +
                    dx_interval;

  const bus::Ticks extra =
      outside ? t.longest_request + bus::bits_to_ticks(tsl, baud) + t.longest_reply + 2 * t.pace_jitter : 0;
  t.twd = round_up_10ms(std::max({100 * bus::kTicksPerMs, 4 * t.exchange_span, 4 * extra}));
  for (int i = 0; i < 4; ++i) {
    t.wd_margin = std::max(bus::kTicksPerMs, t.twd / 100) + extra;
    if (t.twd >= 4 * t.wd_margin) break;
    t.twd = round_up_10ms(4 * t.wd_margin);
  }
  return t;
}

}  // namespace detail

}  // namespace pbvbus::conformance
