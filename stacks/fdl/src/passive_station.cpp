#include "pbvbus/fdl/passive_station.hpp"

#include <algorithm>

#include "pbvbus/fdl/decoded_frame.hpp"

namespace pbvbus::fdl {

PassiveStation::PassiveStation(std::uint8_t address, const BusParams& params, ResponderUser& user,
                               std::uint32_t tsdr)
    : m_params(params), m_user(user), m_address(address), m_own_tsdr(tsdr), m_min_tsdr(params.min_tsdr) {
  m_responder.reset();
}

std::uint32_t PassiveStation::response_delay() const {
  if (m_mutation.fixed_tsdr) [[unlikely]]  // mutant tsdr_too_late: no max TSDR bound
    return std::max(m_min_tsdr, *m_mutation.fixed_tsdr);
  if (m_own_tsdr == 0) return m_min_tsdr;
  return std::max(m_min_tsdr, std::min(m_own_tsdr, m_params.max_tsdr));
}

void PassiveStation::on_power_on(bus::Ticks now) {
  m_powered = true;
  m_min_tsdr = m_params.min_tsdr;
  m_responder.reset();
  m_pending = false;
  m_pending_at = bus::kNever;
  m_pending_address.reset();
  m_pending_min_tsdr.reset();
  m_user.on_power_on(now);
  rearm();
}

void PassiveStation::on_power_off(bus::Ticks) {
  m_powered = false;
  m_pending = false;
}

void PassiveStation::apply_pending() {
  if (!m_pending) return;
  if (m_pending_address) m_address = *m_pending_address;
  if (m_pending_min_tsdr && *m_pending_min_tsdr != 0 && !m_mutation.ignore_min_tsdr)
    m_min_tsdr = *m_pending_min_tsdr;
  m_pending = false;
  m_pending_at = bus::kNever;
  m_pending_address.reset();
  m_pending_min_tsdr.reset();
}

void PassiveStation::rearm() {
  bus::Ticks at = m_user.next_deadline();
  if (m_pending) at = std::min(at, m_pending_at);
  port().set_timer(at);
}

void PassiveStation::on_timer(bus::Ticks now) {
  if (!m_powered) return;
  if (m_pending && m_pending_at <= now) apply_pending();
  if (m_user.next_deadline() <= now) m_user.on_time(now);
  rearm();
}

void PassiveStation::on_frame(const bus::RxFrame& frame) {
  if (!m_powered) return;
  const bus::Ticks now = frame.end;
  if (m_pending && m_pending_at <= now) apply_pending();
  if (!frame.intact()) {
    ++m_stats.dropped_errors;
    return;
  }
  DecodedFrame scratch;
  const DecodedFrame& d = decode_once(frame, scratch);
  if (!d.ok()) {
    ++m_stats.dropped_errors;
    return;
  }
  const Telegram& t = d.telegram;
  // Tokens, acknowledgements and responses are no business of a passive station.
  if (!t.is_request()) return;
  if (t.da != m_address && t.da != kBroadcast) return;
  if (frame.idle_before < m_params.ticks(BusParams::kTsyn)) {
    ++m_stats.dropped_tsyn;
    return;
  }
  ++m_stats.requests;
  const RequestFn fn = fc_request_fn(t.fc);
  const bus::Ticks start = now + m_params.ticks(response_delay());

  if (fn == RequestFn::FdlStatus) {
    const Frame f = Responder::fdl_status_reply(t, m_address, StationType::Slave);
    port().transmit(start, f.bytes());
    ++m_stats.fdl_status;
    ++m_stats.replies;
    return;
  }

  const bool answer = fn_expects_reply(fn) && t.da != kBroadcast;
  if (answer && m_responder.check(t) == Responder::Check::Repeat &&
      !m_mutation.ignore_fcb) {
    ++m_stats.repeats;
    const Frame& f = m_responder.stored_reply(t.sa);
    if (!f.empty()) {
      port().transmit(start, f.bytes());
      ++m_stats.replies;
    }
    return;
  }

  Responder::clear(m_reply);
  Indication ind;
  ind.now = now;
  ind.sa = t.sa;
  ind.da = t.da;
  ind.fn = fn;
  ind.dsap = t.dsap;
  ind.ssap = t.ssap;
  ind.data = t.data;
  m_user.on_request(ind, m_reply);

  bus::Ticks reply_end = now;
  if (answer) {
    const Frame& f = m_responder.finish(t, m_address, StationType::Slave, m_reply);
    if (!f.empty()) {
      port().transmit(start, f.bytes());
      reply_end = start + bus::chars_to_ticks(f.len, m_params.baud);
      ++m_stats.replies;
    }
  }
  if (m_reply.new_address || m_reply.new_min_tsdr) {
    m_pending = true;
    m_pending_at = reply_end;
    m_pending_address = m_reply.new_address;
    m_pending_min_tsdr = m_reply.new_min_tsdr;
    if (reply_end <= now) apply_pending();
  }
  rearm();
}

}  // namespace pbvbus::fdl
