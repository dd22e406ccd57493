#include "pbvbus/captures/event_record.hpp"

#include <algorithm>
#include <cstring>

namespace pbvbus::captures {

namespace {
void put_u16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v);
  p[1] = static_cast<std::uint8_t>(v >> 8);
}
void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put_u64(std::uint8_t* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}
std::uint64_t get_le(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
/// Longest prefix of `text` not longer than kEventMaxText that does not split a UTF-8 sequence.
std::size_t text_len(std::string_view text) {
  if (text.size() <= kEventMaxText) return text.size();
  std::size_t n = kEventMaxText;
  while (n > 0 && (static_cast<std::uint8_t>(text[n]) & 0xC0) == 0x80) --n;
  return n;
}
}  // namespace

std::string_view to_string(EventCategory c) {
  switch (c) {
    case EventCategory::Line:
      return "line";
    case EventCategory::Station:
      return "station";
    case EventCategory::Master:
      return "master";
    case EventCategory::Redundancy:
      return "redundancy";
    case EventCategory::Cpu:
      return "cpu";
    case EventCategory::Hsby:
      return "hsby";
    case EventCategory::Note:
      return "note";
  }
  return "unknown";
}

std::size_t encoded_event_size(const EventRecord& e) {
  return kEventHeaderSize + text_len(e.text);
}

std::size_t encode_event(const EventRecord& e, std::span<std::uint8_t> out) {
  return encode_event(e, e.text, out);
}

std::size_t encode_event(const EventRecord& h, std::string_view text, std::span<std::uint8_t> out) {
  const std::size_t n = text_len(text);
  if (out.size() < kEventHeaderSize + n) return 0;
  std::uint8_t* p = out.data();
  p[0] = kEventRecordVersion;
  p[1] = static_cast<std::uint8_t>(h.category);
  put_u16(p + 2, h.code);
  put_u32(p + 4, static_cast<std::uint32_t>(h.line));
  put_u32(p + 8, static_cast<std::uint32_t>(h.a));
  put_u32(p + 12, static_cast<std::uint32_t>(h.b));
  put_u64(p + 16, h.value);
  if (n > 0) std::memcpy(p + kEventHeaderSize, text.data(), n);
  return kEventHeaderSize + n;
}

std::optional<EventRecord> decode_event(std::span<const std::uint8_t> b, std::string* error) {
  auto fail = [&](const char* why) -> std::optional<EventRecord> {
    if (error) *error = why;
    return std::nullopt;
  };
  if (b.empty()) return fail("empty event record");
  if (b[0] != kEventRecordVersion) return fail("unsupported event record version");
  if (b.size() < kEventHeaderSize) return fail("event record shorter than its 24-octet header");
  EventRecord e;
  e.category = static_cast<EventCategory>(b[1]);
  e.code = static_cast<std::uint16_t>(get_le(b.data() + 2, 2));
  e.line = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_le(b.data() + 4, 4)));
  e.a = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_le(b.data() + 8, 4)));
  e.b = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_le(b.data() + 12, 4)));
  e.value = get_le(b.data() + 16, 8);
  e.text.assign(reinterpret_cast<const char*>(b.data() + kEventHeaderSize),
                b.size() - kEventHeaderSize);
  return e;
}

}  // namespace pbvbus::captures
