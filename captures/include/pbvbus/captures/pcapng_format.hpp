#pragma once
// pcapng constants (IETF draft-ietf-opsawg-pcapng, "PCAP Now Generic"), the subset pbvbus
// writes and reads: Section Header, Interface Description and Enhanced Packet blocks, and the
// options of design.md "Captures".

#include <cstddef>
#include <cstdint>

namespace pbvbus::captures::pcapng {

/// Block bodies and option values are padded to 32 bits.
constexpr std::size_t pad4(std::size_t n) { return (n + 3) & ~std::size_t{3}; }

inline constexpr std::uint32_t kBlockShb = 0x0A0D0D0A;
inline constexpr std::uint32_t kBlockIdb = 0x00000001;
inline constexpr std::uint32_t kBlockSpb = 0x00000003;  ///< Simple Packet Block (read only)
inline constexpr std::uint32_t kBlockEpb = 0x00000006;
inline constexpr std::uint32_t kByteOrderMagic = 0x1A2B3C4D;

// Options common to all blocks.
inline constexpr std::uint16_t kOptEndOfOpt = 0;
inline constexpr std::uint16_t kOptComment = 1;
// SHB options.
inline constexpr std::uint16_t kShbHardware = 2;
inline constexpr std::uint16_t kShbOs = 3;
inline constexpr std::uint16_t kShbUserAppl = 4;
// IDB options.
inline constexpr std::uint16_t kIfName = 2;
inline constexpr std::uint16_t kIfDescription = 3;
inline constexpr std::uint16_t kIfSpeed = 8;
inline constexpr std::uint16_t kIfTsresol = 9;
inline constexpr std::uint16_t kIfTsoffset = 14;
// EPB options.
inline constexpr std::uint16_t kEpbFlags = 2;

/// Link types (tcpdump.org LINKTYPE_*). USER0 carries exactly the octets PROFIBUS_DL (257)
/// would; tshark 4.0 refuses 257 (tools-and-formats.md §4.1), so USER0 is the default.
enum class LinkType : std::uint16_t {
  User0 = 147,  ///< FDL telegrams, SD to ED
  User1 = 148,  ///< pbvbus event records (event_record.hpp)
  /// LINKTYPE_WIRESHARK_UPPER_PDU: exported-PDU tags, then a PDU for the dissector they name
  /// (S7 PDUs for s7comm, tools-and-formats.md §4.2).
  UpperPdu = 252,
  ProfibusDl = 257,
};

// Exported-PDU tags of LINKTYPE_WIRESHARK_UPPER_PDU (Wireshark epan/exported_pdu.h, 4.0): each
// tag is u16 code, u16 length (big-endian), then the value; the list ends with tag 0, length 0.
inline constexpr std::uint16_t kExpPduEnd = 0;
/// Name of a heuristic dissector, NUL-terminated, padded to 4 octets.
inline constexpr std::uint16_t kExpPduHeurProtoName = 13;
inline constexpr std::uint16_t kExpPduIpv4Src = 20;  ///< 4 octets
inline constexpr std::uint16_t kExpPduIpv4Dst = 21;  ///< 4 octets
inline constexpr std::uint16_t kExpPduPortType = 24;  ///< u32, kExpPduPortTcp
inline constexpr std::uint16_t kExpPduSrcPort = 25;  ///< u32
inline constexpr std::uint16_t kExpPduDstPort = 26;  ///< u32
inline constexpr std::uint32_t kExpPduPortTcp = 2;
/// The heuristic name of s7comm under COTP; tag 12 (dissector name) "s7comm" does not work in
/// tshark 4.0, s7comm being registered only as a heuristic (tools-and-formats.md §3.4, §4.2).
inline constexpr const char* kS7commHeuristic = "s7comm_cotp";

// epb_flags direction (bits 0..1).
inline constexpr std::uint32_t kFlagInbound = 1;
inline constexpr std::uint32_t kFlagOutbound = 2;

// epb_flags link-layer-dependent error bits (bits 16..31).
inline constexpr std::uint32_t kFlagSymbolError = 1u << 24;
inline constexpr std::uint32_t kFlagPreambleError = 1u << 25;
inline constexpr std::uint32_t kFlagStartDelimiterError = 1u << 26;
inline constexpr std::uint32_t kFlagUnalignedError = 1u << 27;
inline constexpr std::uint32_t kFlagWrongIfg = 1u << 28;
inline constexpr std::uint32_t kFlagTooShort = 1u << 29;
inline constexpr std::uint32_t kFlagTooLong = 1u << 30;
inline constexpr std::uint32_t kFlagCrcError = 1u << 31;
inline constexpr std::uint32_t kFlagErrorMask = 0xFFFF0000u;

}  // namespace pbvbus::captures::pcapng
