#pragma once
// Diagnostic-buffer entries of the redundant I/O (h_redundant_io.hpp). The seeds give one error
// code, 7960 (001 L5949-5952); the others are decisions in the same 79xx range, one per entry the
// manual says is written (docs/h-redundant-io.md "Events"):
//   7960  DI discrepancy time expired, error not yet localized: no passivation (001 L5949-5954)
//   7961  DI module passivated: the other module changed after the expiry (001 L5957-5959)
//   7962  AI module passivated: discrepancy time expired outside the tolerance window
//         ("in any case the passivated module is registered in the diagnostic buffer",
//         001 L6170-6177)
//   7963  depassivation completed for all modules (001 L6596-6598)
//   7964  module passivated by OB 82 (a diagnostic interrupt; 001 Table 7-4 bit 4, 7-5 bits 0-1)
//   7965  module passivated by OB 85 (an access error; 001 Table 7-4 bit 3, 7-5 byte 2 bits 6-7)
//   7966  AI module passivated: it reads overflow 7FFF or underflow 8000 (001 L6330: wire break
//         gives 7FFF; Table 7-5 byte 1 bit 2)
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "pbvbus/bus/time.hpp"

namespace pbvbus::devices {

inline constexpr std::uint16_t kRedIoDiDiscrepancy = 0x7960;
inline constexpr std::uint16_t kRedIoDiPassivated = 0x7961;
inline constexpr std::uint16_t kRedIoAiPassivated = 0x7962;
inline constexpr std::uint16_t kRedIoDepassivated = 0x7963;
inline constexpr std::uint16_t kRedIoOb82Passivated = 0x7964;
inline constexpr std::uint16_t kRedIoOb85Passivated = 0x7965;
inline constexpr std::uint16_t kRedIoOverflowPassivated = 0x7966;

enum class RedIoKind : std::uint8_t { DI, AI, DO, AO };
std::string_view to_string(RedIoKind k);
/// Inputs (DI, AI) are read from both modules and compared; outputs are written to both.
inline bool is_input(RedIoKind k) { return k == RedIoKind::DI || k == RedIoKind::AI; }

/// Why a module was passivated.
enum class RedIoCause : std::uint8_t {
  None,
  DiDiscrepancy,  ///< 7961
  AiDiscrepancy,  ///< 7962
  Ob82,           ///< 7964
  Ob85,           ///< 7965
  Overflow,       ///< 7966
};
std::string_view to_string(RedIoCause c);

struct RedIoEvent {
  bus::Ticks time = 0;
  std::uint16_t code = 0;
  RedIoKind kind = RedIoKind::DI;  ///< the pair's kind (7963: DI)
  std::size_t pair = 0;        ///< index in the pair list (7963: 0)
  int module = -1;             ///< 0 = module_L, 1 = module_H, -1 = the pair / all pairs
  std::uint32_t address = 0;   ///< the module's address (7960: module_L's; 7963: 0)
  std::uint32_t bit = 0;       ///< DI: bit number in the module (octet · 8 + bit); AI: channel
  std::uint32_t count = 0;     ///< 7963: modules depassivated
  friend bool operator==(const RedIoEvent&, const RedIoEvent&) = default;
};

/// One line for the diagnostic buffer / run report, e.g.
/// "W#16#7961 redundant DI: module_H (IB 12) passivated, pair 0".
std::string describe(const RedIoEvent& e);

}  // namespace pbvbus::devices
