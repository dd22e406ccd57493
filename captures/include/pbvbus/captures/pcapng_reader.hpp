#pragma once
// pcapng capture reader (draft-ietf-opsawg-pcapng): the counterpart of PcapngWriter, used by
// `pbvbus inspect`, replay and the tests.
//
// Reads Section Header, Interface Description, Enhanced Packet and Simple Packet blocks and
// skips every other block by its length. Sections of either byte order are read (the byte order
// magic decides per section); several sections in one file are allowed, their interfaces are
// numbered on across sections. Options read: if_name, if_description, if_speed, if_tsresol,
// if_tsoffset, epb_flags, opt_comment (several comments are joined with "; ").
// Anything malformed ends reading with an error that names the file offset of the problem;
// the reader never reads outside the buffer and never throws on bad input.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pbvbus::captures {

struct PcapngInterface {
  std::uint16_t link_type = 0;
  std::uint32_t snaplen = 0;
  std::string name;
  std::string description;
  std::uint64_t speed = 0;      ///< if_speed in bit/s; 0 = not given
  std::uint8_t tsresol = 6;     ///< if_tsresol as in the file (default 6: microseconds)
  std::int64_t tsoffset_s = 0;  ///< if_tsoffset in seconds
  std::uint32_t section = 0;    ///< index of the section that declared it
};

struct PcapngRecord {
  std::uint32_t interface = 0;      ///< index into PcapngReader::interfaces()
  std::int64_t ts_ns = 0;           ///< timestamp in ns (tsresol and tsoffset applied)
  std::vector<std::uint8_t> bytes;  ///< captured octets
  std::uint32_t orig_len = 0;
  std::uint32_t flags = 0;   ///< epb_flags (0 if absent)
  std::string comment;       ///< opt_comment ("" if absent)
  std::uint64_t offset = 0;  ///< file offset of the block
};

struct PcapngError {
  std::uint64_t offset = 0;
  std::string message;
  /// "offset 1234: EPB block length 17 is not a multiple of 4"
  std::string to_string() const;
};

class PcapngReader {
 public:
  /// Reads from a copy of `data`.
  explicit PcapngReader(std::vector<std::uint8_t> data);
  /// Reads a whole file into memory. nullopt with the reason in `error` if it cannot be read
  /// (a file that is not pcapng gives an error on the first next()).
  static std::optional<PcapngReader> open(const std::string& path, PcapngError& error);

  /// The next packet. False at the end of the file or on an error (then error() is set).
  /// Reusing the same record avoids allocation.
  bool next(PcapngRecord& r);
  /// Interfaces seen so far (all of them once next() has returned false).
  const std::vector<PcapngInterface>& interfaces() const { return m_ifs; }
  const std::optional<PcapngError>& error() const { return m_error; }
  /// Whether the current section is big-endian.
  bool big_endian() const { return m_be; }

 private:
  bool fail(std::uint64_t offset, std::string msg);
  std::uint16_t u16(std::size_t off) const;
  std::uint32_t u32(std::size_t off) const;
  std::uint64_t u64(std::size_t off) const;
  bool read_shb(std::size_t off, std::size_t len);
  bool read_idb(std::size_t off, std::size_t len);
  bool read_epb(std::size_t off, std::size_t len, PcapngRecord& r);
  bool read_spb(std::size_t off, std::size_t len, PcapngRecord& r);
  template <class F>
  bool read_options(std::size_t off, std::size_t end, const char* block, F&& on_option);

  std::vector<std::uint8_t> m_data;
  std::size_t m_pos = 0;
  bool m_be = false;
  bool m_in_section = false;
  std::uint32_t m_section = 0;
  std::uint32_t m_sections_seen = 0;
  std::size_t m_section_base = 0;  ///< index of the section's first interface in m_ifs
  std::vector<PcapngInterface> m_ifs;
  std::optional<PcapngError> m_error;
};

/// Every packet and interface of a file.
struct PcapngCapture {
  std::vector<PcapngInterface> interfaces;
  std::vector<PcapngRecord> records;
};
std::optional<PcapngCapture> read_pcapng(std::span<const std::uint8_t> data, PcapngError& error);
std::optional<PcapngCapture> read_pcapng_file(const std::string& path, PcapngError& error);

}  // namespace pbvbus::captures
