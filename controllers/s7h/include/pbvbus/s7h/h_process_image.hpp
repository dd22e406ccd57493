#pragma once
// The process image of one H-CPU (docs/h-system.md; seeds-digest.md §5): the
// process-image input table (PII, "IB n"), the process-image output table (PIQ, "QB n") and the
// CPU's memory area that holds every piece of user-program state (counters, pulse phase,
// discrepancy timers: devices/h_program_spec.hpp's decision). docs/h-programs.md has the
// layout and the decisions.
//
// Decisions:
// - PII and PIQ are each at most 16 KB (kMaxImageBytes = 16 384, the largest S7-400 process
//   image). 0 is allowed (a program of counters needs no PII). A bigger size throws
//   std::invalid_argument at construction; validate_image_sizes() gives the same message
//   without throwing.
// - The memory area's size is the program's (Program::memory_size()); it starts all zero,
//   which every network reads as "not started yet".
// - Equality compares all three areas byte by byte; the redundant comparison (digest §5: RAM and
//   output image) is done by RedundantExecution on PIQ and memory only.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pbvbus::devices {

/// The three areas of a CPU's image.
enum class Area : std::uint8_t {
  Pii,     ///< process-image input table (I)
  Piq,     ///< process-image output table (Q)
  Memory,  ///< program state (the CPU's work memory as far as the program uses it)
};

std::string_view area_name(Area a);  ///< "PII", "PIQ", "memory"

/// Largest PII or PIQ, bytes.
inline constexpr std::size_t kMaxImageBytes = 16 * 1024;

/// Messages for a PII/PIQ size above kMaxImageBytes (empty when both are fine).
std::vector<std::string> validate_image_sizes(std::size_t pii_bytes, std::size_t piq_bytes);

class ProcessImage {
 public:
  /// Throws std::invalid_argument with the first validate_image_sizes() message.
  ProcessImage(std::size_t pii_bytes, std::size_t piq_bytes, std::size_t memory_bytes = 0);

  std::span<std::uint8_t> pii() { return pii_; }
  std::span<const std::uint8_t> pii() const { return pii_; }
  std::span<std::uint8_t> piq() { return piq_; }
  std::span<const std::uint8_t> piq() const { return piq_; }
  std::span<std::uint8_t> memory() { return memory_; }
  std::span<const std::uint8_t> memory() const { return memory_; }

  std::span<std::uint8_t> area(Area a);
  std::span<const std::uint8_t> area(Area a) const;

  /// Same sizes in all three areas (a copy between them is possible).
  bool same_shape(const ProcessImage& o) const {
    return pii_.size() == o.pii_.size() && piq_.size() == o.piq_.size() &&
           memory_.size() == o.memory_.size();
  }

  friend bool operator==(const ProcessImage&, const ProcessImage&) = default;

 private:
  std::vector<std::uint8_t> pii_;
  std::vector<std::uint8_t> piq_;
  std::vector<std::uint8_t> memory_;
};

/// Where two images first differ.
struct ImageDifference {
  Area area = Area::Piq;
  std::uint32_t offset = 0;  ///< byte offset inside the area
  std::uint8_t value[2] = {0, 0};  ///< the byte in the first and in the second image
};

/// First difference in `areas` (in that order, each from offset 0 up), or nullopt when the
/// listed areas are equal. Areas of different sizes differ at the first offset past the
/// shorter one (value 0 for the missing byte).
std::optional<ImageDifference> first_difference(const ProcessImage& a, const ProcessImage& b,
                                                std::span<const Area> areas);

}  // namespace pbvbus::devices
