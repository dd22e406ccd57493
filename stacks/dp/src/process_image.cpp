// Consistent process images (design.md "Consistent data", protocol-facts.md §F).
#include "pbvbus/dp/process_image.hpp"

#include <algorithm>
#include <thread>

namespace pbvbus::dp {

ConsistentBuffer::ConsistentBuffer(std::size_t len)
    : m_len(len), m_words((len + 7) / 8),
      m_data(std::make_unique<std::atomic<std::uint64_t>[]>(m_words == 0 ? 1 : m_words)) {
  for (std::size_t i = 0; i < (m_words == 0 ? 1 : m_words); ++i)
    m_data[i].store(0, std::memory_order_relaxed);
}

std::uint32_t ConsistentBuffer::begin_write() {
  std::uint32_t s = m_seq.load(std::memory_order_relaxed);
  unsigned spins = 0;
  for (;;) {
    if ((s & 1u) == 0 &&
        m_seq.compare_exchange_weak(s, s + 1, std::memory_order_acquire, std::memory_order_relaxed))
      break;
    // Another writer is in the middle of a copy of at most 244 bytes; let it finish.
    if (++spins > 64) std::this_thread::yield();
    s = m_seq.load(std::memory_order_relaxed);
  }
  return s;
}

void ConsistentBuffer::end_write(std::uint32_t s) { m_seq.store(s + 2, std::memory_order_release); }

bool ConsistentBuffer::write(std::span<const std::uint8_t> data) {
  if (data.size() != m_len) return false;
  const std::uint32_t s = begin_write();
  for (std::size_t w = 0; w < m_words; ++w) {
    std::uint64_t v = 0;
    const std::size_t base = w * 8;
    const std::size_t n = m_len - base < 8 ? m_len - base : 8;
    for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(data[base + i]) << (8 * i);
    m_data[w].store(v, std::memory_order_release);
  }
  end_write(s);
  return true;
}

void ConsistentBuffer::fill(std::uint8_t value) {
  const std::uint32_t s = begin_write();
  for (std::size_t w = 0; w < m_words; ++w) {
    const std::size_t n = m_len - w * 8 < 8 ? m_len - w * 8 : 8;
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(value) << (8 * i);
    m_data[w].store(v, std::memory_order_release);
  }
  end_write(s);
}

bool ConsistentBuffer::read(std::span<std::uint8_t> out) const {
  if (out.size() != m_len) return false;
  unsigned spins = 0;
  while (!try_read(out, 1))
    if (++spins > 64) std::this_thread::yield();
  return true;
}

bool ConsistentBuffer::try_read(std::span<std::uint8_t> out, int attempts) const {
  if (out.size() != m_len) return false;
  for (int a = 0; a < attempts; ++a) {
    const std::uint32_t s1 = m_seq.load(std::memory_order_acquire);
    if ((s1 & 1u) == 0) {
      for (std::size_t w = 0; w < m_words; ++w) {
        const std::uint64_t v = m_data[w].load(std::memory_order_acquire);
        const std::size_t base = w * 8;
        const std::size_t n = m_len - base < 8 ? m_len - base : 8;
        for (std::size_t i = 0; i < n; ++i) out[base + i] = static_cast<std::uint8_t>(v >> (8 * i));
      }
      if (m_seq.load(std::memory_order_relaxed) == s1) return true;
    }
  }
  return false;
}

ProcessImage::ProcessImage(const SlaveLayout& layout)
    : m_layout(layout.modules), m_last_inputs(layout.inputs, 0) {
  for (const auto& m : m_layout) {
    m_in.push_back(std::make_unique<ConsistentBuffer>(m.in_len));
    m_out.push_back(std::make_unique<ConsistentBuffer>(m.out_len));
  }
}

void ProcessImage::read_all_inputs(std::span<std::uint8_t> telegram) {
  for (std::size_t m = 0; m < m_layout.size(); ++m) {
    const auto off = static_cast<std::ptrdiff_t>(m_layout[m].in_offset);
    const std::size_t len = m_layout[m].in_len;
    const auto dst = telegram.subspan(m_layout[m].in_offset, len);
    if (m_in[m]->try_read(dst, 4))
      std::copy(dst.begin(), dst.end(), m_last_inputs.begin() + off);
    else
      std::copy_n(m_last_inputs.begin() + off, len, dst.begin());
  }
}

void ProcessImage::write_all_outputs(std::span<const std::uint8_t> telegram) {
  for (std::size_t m = 0; m < m_layout.size(); ++m)
    m_out[m]->write(telegram.subspan(m_layout[m].out_offset, m_layout[m].out_len));
}

void ProcessImage::clear_outputs() {
  for (auto& b : m_out) b->fill(0);
}

}  // namespace pbvbus::dp
