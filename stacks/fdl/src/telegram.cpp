// FDL telegram codec (protocol-facts.md §B; decisions documented in telegram.hpp).
#include "pbvbus/fdl/telegram.hpp"

#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pbvbus::fdl {

std::string_view to_string(FrameType t) {
  switch (t) {
    case FrameType::SD1: return "SD1";
    case FrameType::SD2: return "SD2";
    case FrameType::SD3: return "SD3";
    case FrameType::SD4: return "SD4";
    case FrameType::SC: return "SC";
  }
  return "?";
}

bool request_fn_valid(std::uint8_t fn) {
  switch (fn & 0x0F) {
    case 0x1:
    case 0x2:
    case 0x8:
    case 0xA:
    case 0xB: return false;
    default: return true;
  }
}

bool response_status_valid(std::uint8_t status) {
  switch (status & 0x0F) {
    case 0x0:
    case 0x1:
    case 0x2:
    case 0x3:
    case 0x8:
    case 0x9:
    case 0xA:
    case 0xC:
    case 0xD: return true;
    default: return false;
  }
}

std::string_view to_string(RequestFn f) {
  switch (f) {
    case RequestFn::TimeEvent: return "TE";
    case RequestFn::SdaLow: return "SDA_low";
    case RequestFn::SdnLow: return "SDN_low";
    case RequestFn::SdaHigh: return "SDA_high";
    case RequestFn::SdnHigh: return "SDN_high";
    case RequestFn::Msrd: return "MSRD";
    case RequestFn::FdlStatus: return "FDL_Status";
    case RequestFn::SrdLow: return "SRD_low";
    case RequestFn::SrdHigh: return "SRD_high";
    case RequestFn::Ident: return "Ident";
    case RequestFn::LsapStatus: return "LSAP_Status";
  }
  return "reserved";
}

std::string_view to_string(ResponseStatus s) {
  switch (s) {
    case ResponseStatus::OK: return "OK";
    case ResponseStatus::UE: return "UE";
    case ResponseStatus::RR: return "RR";
    case ResponseStatus::RS: return "RS";
    case ResponseStatus::DL: return "DL";
    case ResponseStatus::NR: return "NR";
    case ResponseStatus::DH: return "DH";
    case ResponseStatus::RDL: return "RDL";
    case ResponseStatus::RDH: return "RDH";
  }
  return "reserved";
}

std::string_view to_string(StationType s) {
  switch (s) {
    case StationType::Slave: return "slave";
    case StationType::MasterNotReady: return "master not ready";
    case StationType::MasterReady: return "master ready";
    case StationType::MasterInRing: return "master in ring";
  }
  return "?";
}

std::string_view to_string(DecodeError e) {
  switch (e) {
    case DecodeError::None: return "ok";
    case DecodeError::Empty: return "empty frame";
    case DecodeError::UnknownDelimiter: return "unknown start delimiter";
    case DecodeError::Truncated: return "frame truncated";
    case DecodeError::TrailingOctets: return "octets after the end of the frame";
    case DecodeError::LengthMismatch: return "LE and LEr differ";
    case DecodeError::LengthOutOfRange: return "LE outside 4..249";
    case DecodeError::BadSecondDelimiter: return "second SD2 delimiter is not 0x68";
    case DecodeError::BadFcs: return "FCS mismatch";
    case DecodeError::BadEndDelimiter: return "end delimiter is not 0x16";
    case DecodeError::BadSourceAddress: return "source address 127";
    case DecodeError::BadExtension: return "bad address extension";
    case DecodeError::ReservedFunction: return "reserved request function";
    case DecodeError::ReservedStatus: return "reserved response status";
    case DecodeError::BroadcastNotSdn: return "broadcast address with a function other than SDN";
  }
  return "?";
}

std::string_view to_string(EncodeError e) {
  switch (e) {
    case EncodeError::None: return "ok";
    case EncodeError::DataTooLong: return "data unit too long";
    case EncodeError::BadAddress: return "address out of range";
    case EncodeError::BadSap: return "SAP or segment out of range, or segment without SAP";
    case EncodeError::BadFunction: return "reserved function code or status";
    case EncodeError::DataTooShort: return "too few octets for the frame type";
    case EncodeError::WrongFrameType: return "frame type has no FC (token or short acknowledgement)";
  }
  return "?";
}

