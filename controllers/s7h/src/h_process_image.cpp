// Process image of one H-CPU (devices/h_process_image.hpp).
#include "pbvbus/s7h/h_process_image.hpp"

#include <algorithm>
#include <stdexcept>

namespace pbvbus::devices {

std::string_view area_name(Area a) {
  switch (a) {
    case Area::Pii:
      return "PII";
    case Area::Piq:
      return "PIQ";
    case Area::Memory:
      return "memory";
  }
  return "?";
}

std::vector<std::string> validate_image_sizes(std::size_t pii_bytes, std::size_t piq_bytes) {
  std::vector<std::string> out;
  if (pii_bytes > kMaxImageBytes)
    out.push_back("PII size " + std::to_string(pii_bytes) + " bytes exceeds the maximum " +
                  std::to_string(kMaxImageBytes));
  if (piq_bytes > kMaxImageBytes)
    out.push_back("PIQ size " + std::to_string(piq_bytes) + " bytes exceeds the maximum " +
                  std::to_string(kMaxImageBytes));
  return out;
}

namespace {
std::size_t checked_size(std::size_t pii_bytes, std::size_t piq_bytes, std::size_t n) {
  auto errors = validate_image_sizes(pii_bytes, piq_bytes);
  if (!errors.empty()) throw std::invalid_argument(errors.front());
  return n;
}
}  // namespace

ProcessImage::ProcessImage(std::size_t pii_bytes, std::size_t piq_bytes, std::size_t memory_bytes)
    : pii_(checked_size(pii_bytes, piq_bytes, pii_bytes), 0),
      piq_(piq_bytes, 0),
      memory_(memory_bytes, 0) {}

std::span<std::uint8_t> ProcessImage::area(Area a) {
  switch (a) {
    case Area::Pii:
      return pii_;
    case Area::Piq:
      return piq_;
    case Area::Memory:
      return memory_;
  }
  return {};
}

std::span<const std::uint8_t> ProcessImage::area(Area a) const {
  return const_cast<ProcessImage*>(this)->area(a);
}

std::optional<ImageDifference> first_difference(const ProcessImage& a, const ProcessImage& b,
                                                std::span<const Area> areas) {
  for (Area area : areas) {
    auto x = a.area(area);
    auto y = b.area(area);
    const std::size_t common = std::min(x.size(), y.size());
    const auto px =
        std::mismatch(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(common), y.begin()).first;
    const auto off = static_cast<std::size_t>(px - x.begin());
    if (off == common && x.size() == y.size()) continue;
    ImageDifference d;
    d.area = area;
    d.offset = static_cast<std::uint32_t>(off);
    d.value[0] = off < x.size() ? x[off] : 0;
    d.value[1] = off < y.size() ? y[off] : 0;
    return d;
  }
  return std::nullopt;
}

}  // namespace pbvbus::devices
