// The battery's DP request builders and reply reader (groups.hpp). Encoding is fdl::encode (the
// codec picks SD1/SD2/SD3 by §B.1); reading is fdl::decode, so a reply the codec rejects is
// Reply::Kind::Bad with the codec's reason.
//
// Decisions:
// - srd() uses SRD high (FC function 0xD), as DP masters send DP-V0 services (§B.4); sdn() uses
//   SDN high (0x6, Global_Control's FC 0x46).
// - A request the codec refuses (a test that builds a deliberately impossible one) comes back
//   empty; TestBus sends nothing for an empty telegram's bytes but still records it, so the
//   test sees "no reply". No exception leaves these helpers.

#include <cstdio>

#include "groups.hpp"
#include "report_util.hpp"

namespace pbvbus::conformance::detail {

namespace {

std::vector<std::uint8_t> encode_request(std::uint8_t da, std::uint8_t sa, std::uint8_t fc,
                                         std::optional<std::uint8_t> dsap,
                                         std::optional<std::uint8_t> ssap,
                                         std::span<const std::uint8_t> data) {
  fdl::FrameSpec spec;
  spec.da = da;
  spec.sa = sa;
  spec.fc = fc;
  spec.dsap = dsap;
  spec.ssap = ssap;
  spec.data = data;
  fdl::Frame f;
  if (fdl::encode(spec, f) != fdl::EncodeError::None) return {};
  auto b = f.bytes();
  return {b.begin(), b.end()};
}

}  // namespace

std::vector<std::uint8_t> srd(std::uint8_t da, std::uint8_t sa, std::optional<std::uint8_t> dsap,
                              std::optional<std::uint8_t> ssap, std::span<const std::uint8_t> data,
                              bool fcv, bool fcb) {
  return encode_request(da, sa, fdl::make_request_fc(fdl::RequestFn::SrdHigh, fcv, fcb), dsap, ssap,
                        data);
}

std::vector<std::uint8_t> sdn(std::uint8_t da, std::uint8_t sa, std::optional<std::uint8_t> dsap,
                              std::optional<std::uint8_t> ssap, std::span<const std::uint8_t> data) {
  return encode_request(da, sa, fdl::make_request_fc(fdl::RequestFn::SdnHigh), dsap, ssap, data);
}

std::vector<std::uint8_t> fdl_status(std::uint8_t da, std::uint8_t sa) {
  return encode_request(da, sa, fdl::make_request_fc(fdl::RequestFn::FdlStatus), std::nullopt,
                        std::nullopt, {});
}

bool Reply::ok_with_data() const {
  return kind == Kind::Telegram &&
         (status == fdl::ResponseStatus::DL || status == fdl::ResponseStatus::DH);
}

bool Reply::rs() const { return kind == Kind::Telegram && status == fdl::ResponseStatus::RS; }

std::string Reply::describe() const {
  switch (kind) {
    case Kind::None: return "no reply";
    case Kind::Bad: return "bad frame: " + error;
    case Kind::Sc: return "SC";
    case Kind::Telegram: {
      std::string s(fdl::to_string(status));
      if (!data.empty()) s += " " + hex_octets(data);
      return s;
    }
  }
  return "?";
}

Reply reply_of(const Exchange& e) {
  Reply r;
  if (!e.answered) return r;
  if (e.response_flags != 0) {
    r.kind = Reply::Kind::Bad;
    r.error = "receive errors (flags " + std::to_string(e.response_flags) + "): " + hex_octets(e.response);
    return r;
  }
  fdl::Telegram t;
  const fdl::DecodeError err = fdl::decode(e.response, t);
  if (err != fdl::DecodeError::None) {
    r.kind = Reply::Kind::Bad;
    r.error = std::string(fdl::to_string(err)) + ": " + hex_octets(e.response);
    return r;
  }
  if (t.type == fdl::FrameType::SC) {
    r.kind = Reply::Kind::Sc;
    return r;
  }
  if (t.type == fdl::FrameType::SD4 || t.is_request()) {
    r.kind = Reply::Kind::Bad;
    r.error = "not a response: " + hex_octets(e.response);
    return r;
  }
  r.kind = Reply::Kind::Telegram;
  r.fc = t.fc;
  r.da = t.da;
  r.sa = t.sa;
  r.dsap = t.dsap;
  r.ssap = t.ssap;
  r.status = fdl::fc_status(t.fc);
  r.data.assign(t.data.begin(), t.data.end());
  return r;
}

}  // namespace pbvbus::conformance::detail
