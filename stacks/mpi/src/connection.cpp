// One end of an MPI connection (protocol-facts.md §H.3; decisions in docs/mpi.md).
#include "pbvbus/mpi/connection.hpp"

namespace pbvbus::mpi {

std::string_view to_string(State s) {
  switch (s) {
    case State::Closed: return "closed";
    case State::ConnectSent: return "connect sent";
    case State::ConfirmSent: return "confirm sent";
    case State::AckSent: return "ack sent";
    case State::Connected: return "connected";
    case State::Disconnecting: return "disconnecting";
  }
  return "?";
}

std::string_view to_string(RequestError e) {
  switch (e) {
    case RequestError::None: return "ok";
    case RequestError::WrongState: return "not possible in this state";
    case RequestError::Busy: return "a data message is waiting for its ack";
    case RequestError::EmptyData: return "data message without an S7 PDU";
    case RequestError::TooLong: return "S7 PDU too long for one data message";
  }
  return "?";
}

Connection::Connection(Role role, std::uint8_t peer, std::uint8_t local_sap, ConnectionTiming timing)
    : role_(role), peer_(peer), local_sap_(local_sap), timing_(timing) {}

Connection Connection::initiator(std::uint8_t peer, std::uint8_t local_sap, ConnectionTiming timing,
                                 const ConnectParams& params) {
  Connection c(Role::Initiator, peer, local_sap, timing);
  c.params_ = params;
  return c;
}

Connection Connection::responder(std::uint8_t peer, std::uint8_t peer_sap, std::uint8_t local_sap,
                                 ConnectionTiming timing) {
  Connection c(Role::Responder, peer, local_sap, timing);
  c.peer_sap_ = peer_sap;
  return c;
}

void Connection::emit(const Pdu& pdu, std::uint8_t dsap, Outbox& out) {
  Outgoing f;
  f.peer = peer_;
  f.dsap = dsap;
  f.ssap = local_sap_;
  f.type = pdu.type;
  encode(pdu, f.pdu);  // every PDU built here is valid: data length is checked in send_data()
  out.frames.push_back(f);
  unconfirmed_.push_back(Pending{pdu.type, generation_});
}

void Connection::event(EventKind kind, Outbox& out, Reason reason, std::uint8_t nr) {
  Event e;
  e.kind = kind;
  e.local_sap = local_sap_;
  e.peer = peer_;
  e.peer_sap = peer_sap_.value_or(0);
  e.message_number = nr;
  e.reason = reason;
  out.events.push_back(std::move(e));
}

void Connection::close(EventKind kind, Reason reason, Outbox& out) {
  state_ = State::Closed;
  deadline_.reset();
  tx_outstanding_.reset();
  event(kind, out, reason);
}

void Connection::abort(Reason reason, bool tell_peer, Outbox& out) {
  if (tell_peer && peer_sap_) emit(Pdu::disconnect_request(), *peer_sap_, out);
  // The release frame's FDL result belongs to the closed connection: make it stale.
  ++generation_;
  close(EventKind::Broken, reason, out);
}

RequestError Connection::connect(bus::Ticks now, Outbox& out) {
  if (role_ != Role::Initiator || state_ != State::Closed) return RequestError::WrongState;
  ++generation_;
  peer_sap_.reset();
  tx_next_ = 0;  // §H.3: libnodave's counter starts at 0
  tx_outstanding_.reset();
  tx_last_acked_.reset();
  rx_last_.reset();
  emit(Pdu::connect_request(params_), kConnectSap, out);
  state_ = State::ConnectSent;
  deadline_ = now + timing_.connect_timeout;
  return RequestError::None;
}

RequestError Connection::accept(bus::Ticks now, const Pdu& cr, Outbox& out) {
  if (role_ != Role::Responder || state_ != State::Closed || !peer_sap_ ||
      cr.type != PduType::ConnectRequest) {
    return RequestError::WrongState;
  }
  params_ = cr.connect_params;
  emit(Pdu::connect_confirm(params_), *peer_sap_, out);
  state_ = State::ConfirmSent;
  deadline_ = now + timing_.connect_timeout;
  event(EventKind::ConnectIndication, out);
  return RequestError::None;
}

RequestError Connection::send_data(bus::Ticks now, std::span<const std::uint8_t> s7_pdu, Outbox& out) {
  if (state_ != State::Connected) return RequestError::WrongState;
  if (tx_outstanding_) return RequestError::Busy;
  if (s7_pdu.empty()) return RequestError::EmptyData;
  if (s7_pdu.size() > kMaxDataLen) return RequestError::TooLong;
  emit(Pdu::data_message(tx_next_, s7_pdu), *peer_sap_, out);
  tx_outstanding_ = tx_next_;
  tx_next_ = next_message_number(tx_next_);
  deadline_ = now + timing_.ack_timeout;
  return RequestError::None;
}

RequestError Connection::disconnect(bus::Ticks /*now*/, Outbox& out) {
  switch (state_) {
    case State::Closed:
    case State::Disconnecting:
      return RequestError::WrongState;
    case State::ConnectSent:
      // The peer's SAP is not known yet: nothing to address a disconnect request to. A confirm
      // that still arrives finds the connection closed and is answered RS.
      ++generation_;
      close(EventKind::Disconnected, Reason::Local, out);
      return RequestError::None;
    default:
      emit(Pdu::disconnect_request(), *peer_sap_, out);
      state_ = State::Disconnecting;
      deadline_.reset();
      tx_outstanding_.reset();
      return RequestError::None;
  }
}

void Connection::release(Reason reason, Outbox& out) {
  if (state_ == State::Closed) return;
  ++generation_;
  close(EventKind::Disconnected, reason, out);
}

bool Connection::matches(const Received& r) const {
  if (state_ == State::Closed || r.peer != peer_ || r.dsap != local_sap_) return false;
  if (state_ == State::ConnectSent) return true;
  return peer_sap_ && r.ssap == *peer_sap_;
}

FdlReply Connection::on_frame(bus::Ticks now, const Received& r, Outbox& out) {
  if (!matches(r)) return FdlReply::SapNotActivated;
  Pdu p;
  if (decode(r.pdu, p) != DecodeError::None) {
    ++ignored_;
    return FdlReply::UserError;
  }
  if (p.type == PduType::DisconnectRequest) {
    // The peer releases the connection in any state (§H.3 step 7); no MPI reply (docs/mpi.md).
    ++generation_;
    close(EventKind::Disconnected, Reason::ByPeer, out);
    return FdlReply::Ack;
  }
  switch (state_) {
    case State::ConnectSent:
      if (p.type != PduType::ConnectConfirm) break;
      peer_sap_ = r.ssap;  // §H.3: the confirm's SSAP is the PLC-side SAP from now on
      emit(Pdu::connection_ack(), *peer_sap_, out);
      state_ = State::AckSent;
      deadline_ = now + timing_.connect_timeout;
      return FdlReply::Ack;
    case State::AckSent:
      if (p.type != PduType::ConnectionAck) break;
      state_ = State::Connected;
      deadline_.reset();
      event(EventKind::Connected, out);
      return FdlReply::Ack;
    case State::ConfirmSent:
      if (p.type != PduType::ConnectionAck) break;
      emit(Pdu::connection_ack(), *peer_sap_, out);  // §H.3 step 4
      state_ = State::Connected;
      deadline_.reset();
      event(EventKind::Connected, out);
      return FdlReply::Ack;
    case State::Connected:
      if (p.type == PduType::Data) {
        on_data(p, out);
        return FdlReply::Ack;
      }
      if (p.type == PduType::DataAck) {
        on_data_ack(p, out);
        return FdlReply::Ack;
      }
      break;
    case State::Disconnecting:
    case State::Closed:
      break;
  }
  ++ignored_;  // taken by FDL, but nothing this state expects
  return FdlReply::Ack;
}

void Connection::on_data(const Pdu& p, Outbox& out) {
  const std::uint8_t nr = p.message_number;
  if (rx_last_ && nr == *rx_last_) {
    emit(Pdu::data_ack(nr), *peer_sap_, out);  // a repeat: our ack was lost; ack it again
    return;
  }
  if (rx_last_ && nr != next_message_number(*rx_last_)) {
    abort(Reason::SequenceError, true, out);
    return;
  }
  rx_last_ = nr;
  emit(Pdu::data_ack(nr), *peer_sap_, out);  // §H.3 step 6
  Event e;
  e.kind = EventKind::DataIndication;
  e.local_sap = local_sap_;
  e.peer = peer_;
  e.peer_sap = *peer_sap_;
  e.message_number = nr;
  e.data.assign(p.data.begin(), p.data.end());
  out.events.push_back(std::move(e));
}

void Connection::on_data_ack(const Pdu& p, Outbox& out) {
  const std::uint8_t nr = p.message_number;
  if (tx_outstanding_ && nr == *tx_outstanding_) {
    tx_outstanding_.reset();
    tx_last_acked_ = nr;
    deadline_.reset();
    event(EventKind::DataConfirm, out, Reason::None, nr);
    return;
  }
  if (!tx_outstanding_ && tx_last_acked_ && nr == *tx_last_acked_) {
    ++ignored_;  // the same ack again
    return;
  }
  abort(Reason::SequenceError, true, out);
}

void Connection::on_fdl_result(bus::Ticks /*now*/, FdlResult result, Outbox& out) {
  if (unconfirmed_.empty()) return;
  const Pending p = unconfirmed_.front();
  unconfirmed_.pop_front();
  if (p.generation != generation_ || state_ == State::Closed) return;
  switch (result) {
    case FdlResult::Delivered:
      if (p.type == PduType::DisconnectRequest && state_ == State::Disconnecting) {
        close(EventKind::Disconnected, Reason::Local, out);
      }
      return;
    case FdlResult::Refused:
      if (p.type == PduType::ConnectRequest && state_ == State::ConnectSent) {
        close(EventKind::ConnectRefused, Reason::PeerRefused, out);
      } else {
        abort(Reason::PeerRefused, false, out);
      }
      return;
    case FdlResult::NoAnswer:
      abort(Reason::PeerGone, false, out);
      return;
  }
}

void Connection::on_timer(bus::Ticks now, Outbox& out) {
  if (!deadline_ || now < *deadline_) return;
  switch (state_) {
    case State::ConnectSent:
    case State::AckSent:
    case State::ConfirmSent:
      abort(Reason::ConnectTimeout, true, out);
      return;
    case State::Connected:
      if (tx_outstanding_) abort(Reason::AckTimeout, true, out);
      return;
    case State::Disconnecting:
    case State::Closed:
      deadline_.reset();
      return;
  }
}

}  // namespace pbvbus::mpi
