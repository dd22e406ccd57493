// TPKT framing and reassembly (RFC 1006; tpkt.hpp).
#include "pbvbus/s7/tpkt.hpp"

#include <algorithm>

#include "be.hpp"

namespace pbvbus::s7 {

Error append_tpkt(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> payload) {
  const std::size_t total = payload.size() + kTpktHeaderLength;
  if (total < kTpktMinLength) return Error::TpktLengthTooSmall;
  if (total > kTpktMaxLength) return Error::TpktPayloadTooLarge;
  out.push_back(kTpktVersion);
  out.push_back(0);
  be::put_u16(out, static_cast<std::uint16_t>(total));
  be::append(out, payload);
  return Error::None;
}

TpktReassembler::TpktReassembler(std::size_t max_length) {
  set_max_length(max_length);
}

void TpktReassembler::set_max_length(std::size_t max_length) {
  max_ = std::clamp(max_length, kTpktMinLength, kTpktMaxLength);
}

void TpktReassembler::fail(Error e, std::size_t at) {
  error_ = e;
  error_offset_ = at;
  buf_.clear();
  buf_.shrink_to_fit();
  expected_ = 0;
}

std::size_t TpktReassembler::feed(std::span<const std::uint8_t> in) {
  std::size_t used = 0;
  while (!ready_ && error_ == Error::None && used < in.size()) {
    if (buf_.size() < kTpktHeaderLength) {
      const std::uint8_t b = in[used];
      const std::size_t at = stream_offset_ + used;
      ++used;
      if (buf_.empty() && b != kTpktVersion) {
        fail(Error::TpktBadVersion, at);
        break;
      }
      buf_.push_back(b);
      if (buf_.size() == kTpktHeaderLength) {
        expected_ = be::u16(buf_, 2);
        if (expected_ < kTpktMinLength) {
          fail(Error::TpktLengthTooSmall, at - 1);
          break;
        }
        if (expected_ > max_) {
          fail(Error::TpktLengthTooLarge, at - 1);
          break;
        }
        buf_.reserve(expected_);
      }
      continue;
    }
    const std::size_t take = std::min(expected_ - buf_.size(), in.size() - used);
    buf_.insert(buf_.end(), in.begin() + static_cast<std::ptrdiff_t>(used),
                in.begin() + static_cast<std::ptrdiff_t>(used + take));
    used += take;
    if (buf_.size() == expected_) ready_ = true;
  }
  stream_offset_ += used;
  return used;
}

std::span<const std::uint8_t> TpktReassembler::tpkt() const {
  if (!ready_) return {};
  return buf_;
}

std::span<const std::uint8_t> TpktReassembler::payload() const {
  if (!ready_) return {};
  return std::span<const std::uint8_t>(buf_).subspan(kTpktHeaderLength);
}

void TpktReassembler::pop() {
  if (!ready_) return;
  ready_ = false;
  buf_.clear();
  expected_ = 0;
}

}  // namespace pbvbus::s7
