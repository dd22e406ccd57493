// FDL bus parameters: per-baud defaults, derived idle times and the §C.1 constraint check
// (protocol-facts.md §C.1, §C.2; decisions documented in bus_params.hpp).
#include "pbvbus/fdl/bus_params.hpp"

#include <algorithm>

namespace pbvbus::fdl {

namespace {

struct TimingRow {
  std::uint32_t tsl, min_tsdr, max_tsdr, tqui, tset;
};

// §C.1 DP-profile table; 45.45k and 31.25k are our decision (bus_params.hpp).
TimingRow timing_row(bus::Baud baud) {
  switch (baud) {
    case bus::Baud::k9_6:
    case bus::Baud::k19_2:
    case bus::Baud::k93_75:
    case bus::Baud::k187_5: return {100, 11, 60, 0, 1};
    case bus::Baud::k31_25:
    case bus::Baud::k45_45: return {640, 11, 400, 0, 95};
    case bus::Baud::k500: return {200, 11, 100, 0, 1};
    case bus::Baud::k1_5M: return {300, 11, 150, 0, 1};
    case bus::Baud::k3M: return {400, 11, 250, 3, 4};
    case bus::Baud::k6M: return {600, 11, 450, 6, 8};
    case bus::Baud::k12M: return {1000, 11, 800, 9, 16};
  }
  return {300, 11, 150, 0, 1};
}

// Octets on the wire of a frame with an FC carrying `n` DU octets, by the §B.1 type choice.
std::uint64_t request_octets(std::uint64_t n) { return n == 0 ? 6 : n == 8 ? 14 : 9 + n; }
// An SRD reply without data is a short acknowledgement (E5).
std::uint64_t response_octets(std::uint64_t n) { return n == 0 ? 1 : request_octets(n); }

std::string too_small(const char* name, std::uint64_t value, const std::string& bound) {
  return std::string(name) + " " + std::to_string(value) + " must be at least " + bound;
}
std::string too_large(const char* name, std::uint64_t value, const std::string& bound) {
  return std::string(name) + " " + std::to_string(value) + " must be at most " + bound;
}

}  // namespace

BusParams BusParams::defaults(bus::Baud baud) {
  const TimingRow row = timing_row(baud);
  BusParams p;
  p.baud = baud;
  p.tsl = row.tsl;
  p.min_tsdr = row.min_tsdr;
  p.max_tsdr = row.max_tsdr;
  p.tqui = row.tqui;
  p.tset = row.tset;
  p.gap_factor = 10;
  p.hsa = 126;
  p.max_retry = 1;
  p.tsdi = 0;
  p.ttr = p.ttr_estimate(kDefaultTtrSlaves, kDefaultTtrOctets);
  return p;
}

std::uint32_t BusParams::tid1() const { return std::max({kTsyn + tsm(), min_tsdr, tsdi}); }

std::uint32_t BusParams::tid2() const { return std::max(kTsyn + tsm(), max_tsdr); }

std::uint32_t BusParams::ttr_estimate(unsigned slaves, unsigned data_octets) const {
  const std::uint64_t n = data_octets;
  const std::uint64_t cycle = 11 * request_octets(n) + max_tsdr + 11 * response_octets(n) + tid1();
  const std::uint64_t token_pass = 11 * 3 + tid1();
  const std::uint64_t gap_poll = 11 * 6 + tsl + tid1();
  const std::uint64_t total = slaves * cycle + token_pass + gap_poll;
  return static_cast<std::uint32_t>(std::min<std::uint64_t>(total, kTtrMax));
}

std::string BusParams::validate() const {
  // 64-bit sums: the fields are checked one after the other, so any of them may still be huge.
  const std::uint64_t tsl_floor = std::uint64_t{max_tsdr} + kTslMargin;
  if (tsl < tsl_floor) return too_small("TSL", tsl, "max TSDR + 15 = " + std::to_string(tsl_floor));
  if (tsl > kTslMax) return too_large("TSL", tsl, std::to_string(kTslMax));
  const std::uint64_t max_tsdr_floor = 35 + 2 * std::uint64_t{tset} + tqui;
  if (max_tsdr < max_tsdr_floor)
    return too_small("max TSDR", max_tsdr,
                     "35 + 2*TSET + TQUI = " + std::to_string(max_tsdr_floor));
  if (max_tsdr > kMaxTsdrMax) return too_large("max TSDR", max_tsdr, std::to_string(kMaxTsdrMax));
  if (min_tsdr < kMinTsdrMin) return too_small("min TSDR", min_tsdr, std::to_string(kMinTsdrMin));
  if (std::uint64_t{min_tsdr} + 1 > max_tsdr)
    return too_large("min TSDR", min_tsdr, "max TSDR - 1 = " + std::to_string(max_tsdr - 1));
  if (min_tsdr > kMinTsdrMax)
    return too_large("min TSDR", min_tsdr, std::to_string(kMinTsdrMax) + " (one Set_Prm octet)");
  if (tqui > kOctetMax) return too_large("TQUI", tqui, std::to_string(kOctetMax));
  if (tset > kOctetMax) return too_large("TSET", tset, std::to_string(kOctetMax));
  if (ttr < kTtrMin) return too_small("TTR", ttr, std::to_string(kTtrMin));
  if (ttr > kTtrMax) return too_large("TTR", ttr, std::to_string(kTtrMax));
  if (gap_factor < 1) return too_small("G (GAP factor)", gap_factor, "1");
  if (gap_factor > kGapFactorMax)
    return too_large("G (GAP factor)", gap_factor, std::to_string(kGapFactorMax));
  if (hsa < 1) return too_small("HSA", hsa, "1");
  if (hsa > kHsaMax) return too_large("HSA", hsa, std::to_string(kHsaMax));
  if (max_retry > kMaxRetryMax)
    return too_large("retry limit", max_retry, std::to_string(kMaxRetryMax));
  return {};
}

}  // namespace pbvbus::fdl
