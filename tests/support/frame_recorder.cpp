#include "frame_recorder.hpp"

#include <stdexcept>

#include "hex.hpp"
#include "pbvbus/bus/line.hpp"

namespace pbvbus::test {

void FrameRecorder::on_frame(const bus::TapFrame& f) {
  m_frames.push_back(Frame{f.line, {f.bytes.begin(), f.bytes.end()}, f.start, f.end, f.flags, f.sender,
                           f.sent_len});
}

void FrameRecorder::on_line_event(const bus::LineEvent& e) { m_events.push_back(e); }

std::string FrameRecorder::hex(std::size_t i) const { return to_hex(frame(i).bytes); }

std::vector<std::string> FrameRecorder::hex_all() const {
  std::vector<std::string> out;
  out.reserve(m_frames.size());
  for (const auto& f : m_frames) out.push_back(to_hex(f.bytes));
  return out;
}

namespace {
bus::Ticks bit_of(const FrameRecorder::Frame& f) {
  if (f.line == nullptr) throw std::logic_error("FrameRecorder: frame without a line");
  return f.line->bit_ticks();
}
}  // namespace

std::int64_t FrameRecorder::gap_bits(std::size_t i) const {
  const Frame& f = frame(i);
  const bus::Ticks bit = bit_of(f);
  if (i == 0) return f.start / bit;
  const Frame& p = frame(i - 1);
  if (p.line != f.line) throw std::logic_error("FrameRecorder::gap_bits: frames from different lines");
  return (f.start - p.end) / bit;
}

std::int64_t FrameRecorder::start_bits(std::size_t i) const { return frame(i).start / bit_of(frame(i)); }
std::int64_t FrameRecorder::end_bits(std::size_t i) const { return frame(i).end / bit_of(frame(i)); }

}  // namespace pbvbus::test
