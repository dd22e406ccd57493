// CpuMemory and the owner's byte/bit helpers (cpu_memory.hpp).
#include "pbvbus/s7cpu/cpu_memory.hpp"

namespace pbvbus::s7cpu {

CpuMemory::CpuMemory(const CpuMemorySizes& sizes)
    : sizes_(sizes),
      inputs_(sizes.inputs),
      outputs_(sizes.outputs),
      flags_(sizes.flags),
      counters_(sizes.counters),
      timers_(sizes.timers),
      inputs_view_(inputs_),
      outputs_view_(outputs_),
      flags_view_(flags_),
      counters_view_(counters_),
      timers_view_(timers_) {}

void CpuMemory::create_db(std::uint16_t number, std::size_t size) {
  Db& d = dbs_[number];
  d.owned.assign(size, 0);
  d.view = d.owned;
}

void CpuMemory::bind(Area a, std::span<std::uint8_t> storage) {
  switch (a) {
    case Area::Inputs:
      inputs_view_ = storage;
      sizes_.inputs = storage.size();
      return;
    case Area::Outputs:
      outputs_view_ = storage;
      sizes_.outputs = storage.size();
      return;
    case Area::Flags:
      break;
  }
  flags_view_ = storage;
  sizes_.flags = storage.size();
}

void CpuMemory::bind_counters(std::span<std::uint16_t> storage) {
  counters_view_ = storage;
  sizes_.counters = storage.size();
}

void CpuMemory::bind_timers(std::span<std::uint16_t> storage) {
  timers_view_ = storage;
  sizes_.timers = storage.size();
}

void CpuMemory::bind_db(std::uint16_t number, std::span<std::uint8_t> storage) {
  Db& d = dbs_[number];
  d.owned.clear();
  d.owned.shrink_to_fit();
  d.view = storage;
}

void CpuMemory::clear_dbs() { dbs_.clear(); }

bool CpuMemory::delete_db(std::uint16_t number) {
  return dbs_.erase(number) != 0;
}

bool CpuMemory::has_db(std::uint16_t number) const {
  return dbs_.contains(number);
}

std::optional<std::span<std::uint8_t>> CpuMemory::db(std::uint16_t number) {
  const auto it = dbs_.find(number);
  if (it == dbs_.end()) return std::nullopt;
  return it->second.view;
}

std::optional<std::span<const std::uint8_t>> CpuMemory::db(std::uint16_t number) const {
  const auto it = dbs_.find(number);
  if (it == dbs_.end()) return std::nullopt;
  return std::span<const std::uint8_t>(it->second.view);
}

std::span<std::uint8_t> CpuMemory::area(Area a) {
  switch (a) {
    case Area::Inputs:
      return inputs_view_;
    case Area::Outputs:
      return outputs_view_;
    case Area::Flags:
      break;
  }
  return flags_view_;
}

std::span<const std::uint8_t> CpuMemory::area(Area a) const {
  return const_cast<CpuMemory*>(this)->area(a);
}

std::optional<bool> get_bit(std::span<const std::uint8_t> bytes, std::size_t byte,
                            unsigned bit) {
  if (byte >= bytes.size() || bit > 7) return std::nullopt;
  return ((bytes[byte] >> bit) & 1U) != 0;
}

bool set_bit(std::span<std::uint8_t> bytes, std::size_t byte, unsigned bit, bool value) {
  if (byte >= bytes.size() || bit > 7) return false;
  const auto mask = static_cast<std::uint8_t>(1U << bit);
  bytes[byte] = static_cast<std::uint8_t>(value ? (bytes[byte] | mask) : (bytes[byte] & ~mask));
  return true;
}

std::optional<std::uint8_t> get_byte(std::span<const std::uint8_t> bytes, std::size_t byte) {
  if (byte >= bytes.size()) return std::nullopt;
  return bytes[byte];
}

bool set_byte(std::span<std::uint8_t> bytes, std::size_t byte, std::uint8_t value) {
  if (byte >= bytes.size()) return false;
  bytes[byte] = value;
  return true;
}

std::optional<std::uint16_t> get_word(std::span<const std::uint8_t> bytes, std::size_t byte) {
  if (byte >= bytes.size() || bytes.size() - byte < 2) return std::nullopt;
  return static_cast<std::uint16_t>((bytes[byte] << 8) | bytes[byte + 1]);
}

bool set_word(std::span<std::uint8_t> bytes, std::size_t byte, std::uint16_t value) {
  if (byte >= bytes.size() || bytes.size() - byte < 2) return false;
  bytes[byte] = static_cast<std::uint8_t>(value >> 8);
  bytes[byte + 1] = static_cast<std::uint8_t>(value);
  return true;
}

std::optional<std::uint32_t> get_dword(std::span<const std::uint8_t> bytes, std::size_t byte) {
  if (byte >= bytes.size() || bytes.size() - byte < 4) return std::nullopt;
  return (static_cast<std::uint32_t>(bytes[byte]) << 24) |
         (static_cast<std::uint32_t>(bytes[byte + 1]) << 16) |
         (static_cast<std::uint32_t>(bytes[byte + 2]) << 8) | bytes[byte + 3];
}

bool set_dword(std::span<std::uint8_t> bytes, std::size_t byte, std::uint32_t value) {
  if (byte >= bytes.size() || bytes.size() - byte < 4) return false;
  for (std::size_t i = 0; i < 4; ++i) {
    bytes[byte + i] = static_cast<std::uint8_t>(value >> (24 - 8 * i));
  }
  return true;
}

}  // namespace pbvbus::s7cpu
