#include "pbvbus/slaves/module_records.hpp"

#include <algorithm>

namespace pbvbus::devices {
namespace {
std::uint16_t key(std::uint8_t slot, std::uint8_t index) {
  return static_cast<std::uint16_t>((slot << 8) | index);
}
}  // namespace

void ModuleRecords::install(dp::SlaveApplication& app) {
  {
    std::lock_guard lk(m_mu);
    m_apps.push_back(&app);
  }
  app.on_write_any([this](const dp::RecordCall& c, std::span<const std::uint8_t> d) {
    return write(c, d);
  });
}

void ModuleRecords::set_pulled(std::size_t module, bool pulled) {
  std::lock_guard lk(m_mu);
  if (module >= m_pulled.size()) return;
  m_pulled[module] = pulled;
  if (!pulled) return;
  const auto slot = static_cast<std::uint8_t>(module + 1);
  std::erase_if(m_records, [&](const auto& kv) { return (kv.first >> 8) == slot; });
}

std::optional<std::vector<std::uint8_t>> ModuleRecords::record(std::size_t module,
                                                               std::uint8_t index) const {
  std::lock_guard lk(m_mu);
  const auto it = m_records.find(key(static_cast<std::uint8_t>(module + 1), index));
  if (module >= m_pulled.size() || it == m_records.end()) return std::nullopt;
  return it->second;
}

std::uint64_t ModuleRecords::writes_accepted() const {
  std::lock_guard lk(m_mu);
  return m_writes;
}

dp::RecordResult ModuleRecords::write(const dp::RecordCall& c, std::span<const std::uint8_t> data) {
  std::vector<dp::SlaveApplication*> apps;
  bool fresh = false;
  {
    std::lock_guard lk(m_mu);
    // Slot 0 (the interface module) and the reserved index 255 keep no records.
    if (c.slot == 0 || c.index == 0xFF) return dp::RecordResult::fail(dp::dpv1_err::kInvalidIndex);
    if (c.slot > m_pulled.size() || m_pulled[c.slot - 1u])
      return dp::RecordResult::fail(dp::dpv1_err::kInvalidSlot);
    if (data.empty() || data.size() > dp::kMaxRecordData)
      return dp::RecordResult::fail(dp::dpv1_err::kWriteLengthError);
    auto [it, inserted] = m_records.insert_or_assign(key(c.slot, c.index),
                                                     std::vector<std::uint8_t>(data.begin(), data.end()));
    (void)it;
    fresh = inserted;
    ++m_writes;
    apps = m_apps;
  }
  // A Read of the record from now on (outside our lock: on_read takes the application's).
  if (fresh)
    for (dp::SlaveApplication* a : apps)
      a->on_read(c.slot, c.index, [this](const dp::RecordCall& rc, std::span<std::uint8_t> out) {
        return read(rc, out);
      });
  return dp::RecordResult::ok();
}

dp::RecordResult ModuleRecords::read(const dp::RecordCall& c, std::span<std::uint8_t> out) const {
  std::lock_guard lk(m_mu);
  if (c.slot == 0 || c.slot > m_pulled.size() || m_pulled[c.slot - 1u])
    return dp::RecordResult::fail(dp::dpv1_err::kInvalidSlot);
  const auto it = m_records.find(key(c.slot, c.index));
  if (it == m_records.end()) return dp::RecordResult::fail(dp::dpv1_err::kInvalidIndex);
  const std::size_t n = std::min(out.size(), it->second.size());
  std::copy_n(it->second.begin(), n, out.begin());
  return dp::RecordResult::ok(n);
}

}  // namespace pbvbus::devices
