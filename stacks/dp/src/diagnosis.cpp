// Slave_Diag layout (protocol-facts.md §D.4, §D.5).
#include "pbvbus/dp/diagnosis.hpp"

#include <algorithm>

namespace pbvbus::dp {

bool StandardDiag::decode(std::span<const std::uint8_t> du, StandardDiag& out) {
  if (du.size() < kStdDiagLen) return false;
  out.status_1 = du[0];
  out.status_2 = du[1];
  out.status_3 = du[2];
  out.master_add = du[3];
  out.ident = static_cast<std::uint16_t>((du[4] << 8) | du[5]);
  return true;
}

void DiagBuilder::set_standard(const StandardDiag& d) {
  const auto b = d.encode();
  std::copy(b.begin(), b.end(), m_buf.begin());
}

bool DiagBuilder::room(std::size_t n) {
  if (m_len + n > m_max) {
    m_overflow = true;
    return false;
  }
  return true;
}

bool DiagBuilder::add_identifier_block(std::span<const std::uint16_t> faulty_modules,
                                       std::size_t module_count) {
  const std::size_t octets = std::min<std::size_t>((module_count + 7) / 8, 62);
  if (octets == 0 || !room(1 + octets)) return false;
  m_buf[m_len] = static_cast<std::uint8_t>(kBlockIdentifier | (octets + 1));
  std::fill_n(m_buf.begin() + static_cast<std::ptrdiff_t>(m_len + 1), octets, 0);
  for (std::uint16_t m : faulty_modules)
    if (m / 8 < octets) m_buf[m_len + 1 + m / 8] |= static_cast<std::uint8_t>(1u << (m % 8));
  m_len += 1 + octets;
  return true;
}

bool DiagBuilder::add_channel(const ChannelDiag& c) {
  if (!room(3)) return false;
  const auto b = c.encode();
  std::copy(b.begin(), b.end(), m_buf.begin() + static_cast<std::ptrdiff_t>(m_len));
  m_len += 3;
  return true;
}

bool DiagBuilder::add_device_block(std::span<const std::uint8_t> data) {
  if (data.empty()) return true;
  if (data.size() > 62 || !room(1 + data.size())) {
    m_overflow = true;
    return false;
  }
  m_buf[m_len] = static_cast<std::uint8_t>(kBlockDevice | (data.size() + 1));
  std::copy(data.begin(), data.end(), m_buf.begin() + static_cast<std::ptrdiff_t>(m_len + 1));
  m_len += 1 + data.size();
  return true;
}

bool DiagBuilder::add_alarm(std::uint8_t type, std::uint8_t slot, std::uint8_t specifier,
                            std::span<const std::uint8_t> data) {
  if (data.size() > 59 || !room(4 + data.size())) {
    m_overflow = true;
    return false;
  }
  m_buf[m_len] = static_cast<std::uint8_t>(kBlockDevice | (data.size() + 4));
  m_buf[m_len + 1] = static_cast<std::uint8_t>(type & 0x7F);
  m_buf[m_len + 2] = slot;
  m_buf[m_len + 3] = specifier;
  std::copy(data.begin(), data.end(), m_buf.begin() + static_cast<std::ptrdiff_t>(m_len + 4));
  m_len += 4 + data.size();
  return true;
}

bool DiagBuilder::add_status(std::uint8_t status_type, std::uint8_t slot, std::uint8_t specifier,
                             std::span<const std::uint8_t> data) {
  if (!add_alarm(0, slot, specifier, data)) return false;
  // Same layout as an alarm PDU; only the type octet differs (bit 7 set = status).
  m_buf[m_len - data.size() - 3] = static_cast<std::uint8_t>(status_type | 0x80);
  return true;
}

bool DiagBuilder::add_module_status(std::span<const ModuleState> states, AlarmSpec spec) {
  std::array<std::uint8_t, 59> data{};
  const std::size_t octets = std::min<std::size_t>((states.size() + 3) / 4, data.size());
  for (std::size_t i = 0; i < states.size() && i / 4 < octets; ++i)
    data[i / 4] |= static_cast<std::uint8_t>(static_cast<std::uint8_t>(states[i]) << (2 * (i % 4)));
  return add_status(kModuleStatus, 0, static_cast<std::uint8_t>(spec), {data.data(), octets});
}

bool split_ext_diag(std::span<const std::uint8_t> ext, std::vector<ExtDiagBlock>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < ext.size()) {
    const std::uint8_t h = ext[i];
    const std::uint8_t kind = h & kBlockTypeMask;
    std::size_t len = 0;
    if (kind == kBlockChannel) {
      len = 3;
    } else if (kind == kBlockDevice || kind == kBlockIdentifier) {
      len = h & kBlockLengthMask;
      if (len < 1) return false;
    } else {
      return false;
    }
    if (ext.size() - i < len) return false;
    out.push_back({kind, ext.subspan(i, len)});
    i += len;
  }
  return true;
}

}  // namespace pbvbus::dp
