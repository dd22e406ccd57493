#pragma once
// Splitting a raw byte stream into FDL telegrams (protocol-facts.md §B.1), for serial
// attachments (design.md "Serial PROFIBUS") where a program writes bytes and the line needs
// telegrams.
//
// The bus layer must not depend on the FDL codec, so the tiny length rule is repeated here:
//   SC 0xE5 = 1 octet, SD4 0xDC = 3, SD1 0x10 = 6, SD3 0xA2 = 14,
//   SD2 0x68 = LE + 6 where "68 LE LEr 68" has LE == LEr and 4 <= LE <= 249.
// (Cross-checked against fdl::frame_length by the lead's tests.) Nothing else is validated: FCS
// and end delimiter are the receivers' business, exactly as on a real line, so a program may
// deliberately send a bad telegram.
//
// Resynchronisation: a byte that cannot start a telegram is dropped (and counted); an SD2
// header whose LE/LEr/second SD is wrong drops its first octet and the search goes on from the
// next one.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pbvbus::bus {

/// Total telegram length from its first octets: > 0 the length; 0 more octets are needed to
/// tell; -1 `head` does not start a telegram (its first octet must be dropped).
int telegram_length(std::span<const std::uint8_t> head);

class FrameSplitter {
 public:
  FrameSplitter() { m_buf.reserve(512); }

  /// Appends bytes and calls on_frame(std::span<const std::uint8_t>) for every complete
  /// telegram, in order. Returns the number of telegrams emitted.
  template <class F>
  std::size_t feed(std::span<const std::uint8_t> bytes, F&& on_frame) {
    m_buf.insert(m_buf.end(), bytes.begin(), bytes.end());
    std::size_t n = 0, pos = 0;
    while (pos < m_buf.size()) {
      const int len = telegram_length(std::span(m_buf).subspan(pos));
      if (len < 0) {
        ++m_garbage;
        ++pos;
        continue;
      }
      if (len == 0 || static_cast<std::size_t>(len) > m_buf.size() - pos) break;
      on_frame(std::span<const std::uint8_t>(m_buf.data() + pos, static_cast<std::size_t>(len)));
      pos += static_cast<std::size_t>(len);
      ++n;
    }
    m_buf.erase(m_buf.begin(), m_buf.begin() + static_cast<std::ptrdiff_t>(pos));
    return n;
  }

  /// Octets of an incomplete telegram waiting for the rest.
  std::size_t pending() const { return m_buf.size(); }
  /// Drops an incomplete telegram (counted as garbage), e.g. after a long pause.
  void discard_pending() {
    m_garbage += m_buf.size();
    m_buf.clear();
  }
  /// Octets dropped because they could not start a telegram (or were discarded).
  std::uint64_t garbage() const { return m_garbage; }

 private:
  std::vector<std::uint8_t> m_buf;
  std::uint64_t m_garbage = 0;
};

}  // namespace pbvbus::bus