namespace {

// fcs() itself, inlined into encode_as() and decode() (one call per frame less each way).
[[gnu::always_inline]] inline std::uint8_t fcs_inline(std::span<const std::uint8_t> bytes) {
  // Every frame is summed once when it is encoded and once when it is decoded, so this is on
  // the per-frame path. With SSE2: 16 octets per step (PSADBW against zero sums eight octets
  // into each 64-bit half), and a span of 16 or more ends with one overlapping step whose
  // octets already summed are masked out. Otherwise 8 per step (the even and the odd octets of
  // a word in four 16-bit lanes; 32 words cannot overflow them), then 4, then one by one.
  const std::uint8_t* p = bytes.data();
  std::size_t n = bytes.size();
  std::uint64_t sum = 0;
#if defined(__SSE2__)
  if (n >= 16) {
    __m128i acc = _mm_setzero_si128();
    for (; n >= 16; p += 16, n -= 16)
      acc = _mm_add_epi64(acc, _mm_sad_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)),
                                            _mm_setzero_si128()));
    if (n > 0) {
      // The last 1..15 octets: the 16 octets that end where the span ends, with those already
      // summed masked to zero.
      alignas(16) static constexpr std::uint8_t kTailMask[32] = {
          0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
          0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
      const __m128i last = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + n - 16));
      const __m128i mask = _mm_loadu_si128(reinterpret_cast<const __m128i*>(kTailMask + n));
      acc = _mm_add_epi64(acc, _mm_sad_epu8(_mm_and_si128(last, mask), _mm_setzero_si128()));
      n = 0;
    }
    sum += static_cast<std::uint64_t>(_mm_cvtsi128_si64(acc)) +
           static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(acc, acc)));
  }
#endif
  constexpr std::uint64_t kLow = 0x00FF00FF00FF00FFULL;
  while (n >= 8) {
    std::uint64_t lanes = 0;
    for (int words = 0; words < 32 && n >= 8; ++words, p += 8, n -= 8) {
      std::uint64_t w;
      std::memcpy(&w, p, 8);
      lanes += (w & kLow) + ((w >> 8) & kLow);
    }
    sum += (lanes & 0xFFFF) + ((lanes >> 16) & 0xFFFF) + ((lanes >> 32) & 0xFFFF) + (lanes >> 48);
  }
  if (n >= 4) {
    std::uint32_t w;
    std::memcpy(&w, p, 4);
    sum += (w & 0xFF) + ((w >> 8) & 0xFF) + ((w >> 16) & 0xFF) + (w >> 24);
    p += 4;
    n -= 4;
  }
  for (; n > 0; --n) sum += *p++;
  return static_cast<std::uint8_t>(sum);
}

}  // namespace

std::uint8_t fcs(std::span<const std::uint8_t> bytes) { return fcs_inline(bytes); }

namespace {

// Reads one extension chain (DAE or SAE) starting at body[pos]: octets while bit 7 is set, the
// SAP being the octet with bit 6 clear (§B.2).
bool read_chain(std::span<const std::uint8_t> body, std::size_t& pos, std::optional<std::uint8_t>& sap,
                std::optional<std::uint8_t>& segment) {
  for (;;) {
    if (pos >= body.size()) return false;
    const std::uint8_t o = body[pos++];
    if (o & kExtSegment) {
      if (segment) return false;
      segment = static_cast<std::uint8_t>(o & 0x3F);
    } else {
      if (sap) return false;
      sap = static_cast<std::uint8_t>(o & 0x3F);
    }
    if (!(o & kExt)) break;
  }
  return sap.has_value();
}

// Checks and splits DA SA FC [ext...] DU.
DecodeError decode_body(std::span<const std::uint8_t> body, Telegram& t) {
  const std::uint8_t da = body[0], sa = body[1], fc = body[2];
  t.da = da & 0x7F;
  t.sa = sa & 0x7F;
  t.fc = fc;
  if (t.sa == kBroadcast) return DecodeError::BadSourceAddress;
  if (fc_is_request(fc)) {
    if ((fc & 0x80) && fc != kFcClockValue) return DecodeError::ReservedFunction;
    if (!request_fn_valid(fc)) return DecodeError::ReservedFunction;
    if (t.da == kBroadcast && fn_expects_reply(fc_request_fn(fc))) return DecodeError::BroadcastNotSdn;
  } else {
    if ((fc & 0x80) || !response_status_valid(fc)) return DecodeError::ReservedStatus;
    if (t.da == kBroadcast) return DecodeError::BroadcastNotSdn;
  }
  std::size_t pos = 3;
  if (da & kExt) {
    if (!read_chain(body, pos, t.dsap, t.da_segment)) return DecodeError::BadExtension;
  }
  if (sa & kExt) {
    if (!read_chain(body, pos, t.ssap, t.sa_segment)) return DecodeError::BadExtension;
  }
  t.data = body.subspan(pos);
  return DecodeError::None;
}

}  // namespace

