#pragma once
// The SZL extension point of S7Server (docs/s7cpu.md "Read SZL"): a CPU model answers more
// system status lists (SZL, in Siemens' English manuals SSL) than the server's own
// (szl_lists.hpp). The server asks its SzlSource first; nullopt means "not mine" and the server
// answers from its own lists, then "invalid SZL ID".
//
// The answer of a list is its records (LENTHDR octets each, N_DR of them), or why there are
// none. The server frames it as a Read SZL answer (s7_szl.hpp) and maps the reasons to the
// parameter error codes of the Userdata answer, named as Wireshark's s7comm dissector and
// libnodave name them:
//   UnknownId        -> W#16#D401 "invalid SZL ID"      (SFC 51: RET_VAL W#16#8082)
//   UnknownIndex     -> W#16#D402 "invalid SZL index"   (SFC 51: RET_VAL W#16#8083)
//   NotAvailableNow  -> W#16#D406 "information not available" (SFC 51: RET_VAL W#16#8085)
// with the data `0A 00 00 00` (s7_szl.hpp). snap7's server answers D402 for every list it
// lacks; the three codes keep the SFC 51 distinction visible to a client.
#include <cstdint>
#include <optional>
#include <vector>

namespace pbvbus::s7cpu {

/// Parameter error codes of a refused Read SZL (the header comment).
inline constexpr std::uint16_t kSzlErrorInvalidId = 0xD401;
inline constexpr std::uint16_t kSzlErrorInvalidIndex = 0xD402;
inline constexpr std::uint16_t kSzlErrorNotAvailable = 0xD406;

enum class SzlStatus : std::uint8_t { Ok, UnknownId, UnknownIndex, NotAvailableNow };

struct SzlList {
  SzlStatus status = SzlStatus::Ok;
  std::uint16_t record_length = 0;  ///< LENTHDR (octets per record)
  std::uint16_t record_count = 0;   ///< N_DR
  std::vector<std::uint8_t> records;  ///< record_length * record_count octets
};

/// The parameter error code for a status (0 for Ok).
std::uint16_t szl_error_code(SzlStatus s);

class SzlSource {
 public:
  virtual ~SzlSource() = default;
  /// The list `id`/`index` (the request's values), or nullopt: not one of this source's lists.
  virtual std::optional<SzlList> read_szl(std::uint16_t id, std::uint16_t index) = 0;
};

}  // namespace pbvbus::s7cpu
