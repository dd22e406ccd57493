#include "pbvbus/simulation/line_stats.hpp"

#include <algorithm>
#include <cstring>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"

namespace pbvbus::tools {

namespace {
/// A 64-bit hash of a telegram, never 0 (0 marks "no request"). Eight octets per multiply, the
/// last eight (overlapping the ones before) for the rest, and the length mixed in first; every
/// step is a bijection of the state for a given word, so two telegrams of the same length that
/// differ in one word never collide. A mixing of the state at the end only. (An FNV-1a over
/// single octets, then a mix after every word, were visible parts of the per-frame cost.)
std::uint64_t hash_of(std::span<const std::uint8_t> b) {
  const std::size_t n = b.size();
  std::uint64_t h = 1469598103934665603ULL ^ (n * 0x9E3779B97F4A7C15ULL);
  std::uint64_t w = 0;
  if (n >= 8) {
    const std::uint8_t* p = b.data();
    for (std::size_t i = 0; i + 8 < n; i += 8) {
      std::memcpy(&w, p + i, 8);
      h = (h ^ w) * 0xBF58476D1CE4E5B9ULL;
    }
    std::memcpy(&w, p + n - 8, 8);
  } else {
    for (std::size_t k = 0; k < n; ++k) w = (w << 8) | b[k];
  }
  h = (h ^ w) * 0x94D049BB133111EBULL;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 32;
  return h == 0 ? 1 : h;
}

/// by_type index of a first octet (-1: not a start delimiter), one load instead of a switch.
constexpr std::array<std::int8_t, 256> make_type_index() {
  std::array<std::int8_t, 256> a{};
  for (auto& x : a) x = -1;
  a[fdl::kSD1] = 0;
  a[fdl::kSD2] = 1;
  a[fdl::kSD3] = 2;
  a[fdl::kSD4] = 3;
  a[fdl::kSC] = 4;
  return a;
}
constexpr std::array<std::int8_t, 256> kTypeIndex = make_type_index();
}  // namespace

void LineStats::mark(std::uint8_t addr, fdl::StationType t, bool upgrade_only) {
  if (addr >= heard.size()) return;
  const auto v = static_cast<std::int8_t>(t);
  if (!upgrade_only || heard[addr] < v) heard[addr] = v;
}

void LineStats::settle(const fdl::Telegram& frame) {
  m_awaiting = false;
  const fdl::Telegram* t = &frame;
  if (m_await_token) {
    if (t->type != fdl::FrameType::SC && t->sa == m_await_da) return;  // the receiver is active
  } else if (t->type == fdl::FrameType::SC) {
    mark(m_await_da, fdl::StationType::Slave, true);
    return;
  } else if (t->type != fdl::FrameType::SD4 && !t->is_request() && t->sa == m_await_da) {
    return;  // the response: marked by on_frame
  }
  heard[m_await_da] = -1;
  if (m_await_counts) ++no_response;
}

bus::Ticks LineStats::tsyn_of(const bus::Line& line) {
  if (&line != m_tsyn_line || line.baud() != m_tsyn_baud) {
    m_tsyn_line = &line;
    m_tsyn_baud = line.baud();
    m_tsyn = 33 * line.bit_ticks();
  }
  return m_tsyn;
}

void LineStats::on_frame(const bus::TapFrame& f) {
  const bus::Ticks last_end = m_last_end;
  m_last_end = f.end;
  ++frames;
  octets += f.bytes.size();
  const int ti = f.bytes.empty() ? -1 : kTypeIndex[f.bytes[0]];
  if (ti < 0)
    ++garbage;
  else
    ++by_type[static_cast<std::size_t>(ti)];
  if (f.flags != 0) {
    m_awaiting = false;  // a damaged frame decides nothing
    ++m_error_frames;
    if (f.flags & bus::kRxCollision) ++collisions;
    if (f.flags & (bus::kRxParity | bus::kRxFraming)) ++parity;
    if (f.flags & bus::kRxPartial) ++partial;
    if (f.flags & bus::kRxBabble) ++babble;
    return;
  }
  const fdl::DecodedFrame& d = fdl::decode_once(f, m_scratch);
  const fdl::DecodeError e = d.error;
  const fdl::Telegram& t = d.telegram;
  if (e != fdl::DecodeError::None) {
    m_awaiting = false;  // a damaged frame decides nothing
    ++m_error_frames;
    if (e == fdl::DecodeError::BadFcs)
      ++bad_fcs;
    else
      ++malformed;
    return;
  }
  if (m_awaiting) settle(t);
  const bool sync_needed = t.type == fdl::FrameType::SD4 || t.is_request();
  if (sync_needed && last_end >= 0 && f.line != nullptr && f.start - last_end < tsyn_of(*f.line))
    ++short_idle;
  if (t.type == fdl::FrameType::SD4) {
    ++tokens_by_sa[t.sa & 0x7F];
    mark(t.sa, fdl::StationType::MasterInRing, false);
    if (t.da != t.sa && t.da < 127) {
      m_awaiting = true;
      m_await_token = true;
      m_await_counts = false;
      m_await_da = t.da;
    }
  } else if (t.is_request()) {
    const fdl::RequestFn fn = fdl::fc_request_fn(t.fc);
    ++requests_by_fn[static_cast<std::size_t>(fn)];
    mark(t.sa, fdl::StationType::MasterInRing, false);
    // A request to the sender itself is an equidistance pause frame (docs/dp-equidistance.md):
    // nobody answers it, and the next one is no repeat.
    if (fdl::fn_expects_reply(fn) && t.da != fdl::kBroadcast && t.da != t.sa) {
      const std::uint64_t h = hash_of(f.bytes);
      if (m_last_request[t.sa] == h) ++repeats;
      m_last_request[t.sa] = h;
      m_awaiting = true;
      m_await_token = false;
      m_await_counts = fn != fdl::RequestFn::FdlStatus;
      m_await_da = t.da;
    }
  } else if (t.type != fdl::FrameType::SC) {
    ++responses;
    mark(t.sa, fdl::fc_station_type(t.fc), false);
  }
}

void LineStats::on_line_event(const bus::LineEvent& e) {
  faults.push_back({e.time, captures::describe_line_event(e)});
}

}  // namespace pbvbus::tools
