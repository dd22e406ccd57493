// The CPU side's MPI connection resources (protocol-facts.md §H.3; decisions in docs/mpi.md).
#include "pbvbus/mpi/connection_pool.hpp"

#include <algorithm>

namespace pbvbus::mpi {

namespace {
constexpr std::uint8_t kMaxSap = 63;  // §B.2: SAP numbers 0..63
}

void ConnectionPool::sweep() {
  std::erase_if(slots_, [](const Connection& c) {
    return c.state() == State::Closed && c.unconfirmed_frames() == 0;
  });
}

std::size_t ConnectionPool::open_connections() const {
  return static_cast<std::size_t>(std::count_if(
      slots_.begin(), slots_.end(), [](const Connection& c) { return c.state() != State::Closed; }));
}

Connection* ConnectionPool::open_on(std::uint8_t local_sap) {
  for (Connection& c : slots_) {
    if (c.local_sap() == local_sap && c.state() != State::Closed) return &c;
  }
  return nullptr;
}

const Connection* ConnectionPool::find(std::uint8_t local_sap) const {
  for (const Connection& c : slots_) {
    if (c.local_sap() == local_sap && c.state() != State::Closed) return &c;
  }
  return nullptr;
}

std::optional<std::uint8_t> ConnectionPool::free_sap() const {
  // SAP 0 is the connection-management SAP of connect requests (§H.3), never a connection's.
  for (unsigned sap = std::max<unsigned>(config_.first_sap, kConnectSap + 1u); sap <= kMaxSap; ++sap) {
    const bool used = std::any_of(slots_.begin(), slots_.end(),
                                  [&](const Connection& c) { return c.local_sap() == sap; });
    if (!used) return static_cast<std::uint8_t>(sap);
  }
  return std::nullopt;
}

FdlReply ConnectionPool::on_frame(bus::Ticks now, const Received& r, Outbox& out) {
  sweep();
  if (r.dsap != kConnectSap) {
    for (Connection& c : slots_) {
      if (c.matches(r)) {
        const FdlReply reply = c.on_frame(now, r, out);
        sweep();
        return reply;
      }
    }
    return FdlReply::SapNotActivated;
  }
  Pdu cr;
  if (decode(r.pdu, cr) != DecodeError::None) return FdlReply::UserError;
  if (cr.type != PduType::ConnectRequest) return FdlReply::SapNotActivated;
  for (Connection& c : slots_) {
    if (c.state() != State::Closed && c.peer() == r.peer && c.peer_sap() == r.ssap) {
      c.release(Reason::PeerReconnected, out);  // the peer restarted: its old connection is gone
    }
  }
  sweep();
  const std::optional<std::uint8_t> sap = free_sap();
  if (open_connections() >= config_.max_connections || !sap) return FdlReply::NoResources;
  slots_.push_back(Connection::responder(r.peer, r.ssap, *sap, config_.timing));
  slots_.back().accept(now, cr, out);
  return FdlReply::Ack;
}

void ConnectionPool::on_fdl_result(bus::Ticks now, std::uint8_t local_sap, FdlResult result, Outbox& out) {
  for (Connection& c : slots_) {
    if (c.local_sap() == local_sap && c.unconfirmed_frames() > 0) {
      c.on_fdl_result(now, result, out);
      break;
    }
  }
  sweep();
}

void ConnectionPool::on_timer(bus::Ticks now, Outbox& out) {
  for (Connection& c : slots_) {
    if (c.deadline() && *c.deadline() <= now) c.on_timer(now, out);
  }
  sweep();
}

std::optional<bus::Ticks> ConnectionPool::deadline() const {
  std::optional<bus::Ticks> d;
  for (const Connection& c : slots_) {
    if (c.deadline() && (!d || *c.deadline() < *d)) d = c.deadline();
  }
  return d;
}

RequestError ConnectionPool::send_data(bus::Ticks now, std::uint8_t local_sap,
                                       std::span<const std::uint8_t> s7_pdu, Outbox& out) {
  Connection* c = open_on(local_sap);
  if (!c) return RequestError::WrongState;
  return c->send_data(now, s7_pdu, out);
}

RequestError ConnectionPool::disconnect(bus::Ticks now, std::uint8_t local_sap, Outbox& out) {
  Connection* c = open_on(local_sap);
  if (!c) return RequestError::WrongState;
  const RequestError e = c->disconnect(now, out);
  sweep();
  return e;
}

}  // namespace pbvbus::mpi
