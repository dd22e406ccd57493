#include "pbvbus/simulation/line_stats.hpp"

#include <cstring>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/line.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"

namespace pbvbus::tools {

namespace {
/// A 64-bit hash of a telegram, never 0 (0 marks "no request"). Eight octets per multiply (an
/// FNV-1a over single octets was a visible part of the per-frame cost); the length goes in too,
/// so a telegram and its prefix padded with zeros differ.
std::uint64_t hash_of(std::span<const std::uint8_t> b) {
  std::uint64_t h = 1469598103934665603ULL ^ (b.size() * 0x9E3779B97F4A7C15ULL);
  std::size_t i = 0;
  for (; i + 8 <= b.size(); i += 8) {
    std::uint64_t w;
    std::memcpy(&w, b.data() + i, 8);
    h = (h ^ w) * 0xBF58476D1CE4E5B9ULL;
    h ^= h >> 29;
  }
  if (i < b.size()) {
    std::uint64_t w = 0;
    for (std::size_t k = i; k < b.size(); ++k) w = (w << 8) | b[k];
    h = (h ^ w) * 0x94D049BB133111EBULL;
    h ^= h >> 29;
  }
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 32;
  return h == 0 ? 1 : h;
}

int type_index(std::uint8_t sd) {
  switch (sd) {
    case fdl::kSD1: return 0;
    case fdl::kSD2: return 1;
    case fdl::kSD3: return 2;
    case fdl::kSD4: return 3;
    case fdl::kSC: return 4;
    default: return -1;
  }
}
}  // namespace

void LineStats::mark(std::uint8_t addr, fdl::StationType t, bool upgrade_only) {
  if (addr >= heard.size()) return;
  const auto v = static_cast<std::int8_t>(t);
  if (!upgrade_only || heard[addr] < v) heard[addr] = v;
}

void LineStats::settle(const bus::TapFrame& f, const fdl::Telegram* t) {
  if (!m_awaiting) return;
  m_awaiting = false;
  if (f.flags != 0 || t == nullptr) return;  // a damaged frame decides nothing
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

void LineStats::on_frame(const bus::TapFrame& f) {
  const bus::Ticks last_end = m_last_end;
  m_last_end = f.end;
  ++frames;
  octets += f.bytes.size();
  const int ti = f.bytes.empty() ? -1 : type_index(f.bytes[0]);
  if (ti < 0)
    ++garbage;
  else
    ++by_type[static_cast<std::size_t>(ti)];
  if (f.flags != 0) {
    settle(f, nullptr);
    ++m_error_frames;
    if (f.flags & bus::kRxCollision) ++collisions;
    if (f.flags & (bus::kRxParity | bus::kRxFraming)) ++parity;
    if (f.flags & bus::kRxPartial) ++partial;
    if (f.flags & bus::kRxBabble) ++babble;
    return;
  }
  fdl::DecodedFrame scratch;
  const fdl::DecodedFrame& d = fdl::decode_once(f, scratch);
  const fdl::DecodeError e = d.error;
  const fdl::Telegram& t = d.telegram;
  if (e != fdl::DecodeError::None) {
    settle(f, nullptr);
    ++m_error_frames;
    if (e == fdl::DecodeError::BadFcs)
      ++bad_fcs;
    else
      ++malformed;
    return;
  }
  settle(f, &t);
  const bool sync_needed = t.type == fdl::FrameType::SD4 || t.is_request();
  if (sync_needed && last_end >= 0 && f.line != nullptr &&
      f.start - last_end < 33 * f.line->bit_ticks())
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
