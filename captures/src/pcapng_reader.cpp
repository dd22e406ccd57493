#include "pbvbus/captures/pcapng_reader.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "pbvbus/captures/pcapng_format.hpp"
#include "saturate.hpp"

namespace pbvbus::captures {

namespace {

using pcapng::pad4;

std::int64_t to_ns(std::uint64_t ts, std::uint8_t tsresol, std::int64_t offset_s) {
  const int n = tsresol & 0x7F;
  i128 ns;
  if (tsresol & 0x80) {
    ns = (static_cast<i128>(ts) * 1'000'000'000) >> n;
  } else if (n <= 9) {
    i128 mul = 1;
    for (int i = n; i < 9; ++i) mul *= 10;
    ns = static_cast<i128>(ts) * mul;
  } else {
    ns = ts;
    for (int i = 9; i < n && ns != 0; ++i) ns /= 10;
  }
  return saturate(ns + static_cast<i128>(offset_s) * 1'000'000'000);
}

std::string block_name(std::uint32_t type) {
  switch (type) {
    case pcapng::kBlockShb:
      return "SHB";
    case pcapng::kBlockIdb:
      return "IDB";
    case pcapng::kBlockEpb:
      return "EPB";
    case pcapng::kBlockSpb:
      return "SPB";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "block 0x%08X", type);
      return buf;
    }
  }
}
}  // namespace

std::string PcapngError::to_string() const {
  return "offset " + std::to_string(offset) + ": " + message;
}

PcapngReader::PcapngReader(std::vector<std::uint8_t> data) : m_data(std::move(data)) {}

std::optional<PcapngReader> PcapngReader::open(const std::string& path, PcapngError& error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    error = {0, "cannot open '" + path + "': " + std::strerror(errno)};
    return std::nullopt;
  }
  std::vector<std::uint8_t> data;
  std::uint8_t buf[1 << 16];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) data.insert(data.end(), buf, buf + n);
  const bool bad = std::ferror(f) != 0;
  std::fclose(f);
  if (bad) {
    error = {data.size(), "read error on '" + path + "'"};
    return std::nullopt;
  }
  return PcapngReader(std::move(data));
}

bool PcapngReader::fail(std::uint64_t offset, std::string msg) {
  m_error = PcapngError{offset, std::move(msg)};
  m_pos = m_data.size();
  return false;
}

std::uint16_t PcapngReader::u16(std::size_t off) const {
  const std::uint8_t* p = m_data.data() + off;
  return m_be ? static_cast<std::uint16_t>(p[0] << 8 | p[1])
              : static_cast<std::uint16_t>(p[1] << 8 | p[0]);
}
std::uint32_t PcapngReader::u32(std::size_t off) const {
  const std::uint8_t* p = m_data.data() + off;
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | p[m_be ? i : 3 - i];
  return v;
}
std::uint64_t PcapngReader::u64(std::size_t off) const {
  const std::uint8_t* p = m_data.data() + off;
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[m_be ? i : 7 - i];
  return v;
}

template <class F>
bool PcapngReader::read_options(std::size_t off, std::size_t end, const char* block,
                                F&& on_option) {
  while (off < end) {
    if (end - off < 4) return fail(off, std::string(block) + ": option header runs past the block");
    const std::uint16_t code = u16(off);
    const std::uint16_t len = u16(off + 2);
    if (code == pcapng::kOptEndOfOpt) return true;
    if (pad4(len) > end - off - 4)
      return fail(off, std::string(block) + ": option " + std::to_string(code) + " of length " +
                           std::to_string(len) + " runs past the block");
    if (!on_option(code, off + 4, static_cast<std::size_t>(len))) return false;
    off += 4 + pad4(len);
  }
  return true;
}

bool PcapngReader::read_shb(std::size_t off, std::size_t len) {
  // len was checked against the buffer by next(); body starts at off + 8.
  if (len < 28) return fail(off, "SHB block length " + std::to_string(len) + " is below 28");
  const std::uint16_t major = u16(off + 12);
  if (major != 1)
    return fail(off + 12, "unsupported pcapng major version " + std::to_string(major));
  m_in_section = true;
  m_section = m_sections_seen++;
  m_section_base = m_ifs.size();
  return read_options(off + 24, off + len - 4, "SHB",
                      [](std::uint16_t, std::size_t, std::size_t) { return true; });
}

