#pragma once
// The DP system functions of the user program (docs/h-dp-sfc.md): SFC 14 DPRD_DAT and SFC 15
// DPWR_DAT, run by devices::Program at the end of every OB 1 (an H CPU and a plain S7 CPU
// alike), and the RET_VALs of SFC 11 DPSYC_FR and SFC 12 D_ACT_DP, which a plain CPU's node
// runs on its DP master (an H CPU refuses them, 001 Appendix B L14095, L14102).
//
// Sources: 001 §4.10.4 L3344-3365 (SFC 14/15: one module per call, from its configured start
// address; the target/source area has the configured length of the module); the RET_VAL
// values are not in the seeds: they are those of the S7 reference "System Software for
// S7-300/400, System and Standard Functions" as docs/h-dp-sfc.md lists them.
//
// Decisions:
// - LADDR is the module's first byte in the process images (IB for SFC 14, QB for SFC 15), as
//   STEP 7 gives it; a module is looked up in ProgramSpec::io_modules (the owner's map).
// - SFC 14 reads the module's inputs as the owner last took them in one piece (the PII bytes of
//   the module: the owner copies whole modules, so they are never torn); SFC 15 writes the
//   record into the PIQ bytes of the module, from where the owner sends the whole module
//   (001 L3433-3435: SFC 15 updates the process image too).
// - Order in OB 1: after the networks, every SFC 14 call, then every SFC 15 call, in spec order.
// - An area error (RECORD or RET_VAL outside M) is the general error W#16#8x22/8x23 with x the
//   parameter's position (SFC 14: LADDR 1, RET_VAL 2, RECORD 3; SFC 15: LADDR 1, RECORD 2,
//   RET_VAL 3); a RET_VAL that does not fit is not stored.
#include <cstdint>
#include <span>

#include "pbvbus/bus/time.hpp"
#include "pbvbus/s7h/h_program_spec.hpp"

namespace pbvbus::devices {

inline constexpr std::uint16_t kSfcOk = 0x0000;
/// SFC 14/15: no module configured at LADDR (for that direction). SFC 11/12: LADDR is no DP
/// master system / no configured slave.
inline constexpr std::uint16_t kSfcNoModule = 0x8090;
/// SFC 12: MODE not 0, 1 or 2.
inline constexpr std::uint16_t kDActBadMode = 0x8092;
/// SFC 14/15: the module at LADDR is no DP module (a central module of an expansion rack).
inline constexpr std::uint16_t kSfcNotDp = 0x8093;
/// SFC 11: GROUP is 0 (no group).
inline constexpr std::uint16_t kDpsycBadGroup = 0x8094;
/// SFC 11: MODE has no command bit, or bits outside SYNC/UNSYNC/FREEZE/UNFREEZE.
inline constexpr std::uint16_t kDpsycBadMode = 0x8095;
/// SFC 14/15: RECORD's length is not the module's configured length (001 L3352-3354, L3365).
inline constexpr std::uint16_t kSfcWrongLength = 0x80B1;
/// SFC 12 MODE 0: the slave is activated / deactivated.
inline constexpr std::uint16_t kDActIsActive = 0x0000;
inline constexpr std::uint16_t kDActIsInactive = 0x0001;
/// General errors: area length error reading / writing parameter x (W#16#8x22 / 8x23).
constexpr std::uint16_t area_read_error(unsigned param) { return static_cast<std::uint16_t>(0x8022 | (param << 8)); }
constexpr std::uint16_t area_write_error(unsigned param) { return static_cast<std::uint16_t>(0x8023 | (param << 8)); }

/// SFC 14 on images (pii) and memory (mem). Returns RET_VAL; stores it too when c.ret_val fits.
std::uint16_t dprd_dat(const DpReadCall& c, std::span<const IoModuleExtent> modules,
                       std::span<const std::uint8_t> pii, std::span<std::uint8_t> mem);
/// SFC 15 likewise, into piq.
std::uint16_t dpwr_dat(const DpWriteCall& c, std::span<const IoModuleExtent> modules,
                       std::span<std::uint8_t> piq, std::span<std::uint8_t> mem);
/// Every SFC 14 and SFC 15 call of `spec` due at `now` (at <= now).
void run_dp_sfcs(const ProgramSpec& spec, std::span<const std::uint8_t> pii,
                 std::span<std::uint8_t> piq, std::span<std::uint8_t> mem, bus::Ticks now);

/// SFC 11's parameter check: 0 (go on) or its RET_VAL.
std::uint16_t check_dpsyc_fr(std::uint8_t group, std::uint8_t mode);
/// RET_VAL into MW `at` (big-endian) if it fits; false if not.
bool store_ret_val(std::span<std::uint8_t> mem, std::uint32_t at, std::uint16_t ret_val);

}  // namespace pbvbus::devices
