#pragma once
// Drives a dp::Master (or any fdl::InitiatorUser, e.g. dp::Class2Master) by hand, standing in for the FDL active station: it asks next_request()
// the way the station does while holding the token, encodes each Request into the frame the
// station would send (FCB/FCV per responder as in protocol-facts.md §C.6: first frame FCV=0/
// FCB=1, then toggled after each valid reply, reset after a NoResponse), and feeds back the
// Confirmation the test chooses — or, for addresses with an attached SlaveEngine, the engine's
// real answer. Tests compare frames with the hand-written bytes of Appendix 1.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pbvbus/dp/master.hpp"
#include "pbvbus/dp/slave_engine.hpp"
#include "pbvbus/fdl/telegram.hpp"
#include "slave_harness.hpp"

namespace pbvbus::dp::test {

class MasterDriver {
 public:
  MasterDriver(fdl::InitiatorUser& u, std::uint8_t address) : m_m(u), m_addr(address) {
    m_fcb.fill(0);
  }
  explicit MasterDriver(Master& m) : MasterDriver(m, m.address()) {}

  bus::Ticks now = 0;
  bus::Ticks step = bus::kTicksPerMs / 10;  ///< time each message cycle takes
  fdl::Request req;                          ///< the request last taken
  std::vector<std::uint8_t> reply_data;      ///< storage for the confirmation's span

  /// A token visit begins `step` after the previous event. The previous visit is finished
  /// first: the station asks until the master has nothing more (it must then have nothing).
  void token() {
    if (m_visit_open) {
      EXPECT_EQ(next(), "") << "the previous token visit had more to send";
    }
    token_keep();
  }
  /// A token visit without finishing the previous one (its hold time ran out).
  void token_keep() {
    now += step;
    m_m.on_token(now, 0);
  }

  /// The master's next request of this token visit, encoded as a frame ("" if none).
  std::string next() {
    req = fdl::Request{};
    if (!m_m.next_request(fdl::Priority::High, now, req)) {
      fdl::Request low;
      EXPECT_FALSE(m_m.next_request(fdl::Priority::Low, now, low));
      m_visit_open = false;
      return "";
    }
    m_visit_open = true;
    return hex(encode_request(req));
  }

  /// Whole frame the station would send for `r` (FCB state of the responder applied).
  Bytes encode_request(const fdl::Request& r) {
    fdl::FrameSpec s;
    s.da = r.da;
    s.sa = m_addr;
    const bool fcb = fdl::fn_expects_reply(r.fn) && r.da != fdl::kBroadcast;
    const std::uint8_t st = fcb ? m_fcb[r.da] : 0;
    s.fc = fdl::make_request_fc(r.fn, fcb && st != 0, fcb && st != 1);
    s.dsap = r.dsap;
    s.ssap = r.ssap;
    s.data = r.data;
    fdl::Frame f;
    EXPECT_EQ(fdl::encode(s, f), fdl::EncodeError::None);
    return {f.bytes().begin(), f.bytes().end()};
  }

  // --- confirmations for the request last taken ---
  void confirm_sent() { confirm(make(fdl::Confirmation::Result::Sent)); }
  void confirm_sc() {
    auto c = make(fdl::Confirmation::Result::Ok);
    c.short_ack = true;
    valid_reply();
    confirm(c);
  }
  void confirm_data(fdl::ResponseStatus st, const Bytes& data) {
    auto c = make(fdl::Confirmation::Result::Ok);
    c.status = st;
    c.dsap = req.ssap;
    c.ssap = req.dsap;
    reply_data = data;
    c.data = reply_data;
    valid_reply();
    confirm(c);
  }
  void confirm_none(std::uint32_t retries = 1) {
    auto c = make(fdl::Confirmation::Result::NoResponse);
    c.retries = retries;
    if (req.da < 127) m_fcb[req.da] = 0;
    confirm(c);
  }

  // --- with real slave engines ---
  void attach(std::uint8_t address, SlaveEngine& e) { m_slaves[address] = &e; }
  void detach(std::uint8_t address) { m_slaves.erase(address); }

  /// Runs one token visit against the attached engines (unattached addresses do not answer).
  /// Returns every request frame sent.
  std::vector<std::string> visit() {
    token();
    std::vector<std::string> frames;
    for (int guard = 0; guard < 1000; ++guard) {
      const std::string f = next();
      if (f.empty()) break;
      frames.push_back(f);
      deliver();
      now += step;
    }
    return frames;
  }

  /// Hands the request last taken to the attached engine(s) and confirms with its answer.
  void deliver() {
    if (req.da == fdl::kBroadcast) {
      for (auto& [a, e] : m_slaves) {
        fdl::Reply r;
        e->on_request(indication(a), r);
      }
      confirm_sent();
      return;
    }
    const auto it = m_slaves.find(req.da);
    if (it == m_slaves.end()) {
      confirm_none();
      return;
    }
    fdl::Reply r;
    it->second->on_request(indication(req.da), r);
    switch (r.kind) {
      case fdl::Reply::Kind::None: confirm_none(); break;
      case fdl::Reply::Kind::ShortAck: confirm_sc(); break;
      case fdl::Reply::Kind::Data: confirm_data(r.status, r.data); break;
      case fdl::Reply::Kind::Status: confirm_data(r.status, {}); break;
    }
  }

  /// Runs token visits until `pred` holds (at most `max` visits); false if it never did.
  bool run_until(const std::function<bool()>& pred, int max = 100) {
    for (int i = 0; i < max; ++i) {
      if (pred()) return true;
      visit();
      now += step;
    }
    return pred();
  }

 private:
  fdl::Indication indication(std::uint8_t da) {
    fdl::Indication ind;
    ind.now = now;
    ind.sa = m_addr;
    ind.da = req.da == fdl::kBroadcast ? fdl::kBroadcast : da;
    ind.fn = req.fn;
    ind.dsap = req.dsap;
    ind.ssap = req.ssap;
    ind.data = req.data;
    return ind;
  }
  fdl::Confirmation make(fdl::Confirmation::Result r) {
    fdl::Confirmation c;
    c.now = now;
    c.tag = req.tag;
    c.da = req.da;
    c.result = r;
    return c;
  }
  void valid_reply() {
    if (req.da < 127) m_fcb[req.da] = m_fcb[req.da] == 1 ? 2 : 1;
  }
  void confirm(const fdl::Confirmation& c) { m_m.on_confirmation(c); }

  fdl::InitiatorUser& m_m;
  std::uint8_t m_addr;
  bool m_visit_open = false;
  std::array<std::uint8_t, 128> m_fcb{};  ///< 0 = next is a first frame, 1 = next FCB 0, 2 = FCB 1
  std::map<std::uint8_t, SlaveEngine*> m_slaves;
};

}  // namespace pbvbus::dp::test