DecodeError decode(std::span<const std::uint8_t> b, Telegram& t) {
  t = Telegram{};
  if (b.empty()) return DecodeError::Empty;
  switch (b[0]) {
    case kSC:
      if (b.size() > 1) return DecodeError::TrailingOctets;
      t.type = FrameType::SC;
      return DecodeError::None;
    case kSD4:
      if (b.size() < 3) return DecodeError::Truncated;
      if (b.size() > 3) return DecodeError::TrailingOctets;
      t.type = FrameType::SD4;
      // A token carries bare addresses: no extension, no broadcast.
      if ((b[1] & kExt) || (b[2] & kExt)) return DecodeError::BadExtension;
      t.da = b[1];
      t.sa = b[2];
      if (t.sa == kBroadcast) return DecodeError::BadSourceAddress;
      if (t.da == kBroadcast) return DecodeError::BroadcastNotSdn;
      return DecodeError::None;
    case kSD1:
    case kSD3: {
      const bool sd1 = b[0] == kSD1;
      const std::size_t total = sd1 ? 6 : 14;
      if (b.size() < total) return DecodeError::Truncated;
      if (b.size() > total) return DecodeError::TrailingOctets;
      t.type = sd1 ? FrameType::SD1 : FrameType::SD3;
      auto body = b.subspan(1, total - 3);
      if (b[total - 1] != kED) return DecodeError::BadEndDelimiter;
      if (fcs_inline(body) != b[total - 2]) return DecodeError::BadFcs;
      return decode_body(body, t);
    }
    case kSD2: {
      if (b.size() < 4) return DecodeError::Truncated;
      const std::size_t le = b[1];
      if (b[2] != le) return DecodeError::LengthMismatch;
      if (b[3] != kSD2) return DecodeError::BadSecondDelimiter;
      if (le < kMinLe || le > kMaxLe) return DecodeError::LengthOutOfRange;
      const std::size_t total = le + 6;
      if (b.size() < total) return DecodeError::Truncated;
      if (b.size() > total) return DecodeError::TrailingOctets;
      t.type = FrameType::SD2;
      auto body = b.subspan(4, le);
      if (b[total - 1] != kED) return DecodeError::BadEndDelimiter;
      if (fcs_inline(body) != b[total - 2]) return DecodeError::BadFcs;
      return decode_body(body, t);
    }
    default: return DecodeError::UnknownDelimiter;
  }
}

int frame_length(std::span<const std::uint8_t> b) {
  if (b.empty()) return 0;
  switch (b[0]) {
    case kSC: return 1;
    case kSD4: return 3;
    case kSD1: return 6;
    case kSD3: return 14;
    case kSD2: {
      if (b.size() >= 2 && (b[1] < kMinLe || b[1] > kMaxLe)) return -1;
      if (b.size() >= 3 && b[1] != b[2]) return -1;
      if (b.size() < 4) return 0;
      if (b[1] != b[2] || b[3] != kSD2 || b[1] < kMinLe || b[1] > kMaxLe) return -1;
      return b[1] + 6;
    }
    default: return -1;
  }
}

namespace {
// The FC and address checks decode_body() applies, so that encode never makes what decode
// rejects.
EncodeError check_header(const FrameSpec& s) {
  if (s.da > kBroadcast || s.sa >= kBroadcast) return EncodeError::BadAddress;
  if (fc_is_request(s.fc)) {
    if ((s.fc & 0x80) && s.fc != kFcClockValue) return EncodeError::BadFunction;
    if (!request_fn_valid(s.fc)) return EncodeError::BadFunction;
    if (s.da == kBroadcast && fn_expects_reply(fc_request_fn(s.fc))) return EncodeError::BadAddress;
  } else {
    if ((s.fc & 0x80) || !response_status_valid(s.fc)) return EncodeError::BadFunction;
    if (s.da == kBroadcast) return EncodeError::BadAddress;
  }
  return EncodeError::None;
}

// Writes DA SA FC [DAE..] [SAE..] DU into `body`; returns its length, or 0 on error.
std::size_t write_body(const FrameSpec& s, std::uint8_t* body, std::size_t cap, EncodeError& err) {
  err = check_header(s);
  if (err != EncodeError::None) return 0;
  if ((s.dsap && *s.dsap > 63) || (s.ssap && *s.ssap > 63) || (s.da_segment && *s.da_segment > 63) ||
      (s.sa_segment && *s.sa_segment > 63) || (s.da_segment && !s.dsap) || (s.sa_segment && !s.ssap)) {
    err = EncodeError::BadSap;
    return 0;
  }
  std::size_t n = 0;
  const std::size_t ext = (s.dsap ? 1u : 0u) + (s.ssap ? 1u : 0u) + (s.da_segment ? 1u : 0u) +
                          (s.sa_segment ? 1u : 0u);
  if (3 + ext + s.data.size() > cap) {
    err = EncodeError::DataTooLong;
    return 0;
  }
  body[n++] = static_cast<std::uint8_t>(s.da | (s.dsap ? kExt : 0));
  body[n++] = static_cast<std::uint8_t>(s.sa | (s.ssap ? kExt : 0));
  body[n++] = s.fc;
  if (s.dsap) {
    if (s.da_segment) body[n++] = static_cast<std::uint8_t>(kExt | kExtSegment | *s.da_segment);
    body[n++] = *s.dsap;
  }
  if (s.ssap) {
    if (s.sa_segment) body[n++] = static_cast<std::uint8_t>(kExt | kExtSegment | *s.sa_segment);
    body[n++] = *s.ssap;
  }
  if (!s.data.empty()) std::memcpy(body + n, s.data.data(), s.data.size());
  n += s.data.size();
  err = EncodeError::None;
  return n;
}
}  // namespace