bool PcapngReader::read_idb(std::size_t off, std::size_t len) {
  if (len < 20) return fail(off, "IDB block length " + std::to_string(len) + " is below 20");
  PcapngInterface i;
  i.link_type = u16(off + 8);
  i.snaplen = u32(off + 12);
  i.section = m_section;
  const bool ok = read_options(
      off + 16, off + len - 4, "IDB", [&](std::uint16_t code, std::size_t v, std::size_t n) {
        const char* s = reinterpret_cast<const char*>(m_data.data() + v);
        switch (code) {
          case pcapng::kIfName:
            i.name.assign(s, n);
            break;
          case pcapng::kIfDescription:
            i.description.assign(s, n);
            break;
          case pcapng::kIfSpeed:
            if (n != 8)
              return fail(v - 4, "IDB: if_speed has length " + std::to_string(n) + ", not 8");
            i.speed = u64(v);
            break;
          case pcapng::kIfTsresol:
            if (n != 1)
              return fail(v - 4, "IDB: if_tsresol has length " + std::to_string(n) + ", not 1");
            i.tsresol = m_data[v];
            break;
          case pcapng::kIfTsoffset:
            if (n != 8)
              return fail(v - 4, "IDB: if_tsoffset has length " + std::to_string(n) + ", not 8");
            i.tsoffset_s = static_cast<std::int64_t>(u64(v));
            break;
          default:
            break;
        }
        return true;
      });
  if (!ok) return false;
  m_ifs.push_back(std::move(i));
  return true;
}

bool PcapngReader::read_epb(std::size_t off, std::size_t len, PcapngRecord& r) {
  if (len < 32) return fail(off, "EPB block length " + std::to_string(len) + " is below 32");
  const std::uint32_t if_id = u32(off + 8);
  if (if_id >= m_ifs.size() - m_section_base)
    return fail(off + 8, "EPB refers to interface " + std::to_string(if_id) +
                             ", but the section declares " +
                             std::to_string(m_ifs.size() - m_section_base));
  const std::uint32_t caplen = u32(off + 20);
  if (pad4(caplen) > len - 32)
    return fail(off + 20, "EPB captured length " + std::to_string(caplen) + " exceeds the block (" +
                              std::to_string(len) + " octets)");
  const PcapngInterface& itf = m_ifs[m_section_base + if_id];
  const std::uint64_t ts = (static_cast<std::uint64_t>(u32(off + 12)) << 32) | u32(off + 16);
  r.interface = static_cast<std::uint32_t>(m_section_base + if_id);
  r.ts_ns = to_ns(ts, itf.tsresol, itf.tsoffset_s);
  r.orig_len = u32(off + 24);
  r.bytes.assign(m_data.begin() + static_cast<std::ptrdiff_t>(off + 28),
                 m_data.begin() + static_cast<std::ptrdiff_t>(off + 28 + caplen));
  r.flags = 0;
  r.comment.clear();
  r.offset = off;
  return read_options(
      off + 28 + pad4(caplen), off + len - 4, "EPB",
      [&](std::uint16_t code, std::size_t v, std::size_t n) {
        if (code == pcapng::kEpbFlags) {
          if (n != 4)
            return fail(v - 4, "EPB: epb_flags has length " + std::to_string(n) + ", not 4");
          r.flags = u32(v);
        } else if (code == pcapng::kOptComment) {
          if (!r.comment.empty()) r.comment += "; ";
          r.comment.append(reinterpret_cast<const char*>(m_data.data() + v), n);
        }
        return true;
      });
}

