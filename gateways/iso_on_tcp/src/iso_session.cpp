#include "pbvbus/iso_on_tcp/iso_session.hpp"

#include <algorithm>

#include "pbvbus/s7/cotp.hpp"
#include "pbvbus/s7/cotp_data.hpp"
#include "pbvbus/s7/cotp_disconnect.hpp"
#include "pbvbus/s7/s7_pdu.hpp"
#include "pbvbus/s7/s7_setup.hpp"

namespace pbvbus::iso_on_tcp {

const char* to_string(SessionEnd e) {
  switch (e) {
    case SessionEnd::ClientDisconnect:
      return "client disconnect";
    case SessionEnd::Refused:
      return "connect refused";
    case SessionEnd::ChannelClosed:
      return "route closed";
    case SessionEnd::Garbage:
      return "garbage";
    case SessionEnd::QueueFull:
      return "too many pipelined jobs";
    case SessionEnd::NoAnswer:
      return "no answer";
  }
  return "?";
}

IsoSession::IsoSession(S7Router& router, const SessionLimits& limits, Hooks hooks,
                       std::uint64_t connection_id, std::uint16_t own_ref)
    : router_(router),
      limits_(limits),
      hooks_(std::move(hooks)),
      id_(connection_id),
      own_ref_(own_ref),
      reasm_(s7::kTpktDefaultMaxLength) {}

IsoSession::~IsoSession() {
  alive_.reset();
}

void IsoSession::feed(std::span<const std::uint8_t> in) {
  while (!finished_ && !in.empty()) {
    const std::size_t n = reasm_.feed(in);
    in = in.subspan(n);
    if (reasm_.error() != s7::Error::None) {
      end(SessionEnd::Garbage, std::string("TPKT framing lost (") +
                                   std::string(s7::to_string(reasm_.error())) + " at octet " +
                                   std::to_string(reasm_.error_offset()) + ")");
      return;
    }
    if (!reasm_.ready()) continue;
    const auto payload = reasm_.payload();
    const std::vector<std::uint8_t> tpdu(payload.begin(), payload.end());
    reasm_.pop();
    on_tpdu(tpdu);
  }
}

void IsoSession::on_tpdu(std::span<const std::uint8_t> tpdu) {
  const auto code = s7::cotp_code(tpdu);
  if (!code.ok()) {
    if (channel_) send_error(s7::er_cause::kNotSpecified, tpdu);
    end(SessionEnd::Garbage,
        "COTP TPDU does not decode (" + std::string(s7::to_string(code.error)) + ")");
    return;
  }
  if (!channel_) {
    if (code.value == s7::kCotpCr) {
      on_connect_request(tpdu);
      return;
    }
    end(SessionEnd::Garbage, "first TPDU is not a CR");
    return;
  }
  switch (code.value) {
    case s7::kCotpDt:
      on_data(tpdu);
      return;
    case s7::kCotpDr: {
      std::vector<std::uint8_t> dc;
      s7::append_disconnect_confirm(dc, peer_ref_, own_ref_);
      send_tpdu(dc);
      end(SessionEnd::ClientDisconnect, "client sent DR");
      return;
    }
    case s7::kCotpEr:
      end(SessionEnd::Garbage, "client sent ER");
      return;
    default:
      // A second CR, a CC or a DC on an open connection (ISO 8073 §13.12: a TPDU of a type that
      // is not allowed here is answered with an ER, cause "invalid TPDU type").
      send_error(s7::er_cause::kInvalidTpduType, tpdu);
      end(SessionEnd::Garbage, "TPDU not allowed on an open connection");
      return;
  }
}

void IsoSession::on_connect_request(std::span<const std::uint8_t> tpdu) {
  const auto cr = s7::decode_connect_request(tpdu);
  if (!cr.ok()) {
    send_error(s7::er_cause::kInvalidParameterValue, tpdu);
    end(SessionEnd::Garbage, "CR does not decode (" + std::string(s7::to_string(cr.error)) + ")");
    return;
  }
  peer_ref_ = cr.value.src_ref;
  calling_tsap_.assign(cr.value.calling_tsap.begin(), cr.value.calling_tsap.end());
  called_tsap_.assign(cr.value.called_tsap.begin(), cr.value.called_tsap.end());
  RouteRequest req;
  req.calling_tsap = calling_tsap_;
  req.called_tsap = called_tsap_;
  req.calling = s7::parse_s7_tsap(calling_tsap_);
  req.called = s7::parse_s7_tsap(called_tsap_);
  req.connection_id = id_;
  RouteResult route = router_.open(req);
  if (!route.channel) {
    std::vector<std::uint8_t> dr;
    s7::append_disconnect_request(dr, peer_ref_, own_ref_, route.dr_reason);
    send_tpdu(dr);
    end(SessionEnd::Refused,
        "CR refused (DR reason " + std::to_string(route.dr_reason) + "): " + route.why);
    return;
  }
  channel_ = std::move(route.channel);
  std::weak_ptr<bool> alive = alive_;
  channel_->on_closed([this, alive](const std::string& reason) {
    if (!alive.expired()) on_channel_closed(reason);
  });
  const s7::ConnectTpdu cc = s7::confirm_for(cr.value, own_ref_, limits_.max_tpdu_code);
  // The confirmed size bounds what the door sends. What it takes stays bounded by class 0's
  // 2048 + 4 (the reassembler's default): libnodave asks for TPDU 512 and Setup Communication
  // PDU 960 on the same connection (protocol-facts §H.4, tools-and-formats §3.2) and sends a
  // PDU as one DT, so holding clients to the confirmed size would close such connections.
  tpdu_size_ = cc.tpdu_size_code != 0 ? s7::tpdu_size_octets(cc.tpdu_size_code) : 128;
  std::vector<std::uint8_t> out;
  s7::append_connect(out, cc);  // cannot fail: sizes and TSAPs come from a decoded CR
  send_tpdu(out);
}

void IsoSession::on_data(std::span<const std::uint8_t> tpdu) {
  const auto dt = s7::decode_data(tpdu);
  if (!dt.ok()) {
    send_error(s7::er_cause::kInvalidParameterValue, tpdu);
    end(SessionEnd::Garbage, "DT does not decode (" + std::string(s7::to_string(dt.error)) + ")");
    return;
  }
  if (tsdu_.size() + dt.value.user_data.size() > limits_.max_pdu) {
    end(SessionEnd::Garbage, "S7 PDU longer than " + std::to_string(limits_.max_pdu) + " octets");
    return;
  }
  tsdu_.insert(tsdu_.end(), dt.value.user_data.begin(), dt.value.user_data.end());
  if (!dt.value.eot) return;
  std::vector<std::uint8_t> pdu;
  pdu.swap(tsdu_);
  on_job(std::move(pdu));
}

void IsoSession::on_job(std::vector<std::uint8_t> pdu) {
  const auto h = s7::decode_s7_pdu(pdu);
  if (!h.ok()) {
    end(SessionEnd::Garbage, "not an S7 PDU (" + std::string(s7::to_string(h.error)) + ")");
    return;
  }
  if (h.value.header.type != s7::kS7Job && h.value.header.type != s7::kS7Userdata) {
    end(SessionEnd::Garbage,
        "S7 PDU of type " + std::to_string(h.value.header.type) + " from a client");
    return;
  }
  ++jobs_;
  capture(PduDirection::FromClient, pdu);
  if (in_flight_ < amq_ && queue_.empty()) {
    dispatch(std::move(pdu));
    return;
  }
  if (queue_.size() >= limits_.max_queued_jobs) {
    end(SessionEnd::QueueFull, std::to_string(in_flight_) + " jobs outstanding (AmQ " +
                                   std::to_string(amq_) + ") and " + std::to_string(queue_.size()) +
                                   " waiting (max_queued_jobs): the client pipelines more "
                                   "jobs than the connection allows");
    return;
  }
  queue_.push_back(std::move(pdu));
  queued_max_ = std::max(queued_max_, queue_.size());
}

void IsoSession::dispatch(std::vector<std::uint8_t> pdu) {
  ++in_flight_;
  std::weak_ptr<bool> alive = alive_;
  channel_->request(std::move(pdu), [this, alive](std::vector<std::uint8_t> answer) {
    if (!alive.expired()) on_answer(std::move(answer));
  });
}

void IsoSession::drain() {
  // A channel that answers at once calls on_answer() from inside dispatch(): the outer loop
  // goes on, so a long queue never recurses.
  if (draining_) return;
  draining_ = true;
  while (!finished_ && channel_ && in_flight_ < amq_ && !queue_.empty()) {
    std::vector<std::uint8_t> next = std::move(queue_.front());
    queue_.pop_front();
    dispatch(std::move(next));
  }
  draining_ = false;
}

void IsoSession::on_answer(std::vector<std::uint8_t> answer) {
  if (finished_) return;
  if (in_flight_ > 0) --in_flight_;
  if (answer.empty()) {
    end(SessionEnd::NoAnswer, "the CPU answered a job with nothing (not an S7 job)");
    return;
  }
  ++answers_;
  capture(PduDirection::ToClient, answer);
  // The Setup Communication answer fixes how many jobs may be outstanding (max AmQ called).
  if (const auto h = s7::decode_s7_pdu(answer); h.ok() && h.value.header.type == s7::kS7AckData &&
                                                !h.value.params.empty() &&
                                                h.value.params[0] == s7::kFnSetupCommunication) {
    if (const auto setup = s7::decode_setup_communication(h.value); setup.ok())
      amq_ = std::max<std::size_t>(1, setup.value.max_amq_called);
  }
  // One S7 PDU in as many DTs as the confirmed TPDU size needs (ISO 8073 §13.7: EOT on the last).
  const std::size_t room = tpdu_size_ - s7::kDtHeaderLength;
  std::span<const std::uint8_t> rest(answer);
  std::vector<std::uint8_t> tpdu;
  do {
    const std::size_t n = std::min(room, rest.size());
    tpdu.clear();
    s7::append_data(tpdu, rest.first(n), n == rest.size());
    send_tpdu(tpdu);
    rest = rest.subspan(n);
  } while (!rest.empty() && !finished_);
  drain();
}

void IsoSession::on_channel_closed(const std::string& reason) {
  if (finished_) return;
  std::vector<std::uint8_t> dr;
  s7::append_disconnect_request(dr, peer_ref_, own_ref_, s7::dr_reason::kNotSpecified);
  send_tpdu(dr);
  end(SessionEnd::ChannelClosed, "route closed: " + reason);
}

void IsoSession::send_tpdu(const std::vector<std::uint8_t>& tpdu) {
  std::vector<std::uint8_t> out;
  out.reserve(tpdu.size() + s7::kTpktHeaderLength);
  if (s7::append_tpkt(out, tpdu) != s7::Error::None) return;  // TPDUs here are < 64 KiB
  if (hooks_.send) hooks_.send(out);
}

void IsoSession::send_error(std::uint8_t cause, std::span<const std::uint8_t> tpdu) {
  std::vector<std::uint8_t> er;
  s7::append_error_tpdu(er, peer_ref_, cause, tpdu);
  send_tpdu(er);
}

void IsoSession::capture(PduDirection d, std::span<const std::uint8_t> pdu) {
  if (!hooks_.capture) return;
  PduRecord r;
  r.direction = d;
  r.connection_id = id_;
  r.calling_tsap = calling_tsap_;
  r.called_tsap = called_tsap_;
  r.wall = std::chrono::system_clock::now();
  r.pdu = pdu;
  hooks_.capture(r);
}

void IsoSession::end(SessionEnd e, const std::string& why) {
  if (finished_) return;
  finished_ = true;
  queue_.clear();
  if (hooks_.finish) hooks_.finish(e, why);
}

}  // namespace pbvbus::iso_on_tcp
