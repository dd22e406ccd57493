// Redundant execution and comparison on the two CPUs of an H-system
// (devices/h_redundant_execution.hpp).
#include "pbvbus/s7h/h_redundant_execution.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace pbvbus::devices {

RedundantExecution::RedundantExecution(const ProgramSpec& spec, std::size_t pii_bytes,
                                       std::size_t piq_bytes, std::size_t memory_bytes)
    : program_(spec, pii_bytes, piq_bytes),
      images_{ProcessImage(pii_bytes, piq_bytes, std::max(program_.memory_size(), memory_bytes)),
              ProcessImage(pii_bytes, piq_bytes, std::max(program_.memory_size(), memory_bytes))} {}

bool RedundantExecution::set_inputs(std::span<const std::uint8_t> pii_from_io) {
  if (pii_from_io.size() != program_.pii_size()) return false;
  for (auto& img : images_) std::copy(pii_from_io.begin(), pii_from_io.end(), img.pii().begin());
  return true;
}

ScanResult RedundantExecution::scan(bus::Ticks now, std::array<bool, 2> running, int master) {
  ScanResult r;
  if (now < 0) return r;
  for (int rack = 0; rack < 2; ++rack) {
    auto& ev = run_events_[static_cast<std::size_t>(rack)];
    ev.clear();
    if (!running[static_cast<std::size_t>(rack)]) continue;
    program_.scan(images_[static_cast<std::size_t>(rack)], now, ev);
    r.ran[static_cast<std::size_t>(rack)] = true;
    ++scans_[static_cast<std::size_t>(rack)];
    for (auto& e : ev) e.rack = rack;
  }
  if (!r.ran[0] && !r.ran[1]) return r;
  last_start_ = now;

  if (r.ran[0] && r.ran[1]) {
    r.compared = true;
    static constexpr Area kCompared[] = {Area::Piq, Area::Memory};
    r.comparison_error = first_difference(images_[0], images_[1], kCompared);
    const auto& e0 = run_events_[0];
    const auto& e1 = run_events_[1];
    r.sync_error = !std::equal(e0.begin(), e0.end(), e1.begin(), e1.end(),
                               [](const ProgramEvent& a, const ProgramEvent& b) {
                                 ProgramEvent x = a;
                                 x.rack = b.rack;  // the same event on either CPU
                                 return x == b;
                               });
  }
  int reporter = valid_rack(master) && r.ran[static_cast<std::size_t>(master)] ? master
                 : r.ran[0]                                                     ? 0
                                                                                : 1;
  r.events = run_events_[static_cast<std::size_t>(reporter)];
  events_.insert(events_.end(), r.events.begin(), r.events.end());
  if (valid_rack(master) && r.ran[static_cast<std::size_t>(master)]) r.output_rack = master;
  return r;
}

bool RedundantExecution::copy_state(int from, int to) {
  if (!valid_rack(from) || !valid_rack(to)) return false;
  if (from != to) images_[static_cast<std::size_t>(to)] = images_[static_cast<std::size_t>(from)];
  return true;
}

bool RedundantExecution::inject_divergence(int rack, Area area, std::uint32_t offset,
                                           std::uint8_t xor_mask) {
  if (!valid_rack(rack)) return false;
  auto bytes = images_[static_cast<std::size_t>(rack)].area(area);
  if (offset >= bytes.size()) return false;
  bytes[offset] = static_cast<std::uint8_t>(bytes[offset] ^ xor_mask);
  return true;
}

const ProcessImage& RedundantExecution::image(int rack) const {
  if (!valid_rack(rack)) throw std::out_of_range("rack " + std::to_string(rack) + " (0 or 1)");
  return images_[static_cast<std::size_t>(rack)];
}

ProcessImage& RedundantExecution::image(int rack) {
  if (!valid_rack(rack)) throw std::out_of_range("rack " + std::to_string(rack) + " (0 or 1)");
  return images_[static_cast<std::size_t>(rack)];
}

std::uint64_t RedundantExecution::scans(int rack) const {
  return valid_rack(rack) ? scans_[static_cast<std::size_t>(rack)] : 0;
}

bus::Ticks RedundantExecution::next_scan(bus::Ticks now) const {
  if (!last_start_) return now;
  const bus::Ticks due = *last_start_ > std::numeric_limits<bus::Ticks>::max() - scan_time()
                             ? std::numeric_limits<bus::Ticks>::max()
                             : *last_start_ + scan_time();
  return std::max(due, now);
}

}  // namespace pbvbus::devices
