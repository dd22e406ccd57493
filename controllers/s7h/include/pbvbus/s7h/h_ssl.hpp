#pragma once
// SSL partial lists of the H-system for SFC 51 RDSYSST (seeds-digest.md §6 "SSL lists";
// docs/h-system.md "SSL lists (SFC 51)"). HSystemModel::read_ssl(id, index) answers with these.
//
// The answer is byte-exact: SSL_HEADER (LENTHDR, N_DR; words, big-endian as every S7 word) then
// N_DR records of LENTHDR bytes. Layouts from "System Software for S7-300/400 System and Standard
// Functions", Volume 2, ch. "System Status Lists" (found with the project's search; the sections
// are named at each builder). RET_VAL (same manual, SFC 51): 0; W#16#8082 SSL_ID wrong or
// unknown; W#16#8083 INDEX wrong or not permitted; W#16#8085 information not available now
// (digest §6/R7: SFC 51 during the update).
//
// Decisions where the manual excerpt is silent (each written down, none silent):
// - xy71 record (16 bytes): redinf W#16#0012 ("1 of 2 H system"); mwstat1 bit 4/5 = CPU in rack
//   0/1 is master; mwstat2 bit 0 = synchronisation possible (both CPUs powered over a whole
//   link), bit 4/5 = CPU inserted in rack 0/1 (powered) and 0 in Redundant mode (as the manual
//   says), bit 7 (swap since the last SFC 90 re-enable) 0: SFC 90 is not modelled; hsfcinfo 0
//   (SFC 90 not modelled), samfehl 0 (reserved). bz_cpu_x: Off -> 000F NO POWER, STOP -> 0004
//   STOP (internal), STOP with a reset request -> 0002 STOP (reset memory), STARTUP -> 0006
//   (warm restart, OB 100), RUN -> 0008 in Solo / 0009 RUN-R in Redundant, HOLD 000A, LINK-UP
//   000B, UPDATE 000C, DEFECTIVE 000D, ERROR-SEARCH 000E (SELFTEST), SYNCUP (1500) 000B.
//   bz_cpu_2 0. cpu_valid: the answering CPU's own value always, the partner's when the link
//   is whole (it is known over the sync link only). Byte 15 is not in the excerpt found: 0.
// - W#16#0C75 (switched DP slave): the model has no diagnostic addresses, so INDEX is
//   (DP master system ID << 8) | station, DP master system ID = system index + 1, and logadr
//   repeats INDEX. adr1_bgt<r> = the same word for the rack r whose line is the station's
//   active channel, 0 for the other; adr2 (IM slot/submodule) 0; bytes 14-15 (not in the
//   excerpt) 0. A station that is not switched, or unknown: W#16#8083.
// - W#16#0019 / W#16#0174 records (4 bytes): cpu_led_ID byte 0 = 1111 b3 b2..b0 (bit 3 master,
//   bits 0-2 rack), byte 1 the LED ID (BUS1F 0B, BUS2F 0C, REDF 0D, MSTR 0E, RACK0 0F, RACK1 10,
//   IFM1F 12, IFM2F 13); led_on 1 only for a steady LED; a flashing one has led_on 0 and
//   led_blink 1 (2 Hz; BUSxF flashing too) or 2 (0.5 Hz). Only the LEDs the model has (no RUN,
//   STOP, SF, INTF, EXTF ...: W#16#8083 for their ID in 0174). BUSxF for the first two master
//   systems. W#16#0019 is the answering CPU's list, "only possible in the non-redundant H
//   modes" (manual): W#16#8085 in Redundant mode. W#16#0174 in Redundant mode: one record per
//   CPU (rack 0 first, the manual's "all redundant H CPUs").
// - W#16#0232 index 4: one record per CPU in Redundant (the master's first: F8+F1 or F9+F0),
//   else the answering CPU's (F8 rack 0 / F9 rack 1 as master). The listed fields are 19 words
//   (38 bytes): index, sch_schal 1, sch_par 0 (no password), sch_rel 1 (no protection is
//   modelled), bart_sch 1 RUN / 3 STOP from the mode switch, anl_sch 0 (none), ken_rel 0 (no
//   version IDs), ken_ver* 0, 8 reserved words. LENTHDR = 38 as counted, NOT confirmed.
// - W#16#0222 (INDEX = OB 70 or 72, W#16#0048 is the redundancy class = 72): 28 bytes
//   (LENTHDR W#16#001C): 20 bytes start information of the last start of that OB (byte 0-1
//   the event ID: EV_CLASS, FLT_ID; byte 3 the OB number; priority byte 2, the info words and
//   the date-time are 0: the seeds give no priority and the model has no calendar; OB 72's
//   event ID is 0, the seeds give none), then al 1 = W#16#0010 (bit 4: OB loaded, required in
//   an H system, digest §6) and 6 zero bytes. Other OBs: W#16#8083.
// - The answering CPU is the master (one program, SFC 51 runs in it; in Redundant both give
//   the same answer). No master: W#16#8085.
#include <cstdint>
#include <vector>

namespace pbvbus::devices {

class HCpuPair;

/// bz_cpu of CPU `rack` (the codes above: 0004 STOP, 0008 RUN, 0009 RUN-R, 000B LINK-UP ...);
/// SZL W#16#0424 over S7 reports its low octet as the CPU's state (h_s7_session.hpp).
std::uint16_t bz_cpu(const HCpuPair& pair, int rack);

inline constexpr std::uint16_t kRetSslIdUnknown = 0x8082;  ///< W#16#8082: SSL_ID wrong/unknown
inline constexpr std::uint16_t kRetSslIndex = 0x8083;      ///< W#16#8083: INDEX wrong

inline constexpr std::uint16_t kSslHState = 0x0071;
inline constexpr std::uint16_t kSslHStateHeader = 0x0F71;
inline constexpr std::uint16_t kSslSwitchedSlave = 0x0C75;
inline constexpr std::uint16_t kSslAllLeds = 0x0019;
inline constexpr std::uint16_t kSslOneLed = 0x0174;
inline constexpr std::uint16_t kSslInterrupt = 0x0222;
inline constexpr std::uint16_t kSslProtection = 0x0232;

/// LED IDs of W#16#0019/0174 the model knows.
enum class LedId : std::uint8_t {
  Bus1f = 0x0B,
  Bus2f = 0x0C,
  Redf = 0x0D,
  Mstr = 0x0E,
  Rack0 = 0x0F,
  Rack1 = 0x10,
  Ifm1f = 0x12,
  Ifm2f = 0x13,
};

struct SslResult {
  std::uint16_t ret_val = 0;        ///< 0 or W#16#8082/8083/8085
  std::vector<std::uint8_t> data;   ///< LENTHDR, N_DR, records (empty on an error)
};

/// Appends a big-endian word.
inline void put_word(std::vector<std::uint8_t>& v, std::uint16_t w) {
  v.push_back(static_cast<std::uint8_t>(w >> 8));
  v.push_back(static_cast<std::uint8_t>(w & 0xFF));
}

/// Byte 0 of an H CPU's record ID: 1111 b3 (1 = master) b2..b0 (rack).
constexpr std::uint8_t h_cpu_id_byte(int rack, bool master) {
  return static_cast<std::uint8_t>(0xF0 | (master ? 0x08 : 0x00) | (rack & 0x07));
}

}  // namespace pbvbus::devices