namespace {

// encode_as() itself, inlined into encode() (the per-frame path: one call less).
[[gnu::always_inline]] inline EncodeError encode_as_inline(FrameType type, const FrameSpec& s,
                                                           Frame& out) {
  out.len = 0;
  EncodeError err = EncodeError::None;
  auto& b = out.buf;
  switch (type) {
    case FrameType::SD1: {
      const std::size_t n = write_body(s, b.data() + 1, 3, err);
      if (!n) return err;
      b[0] = kSD1;
      b[4] = fcs_inline({b.data() + 1, 3});
      b[5] = kED;
      out.len = 6;
      return EncodeError::None;
    }
    case FrameType::SD3: {
      const std::size_t n = write_body(s, b.data() + 1, 11, err);
      if (!n) return err;
      if (n != 11) return EncodeError::DataTooShort;
      b[0] = kSD3;
      b[12] = fcs_inline({b.data() + 1, 11});
      b[13] = kED;
      out.len = 14;
      return EncodeError::None;
    }
    case FrameType::SD2: {
      const std::size_t n = write_body(s, b.data() + 4, kMaxLe, err);
      if (!n) return err;
      if (n < kMinLe) return EncodeError::DataTooShort;  // LE 3 is an SD1
      b[0] = kSD2;
      b[1] = b[2] = static_cast<std::uint8_t>(n);
      b[3] = kSD2;
      b[4 + n] = fcs_inline({b.data() + 4, n});
      b[5 + n] = kED;
      out.len = static_cast<std::uint16_t>(n + 6);
      return EncodeError::None;
    }
    case FrameType::SD4:
    case FrameType::SC: return EncodeError::WrongFrameType;
  }
  return EncodeError::WrongFrameType;
}

}  // namespace

EncodeError encode_as(FrameType type, const FrameSpec& s, Frame& out) {
  return encode_as_inline(type, s, out);
}

EncodeError encode(const FrameSpec& s, Frame& out) {
  const std::size_t after_fc = (s.dsap ? 1u : 0u) + (s.ssap ? 1u : 0u) + (s.da_segment ? 1u : 0u) +
                               (s.sa_segment ? 1u : 0u) + s.data.size();
  const FrameType t = after_fc == 0 ? FrameType::SD1 : after_fc == 8 ? FrameType::SD3 : FrameType::SD2;
  return encode_as_inline(t, s, out);
}

Frame encode_token(std::uint8_t da, std::uint8_t sa) {
  Frame f;
  f.buf[0] = kSD4;
  f.buf[1] = static_cast<std::uint8_t>(da & 0x7F);
  f.buf[2] = static_cast<std::uint8_t>(sa & 0x7F);
  f.len = 3;
  return f;
}

Frame encode_sc() {
  Frame f;
  f.buf[0] = kSC;
  f.len = 1;
  return f;
}

FrameSpec to_spec(const Telegram& t) {
  FrameSpec s;
  s.da = t.da;
  s.sa = t.sa;
  s.fc = t.fc;
  s.dsap = t.dsap;
  s.ssap = t.ssap;
  s.da_segment = t.da_segment;
  s.sa_segment = t.sa_segment;
  s.data = t.data;
  return s;
}

EncodeError reencode(const Telegram& t, Frame& out) {
  switch (t.type) {
    case FrameType::SD4:
      if (t.da >= kBroadcast || t.sa >= kBroadcast) {
        out.len = 0;
        return EncodeError::BadAddress;
      }
      out = encode_token(t.da, t.sa);
      return EncodeError::None;
    case FrameType::SC: out = encode_sc(); return EncodeError::None;
    default: return encode_as(t.type, to_spec(t), out);
  }
}

}  // namespace pbvbus::fdl
