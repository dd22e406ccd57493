#pragma once
// A frame from the line decoded once, whoever reads it (docs/architecture.md "Decode once per
// frame").
//
// decode_once() returns decode()'s result for a frame's octets. For a frame that comes from a
// bus::Line (RxFrame::memo / TapFrame::memo set), the first reader decodes it into the
// transmission's bus::FrameMemo and every later reader of the same view (the other receivers,
// the statistics, the captures) gets that same result without decoding again. Without a memo
// (a frame made by hand in a test, a pty's byte stream) it decodes into the caller's scratch.
// Either way the result is exactly what decode() gives for those octets.
//
// The returned reference, and the telegram's `data` span into the frame's octets, are valid
// only while the frame is (during the on_frame() call).

#include <new>
#include <span>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/frame_memo.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::fdl {

struct DecodedFrame {
  DecodeError error = DecodeError::Empty;  ///< DecodeError::None: `telegram` holds the frame
  Telegram telegram;
  bool ok() const { return error == DecodeError::None; }
};

/// The key of the FDL layer's entries in a bus::FrameMemo (its address is what counts).
inline constexpr char kDecodedFrameMemoOwner = 0;

/// Decodes `bytes` and stores the result in `memo` (nullptr: in `scratch`).
const DecodedFrame& decode_into(std::span<const std::uint8_t> bytes, bus::FrameMemo* memo,
                                DecodedFrame& scratch);

/// decode() of `bytes`, taken from `memo` if a reader of the same view decoded it already.
inline const DecodedFrame& decode_once(std::span<const std::uint8_t> bytes, bus::FrameMemo* memo,
                                       DecodedFrame& scratch) {
  if (memo != nullptr)
    if (const void* p = memo->find(&kDecodedFrameMemoOwner, bytes))
      return *std::launder(static_cast<const DecodedFrame*>(p));
  return decode_into(bytes, memo, scratch);
}
inline const DecodedFrame& decode_once(const bus::RxFrame& f, DecodedFrame& scratch) {
  return decode_once(f.bytes, f.memo, scratch);
}
inline const DecodedFrame& decode_once(const bus::TapFrame& f, DecodedFrame& scratch) {
  return decode_once(f.bytes, f.memo, scratch);
}

}  // namespace pbvbus::fdl
