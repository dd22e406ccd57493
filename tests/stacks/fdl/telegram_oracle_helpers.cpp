#include "telegram_oracle_helpers.hpp"

#include <algorithm>
#include <array>
#include <cstring>

namespace pbvbus::test {

using namespace pbvbus::fdl;

namespace {

bool same_fields(const Telegram& a, const Telegram& b) {
  return a.type == b.type && a.da == b.da && a.sa == b.sa && a.fc == b.fc && a.dsap == b.dsap &&
         a.ssap == b.ssap && a.da_segment == b.da_segment && a.sa_segment == b.sa_segment &&
         std::ranges::equal(a.data, b.data);
}

bool same_fields(const Telegram& t, const FrameSpec& s) {
  return t.da == s.da && t.sa == s.sa && t.fc == s.fc && t.dsap == s.dsap && t.ssap == s.ssap &&
         t.da_segment == s.da_segment && t.sa_segment == s.sa_segment &&
         std::ranges::equal(t.data, s.data);
}

const char* check_ranges(std::span<const std::uint8_t> in, const Telegram& t) {
  if (t.da > 127 || t.sa > 126) return "decoded address out of range";
  for (const auto& o : {t.dsap, t.ssap, t.da_segment, t.sa_segment})
    if (o && *o > 63) return "decoded SAP or segment above 63";
  if ((t.da_segment && !t.dsap) || (t.sa_segment && !t.ssap)) return "segment without its SAP";
  if (!t.data.empty() &&
      (t.data.data() < in.data() || t.data.data() + t.data.size() > in.data() + in.size()))
    return "data span outside the input";
  if ((t.type == FrameType::SD4 || t.type == FrameType::SC) &&
      (t.fc != 0 || t.dsap || t.ssap || !t.data.empty()))
    return "token or SC with FC, SAP or data";
  if (t.type == FrameType::SD1 && (t.dsap || t.ssap || !t.data.empty()))
    return "SD1 with octets after FC";
  return nullptr;
}

// Rewrites the chain at out[pos] (length 1 or 2) to segment-first; returns its length.
std::size_t canonical_chain(std::uint8_t* out, std::size_t pos, std::optional<std::uint8_t> sap,
                            std::optional<std::uint8_t> segment) {
  if (!segment) return 1;
  out[pos] = static_cast<std::uint8_t>(kExt | kExtSegment | *segment);
  out[pos + 1] = *sap;
  return 2;
}

}  // namespace

std::size_t canonical_chain_order(std::span<const std::uint8_t> in, const Telegram& t,
                                  std::uint8_t* out) {
  std::memcpy(out, in.data(), in.size());
  std::size_t pos = 0;
  switch (t.type) {
    case FrameType::SD1:
    case FrameType::SD3: pos = 4; break;
    case FrameType::SD2: pos = 7; break;
    default: return in.size();
  }
  if (t.dsap) pos += canonical_chain(out, pos, t.dsap, t.da_segment);
  if (t.ssap) canonical_chain(out, pos, t.ssap, t.sa_segment);
  return in.size();
}

const char* decode_oracle(std::span<const std::uint8_t> in) {
  const int flen = frame_length(in);
  if (flen < -1 || flen > static_cast<int>(kMaxFrame)) return "frame_length out of range";
  Telegram t;
  if (decode(in, t) != DecodeError::None) return nullptr;

  if (const char* why = check_ranges(in, t)) return why;
  Frame f;
  if (reencode(t, f) != EncodeError::None) return "accepted frame does not re-encode";
  std::array<std::uint8_t, kMaxFrame> canon{};
  if (in.size() > canon.size()) return "accepted frame longer than kMaxFrame";
  const std::size_t n = canonical_chain_order(in, t, canon.data());
  if (!std::ranges::equal(std::span<const std::uint8_t>(canon.data(), n), f.bytes()))
    return "re-encoded bytes differ from the accepted frame";
  Telegram t2;
  if (decode(f.bytes(), t2) != DecodeError::None) return "re-encoded frame does not decode";
  if (!same_fields(t, t2)) return "re-encoded frame decodes to other fields";

  if (flen != static_cast<int>(in.size())) return "frame_length disagrees with decode";
  for (std::size_t k = 1; k < in.size(); ++k) {
    const int l = frame_length(in.first(k));
    if (l != 0 && l != flen) return "frame_length of a prefix disagrees";
  }
  return nullptr;
}

// Layout of the input: [0] DA, [1] SA, [2] FC, [3] flags, [4] DSAP, [5] SSAP, [6] DA segment,
// [7] SA segment, [8..] data. Flags: bit 0 DSAP, 1 SSAP, 2 DA segment, 3 SA segment,
// bits 4-5: 0 encode(), 1 encode_as(SD1), 2 SD2, 3 SD3; bit 6 encode_as(SD4 or SC).
// Missing octets count as 0.
const char* encode_oracle(std::span<const std::uint8_t> in) {
  auto at = [&](std::size_t i) -> std::uint8_t { return i < in.size() ? in[i] : 0; };
  const std::uint8_t flags = at(3);
  FrameSpec s;
  s.da = at(0);
  s.sa = at(1);
  s.fc = at(2);
  if (flags & 1) s.dsap = at(4);
  if (flags & 2) s.ssap = at(5);
  if (flags & 4) s.da_segment = at(6);
  if (flags & 8) s.sa_segment = at(7);
  if (in.size() > 8) s.data = in.subspan(8);

  Frame f;
  const unsigned mode = (flags >> 4) & 3;
  EncodeError err;
  if (flags & 0x40) {
    err = encode_as((flags & 0x80) ? FrameType::SC : FrameType::SD4, s, f);
    if (err != EncodeError::WrongFrameType) return "encode_as(SD4/SC) did not refuse";
    return nullptr;
  }
  constexpr FrameType kTypes[] = {FrameType::SD1, FrameType::SD1, FrameType::SD2, FrameType::SD3};
  err = mode == 0 ? encode(s, f) : encode_as(kTypes[mode], s, f);
  if (err != EncodeError::None) {
    if (!f.empty()) return "failed encode left a frame";
    return nullptr;
  }
  Telegram t;
  if (decode(f.bytes(), t) != DecodeError::None) return "encoded frame does not decode";
  if (!same_fields(t, s)) return "encoded frame decodes to other fields";
  if (frame_length(f.bytes()) != static_cast<int>(f.len)) return "frame_length of encoded frame";
  const std::size_t after_fc = f.len - (t.type == FrameType::SD2 ? 9u : 6u);
  if (mode == 0) {
    const FrameType want = after_fc == 0 ? FrameType::SD1
                           : after_fc == 8 ? FrameType::SD3
                                           : FrameType::SD2;
    if (t.type != want) return "encode() chose the wrong frame type";
  } else if (t.type != kTypes[mode]) {
    return "encode_as() produced another frame type";
  }
  return nullptr;
}

}  // namespace pbvbus::test
