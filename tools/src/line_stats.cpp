#include "pbvbus/tools/line_stats.hpp"

#include "pbvbus/bus/device.hpp"
#include "pbvbus/captures/pcapng_writer.hpp"

namespace pbvbus::tools {

namespace {
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

void LineStats::on_frame(const bus::TapFrame& f) {
  ++frames;
  octets += f.bytes.size();
  const int ti = f.bytes.empty() ? -1 : type_index(f.bytes[0]);
  if (ti < 0)
    ++garbage;
  else
    ++by_type[static_cast<std::size_t>(ti)];
  if (f.flags != 0) {
    ++m_error_frames;
    if (f.flags & bus::kRxCollision) ++collisions;
    if (f.flags & (bus::kRxParity | bus::kRxFraming)) ++parity;
    if (f.flags & bus::kRxPartial) ++partial;
    if (f.flags & bus::kRxBabble) ++babble;
    return;
  }
  fdl::Telegram t;
  const fdl::DecodeError e = fdl::decode(f.bytes, t);
  if (e != fdl::DecodeError::None) {
    ++m_error_frames;
    if (e == fdl::DecodeError::BadFcs)
      ++bad_fcs;
    else
      ++malformed;
    return;
  }
  if (t.type == fdl::FrameType::SD4) {
    ++tokens_by_sa[t.sa & 0x7F];
  } else if (t.is_request()) {
    ++requests_by_fn[static_cast<std::size_t>(fdl::fc_request_fn(t.fc))];
  } else if (t.type != fdl::FrameType::SC) {
    ++responses;
  }
}

void LineStats::on_line_event(const bus::LineEvent& e) {
  faults.push_back({e.time, captures::describe_line_event(e)});
}

}  // namespace pbvbus::tools