bool PcapngReader::read_spb(std::size_t off, std::size_t len, PcapngRecord& r) {
  if (len < 16) return fail(off, "SPB block length " + std::to_string(len) + " is below 16");
  if (m_ifs.size() == m_section_base) return fail(off, "SPB before any IDB in its section");
  const PcapngInterface& itf = m_ifs[m_section_base];
  const std::uint32_t orig = u32(off + 8);
  std::size_t cap = std::min<std::size_t>(orig, len - 16);
  if (itf.snaplen != 0) cap = std::min<std::size_t>(cap, itf.snaplen);
  r.interface = static_cast<std::uint32_t>(m_section_base);
  r.ts_ns = 0;
  r.orig_len = orig;
  r.bytes.assign(m_data.begin() + static_cast<std::ptrdiff_t>(off + 12),
                 m_data.begin() + static_cast<std::ptrdiff_t>(off + 12 + cap));
  r.flags = 0;
  r.comment.clear();
  r.offset = off;
  return true;
}

bool PcapngReader::next(PcapngRecord& r) {
  while (m_pos < m_data.size()) {
    const std::size_t off = m_pos;
    const std::size_t left = m_data.size() - off;
    if (left < 12)
      return fail(off, "truncated block: " + std::to_string(left) +
                           " octets left, a block needs at least 12");
    std::uint32_t type;
    std::memcpy(&type, m_data.data() + off, 4);  // SHB type is a palindrome: any order works
    if (type == pcapng::kBlockShb) {
      static constexpr std::uint8_t kLe[4] = {0x4D, 0x3C, 0x2B, 0x1A};
      static constexpr std::uint8_t kBe[4] = {0x1A, 0x2B, 0x3C, 0x4D};
      if (std::memcmp(m_data.data() + off + 8, kLe, 4) == 0)
        m_be = false;
      else if (std::memcmp(m_data.data() + off + 8, kBe, 4) == 0)
        m_be = true;
      else
        return fail(off + 8, "SHB byte-order magic is not 1A2B3C4D in either byte order");
    } else if (!m_in_section) {
      return fail(off, off == 0 ? "not a pcapng file: it does not start with a Section Header Block"
                                : "block before any Section Header Block");
    } else {
      type = u32(off);
    }
    const std::uint32_t len = u32(off + 4);
    if (len < 12 || len % 4 != 0)
      return fail(off + 4, block_name(type) + " block length " + std::to_string(len) +
                               " is below 12 or not a multiple of 4");
    if (len > left)
      return fail(off + 4, block_name(type) + " block length " + std::to_string(len) +
                               " runs past the end of the file (" + std::to_string(left) +
                               " octets left)");
    if (u32(off + len - 4) != len)
      return fail(off + len - 4, block_name(type) + " trailing block length " +
                                     std::to_string(u32(off + len - 4)) +
                                     " differs from the leading one (" + std::to_string(len) + ")");
    m_pos = off + len;
    switch (type) {
      case pcapng::kBlockShb:
        if (!read_shb(off, len)) return false;
        break;
      case pcapng::kBlockIdb:
        if (!read_idb(off, len)) return false;
        break;
      case pcapng::kBlockEpb:
        return read_epb(off, len, r);
      case pcapng::kBlockSpb:
        return read_spb(off, len, r);
      default:
        break;  // unknown or uninteresting block: skipped by its length
    }
  }
  return false;
}

std::optional<PcapngCapture> read_pcapng(std::span<const std::uint8_t> data, PcapngError& error) {
  PcapngReader reader(std::vector<std::uint8_t>(data.begin(), data.end()));
  PcapngCapture cap;
  PcapngRecord r;
  while (reader.next(r)) cap.records.push_back(r);
  if (reader.error()) {
    error = *reader.error();
    return std::nullopt;
  }
  cap.interfaces = reader.interfaces();
  return cap;
}

std::optional<PcapngCapture> read_pcapng_file(const std::string& path, PcapngError& error) {
  auto reader = PcapngReader::open(path, error);
  if (!reader) return std::nullopt;
  PcapngCapture cap;
  PcapngRecord r;
  while (reader->next(r)) cap.records.push_back(r);
  if (reader->error()) {
    error = *reader->error();
    return std::nullopt;
  }
  cap.interfaces = reader->interfaces();
  return cap;
}

}  // namespace pbvbus::captures
