#include "pbvbus/gateways/canopen_sdo.hpp"

#include "pbvbus/gateways/canopen_objects.hpp"

namespace pbvbus::gateways::canopen {

namespace {

// Client command specifiers (bits 7..5 of octet 0).
constexpr std::uint8_t kCcsDownloadSegment = 0;
constexpr std::uint8_t kCcsInitiateDownload = 1;
constexpr std::uint8_t kCcsInitiateUpload = 2;
constexpr std::uint8_t kCcsAbort = 4;

constexpr std::uint8_t kExpedited = 0x02;       // e
constexpr std::uint8_t kSizeIndicated = 0x01;   // s

SdoFrame header(std::uint8_t cs, std::uint16_t index, std::uint8_t sub) {
  return SdoFrame{cs, static_cast<std::uint8_t>(index & 0xFF), static_cast<std::uint8_t>(index >> 8),
                  sub, 0, 0, 0, 0};
}

void put_u32(SdoFrame& f, std::uint32_t v) {
  for (std::size_t i = 0; i < 4; ++i) f[4 + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace

SdoRequest parse_sdo_request(std::span<const std::uint8_t> d) {
  SdoRequest r;
  // Index and sub-index sit at the same place in every initiate/abort request; take what is
  // there so even a rejected request is answered with its own multiplexer.
  if (d.size() >= 2) r.index = d[1];
  if (d.size() >= 3) r.index = static_cast<std::uint16_t>(r.index | (d[2] << 8));
  if (d.size() >= 4) r.sub = d[3];
  if (d.size() < 8) {
    r.abort = kAbortCommandSpecifier;
    return r;
  }
  const std::uint8_t cs = d[0];
  switch (cs >> 5) {
    case kCcsInitiateUpload: r.kind = SdoRequestKind::Upload; return r;
    case kCcsInitiateDownload: {
      if (!(cs & kExpedited)) break;  // segmented download: not supported
      r.kind = SdoRequestKind::Download;
      const std::uint8_t n = (cs >> 2) & 0x03;  // octets that do not contain data
      r.size = (cs & kSizeIndicated) ? static_cast<std::uint8_t>(4 - n) : 0;
      const std::size_t octets = r.size == 0 ? 4 : r.size;
      for (std::size_t i = 0; i < octets; ++i)
        r.value |= static_cast<std::uint32_t>(d[4 + i]) << (8 * i);
      return r;
    }
    case kCcsAbort: r.kind = SdoRequestKind::ClientAbort; return r;
    case kCcsDownloadSegment:
    default: break;  // segments without a transfer, block transfers, ccs 7
  }
  r.kind = SdoRequestKind::Invalid;
  r.abort = kAbortCommandSpecifier;
  return r;
}

SdoFrame sdo_upload_response(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                             std::uint8_t size) {
  if (size < 1) size = 1;
  if (size > 4) size = 4;
  // scs 2, e = 1, s = 1, n = 4 - size.
  SdoFrame f = header(static_cast<std::uint8_t>(0x43 | ((4 - size) << 2)), index, sub);
  for (std::size_t i = 0; i < size; ++i) f[4 + i] = static_cast<std::uint8_t>(value >> (8 * i));
  return f;
}

SdoFrame sdo_download_response(std::uint16_t index, std::uint8_t sub) {
  return header(0x60, index, sub);
}

SdoFrame sdo_abort(std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  SdoFrame f = header(0x80, index, sub);
  put_u32(f, code);
  return f;
}

}  // namespace pbvbus::gateways::canopen
