#pragma once
// Drives a SlaveEngine by hand: golden request frames are decoded with the FDL codec into the
// Indication a passive station would deliver, and the engine's Reply is encoded the way the
// station sends it (response DA/SA and SAPs mirrored, FC = slave + status), so tests compare
// whole frames with the hand-written frames of protocol-facts.md Appendix 1.

#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/telegram.hpp"

namespace pbvbus::dp::test {

using Bytes = std::vector<std::uint8_t>;

inline std::string hex(std::span<const std::uint8_t> b) {
  static const char* d = "0123456789ABCDEF";
  std::string s;
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (i) s += ' ';
    s += d[b[i] >> 4];
    s += d[b[i] & 15];
  }
  return s;
}

/// The frame a passive station sends for `reply` to the request `ind` ("" for none).
inline Bytes encode_reply(const fdl::Indication& ind, const fdl::Reply& reply) {
  using K = fdl::Reply::Kind;
  if (reply.kind == K::None) return {};
  if (reply.kind == K::ShortAck) return {fdl::kSC};
  fdl::FrameSpec s;
  s.da = ind.sa;
  s.sa = ind.da;
  s.fc = fdl::make_response_fc(fdl::StationType::Slave, reply.status);
  s.dsap = ind.ssap;
  s.ssap = ind.dsap;
  if (reply.kind == K::Data) s.data = reply.data;
  fdl::Frame f;
  EXPECT_EQ(fdl::encode(s, f), fdl::EncodeError::None);
  return {f.bytes().begin(), f.bytes().end()};
}

class Harness {
 public:
  explicit Harness(SlaveEngine& e) : m_e(e) {}
  bus::Ticks now = 0;
  fdl::Reply last;

  /// Delivers a whole request frame (decoded with the codec) and returns the reply frame.
  Bytes frame(const Bytes& req) {
    fdl::Telegram t;
    const auto err = fdl::decode(req, t);
    EXPECT_EQ(err, fdl::DecodeError::None) << hex(req);
    fdl::Indication ind;
    ind.now = now;
    ind.sa = t.sa;
    ind.da = t.da;
    ind.fn = fdl::fc_request_fn(t.fc);
    ind.dsap = t.dsap;
    ind.ssap = t.ssap;
    ind.data = t.data;
    last = fdl::Reply{};
    m_e.on_request(ind, last);
    return encode_reply(ind, last);
  }
  /// Builds and delivers a request from master `sa` to slave `da`.
  Bytes req(std::uint8_t sa, std::uint8_t da, std::optional<std::uint8_t> dsap, const Bytes& data,
            fdl::RequestFn fn = fdl::RequestFn::SrdHigh) {
    fdl::Indication ind;
    ind.now = now;
    ind.sa = sa;
    ind.da = da;
    ind.fn = fn;
    ind.dsap = dsap;
    if (dsap) ind.ssap = sa_sap(*dsap);
    ind.data = data;
    last = fdl::Reply{};
    m_e.on_request(ind, last);
    return encode_reply(ind, last);
  }
  /// Only the reply's DU (empty for SC, none, or a status-only reply).
  Bytes du(std::uint8_t sa, std::uint8_t da, std::optional<std::uint8_t> dsap, const Bytes& data,
           fdl::RequestFn fn = fdl::RequestFn::SrdHigh) {
    req(sa, da, dsap, data, fn);
    return last.kind == fdl::Reply::Kind::Data ? last.data : Bytes{};
  }
  void advance(bus::Ticks t) {
    now += t;
    while (m_e.next_deadline() <= now) {
      const auto d = m_e.next_deadline();
      m_e.on_time(d);
      if (m_e.next_deadline() == d) break;  // an engine that does not move its deadline
    }
  }

  static std::uint8_t sa_sap(std::uint8_t dsap) {
    if (dsap == 51 || dsap == 50) return 51;  // MSAC_C1 from the class-1 master
    if (dsap <= 49) return 50;                // MSAC_C2 from the class-2 master
    return 62;
  }

 private:
  SlaveEngine& m_e;
};

}  // namespace pbvbus::dp::test
