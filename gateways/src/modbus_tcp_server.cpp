#include "pbvbus/gateways/modbus_tcp_server.hpp"

#include <array>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>
#include <cstring>
#include <list>
#include <vector>

#include "pbvbus/gateways/modbus_frame.hpp"
#include "pbvbus/tcp_door/tcp_accept.hpp"
#include "pbvbus/tcp_door/throttled_log.hpp"

namespace pbvbus::gateways {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {
/// Read buffer per connection: many pipelined requests per read, and always room for one whole
/// ADU after compaction.
constexpr std::size_t kReadBuffer = 4096;
static_assert(kReadBuffer >= 2 * kModbusTcpMaxAdu);
}  // namespace

struct ModbusTcpServer::Impl : std::enable_shared_from_this<ModbusTcpServer::Impl> {
  struct Connection;
  Impl(asio::io_context& i, ModbusHandler& h, ModbusTcpOptions o)
      : io(i), handler(h), opt(std::move(o)), acceptor(i), backoff(i, "modbus_tcp", opt.log),
        evictions(opt.log) {}

  void start();
  void accept();
  void admit(tcp::socket s);
  void evict_longest_idle();
  void close();
  void forget(std::list<std::shared_ptr<Connection>>::iterator it);

  asio::io_context& io;
  ModbusHandler& handler;
  ModbusTcpOptions opt;
  tcp::acceptor acceptor;
  tcp_accept::AcceptBackoff backoff;
  ThrottledLog evictions;
  std::string who = "modbus_tcp";  // starts each logged line: "modbus_tcp HOST:PORT"
  std::uint16_t port = 0;
  ModbusDoorStats stats;
  bool closed = false;
  std::list<std::shared_ptr<Connection>> conns;
};

struct ModbusTcpServer::Impl::Connection : std::enable_shared_from_this<Connection> {
  Connection(Impl* s, tcp::socket so) : srv(s), sock(std::move(so)), idle(s->io) {}

  void start();
  void read();
  void process();
  void serve(const MbapDecoded& d, const std::uint8_t* adu);
  void flush();
  void arm_idle(Clock::time_point at);
  void close(bool bad);
  void detach();

  Impl* srv;  // null once closed: queued handlers then do nothing
  tcp::socket sock;
  asio::steady_timer idle;
  std::list<std::shared_ptr<Connection>>::iterator self;
  std::array<std::uint8_t, kReadBuffer> in{};
  std::size_t begin = 0;
  std::size_t end = 0;
  std::vector<std::uint8_t> out_pending;
  std::vector<std::uint8_t> out_flight;
  bool writing = false;
  bool eof = false;  // the client half-closed; close once the responses are out
  Clock::time_point last_request{};
};

void ModbusTcpServer::Impl::start() {
  const tcp::endpoint ep(asio::ip::make_address(opt.address), opt.port);
  acceptor.open(ep.protocol());
  acceptor.set_option(tcp::acceptor::reuse_address(true));
  acceptor.bind(ep);
  acceptor.listen(tcp_accept::kListenBacklog);
  port = acceptor.local_endpoint().port();
  who = "modbus_tcp " + opt.address + ":" + std::to_string(port);
  backoff.set_who(who);
  accept();
}

void ModbusTcpServer::Impl::accept() {
  std::weak_ptr<Impl> w = shared_from_this();
  acceptor.async_accept([w](const boost::system::error_code& ec, tcp::socket s) {
    auto self = w.lock();
    if (!self || self->closed || ec == asio::error::operation_aborted) return;
    if (ec) {
      // EMFILE & co.: the connection stays pending, so accepting again at once would fail at
      // once, forever. Pause, then try again (tcp_accept.hpp).
      ++self->stats.accept_pauses;
      self->backoff.failed(ec.value(), [w] {
        if (auto p = w.lock(); p && !p->closed) p->accept();
      });
      return;
    }
    self->backoff.succeeded();
    self->admit(std::move(s));
    if (!self->closed) self->accept();
  });
}

void ModbusTcpServer::Impl::admit(tcp::socket s) {
  if (opt.max_clients == 0) {
    // Accept and close at once, so the client learns it at connect time instead of hanging in
    // the listen backlog.
    ++stats.clients_refused;
    boost::system::error_code ignore;
    s.close(ignore);
    return;
  }
  while (conns.size() >= opt.max_clients) evict_longest_idle();
  auto c = std::make_shared<Connection>(this, std::move(s));
  conns.push_front(c);
  c->self = conns.begin();
  ++stats.clients_accepted;
  stats.clients_now = conns.size();
  c->start();
}

void ModbusTcpServer::Impl::evict_longest_idle() {
  // The list runs newest first: on equal times the older connection (later in the list) goes.
  std::shared_ptr<Connection> victim;
  for (const auto& c : conns)
    if (!victim || c->last_request <= victim->last_request) victim = c;
  boost::system::error_code ec;
  const auto peer = victim->sock.remote_endpoint(ec);
  const auto idle_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - victim->last_request);
  ++stats.clients_evicted;
  evictions(who + ": evicted the longest-idle client " +
            (ec ? std::string("(peer unknown)") : peer.address().to_string() + ":" +
                                                      std::to_string(peer.port())) +
            " (no request for " + std::to_string(idle_ms.count()) + " ms) for a new one: " +
            std::to_string(conns.size()) + " clients open (max_clients)");
  victim->close(false);
}

void ModbusTcpServer::Impl::forget(std::list<std::shared_ptr<Connection>>::iterator it) {
  conns.erase(it);
  stats.clients_now = conns.size();
}

void ModbusTcpServer::Impl::close() {
  if (closed) return;
  closed = true;
  boost::system::error_code ignore;
  acceptor.close(ignore);
  for (auto& c : conns) c->detach();
  conns.clear();
  stats.clients_now = 0;
}

void ModbusTcpServer::Impl::Connection::start() {
  boost::system::error_code ignore;
  sock.set_option(tcp::no_delay(true), ignore);
  // A small kernel send buffer: the door's own bound (max_output) then applies after some
  // 100 KB built for a client that does not read, not after megabytes (tcp_accept.hpp).
  sock.set_option(asio::socket_base::send_buffer_size(tcp_accept::kKernelSendBuffer), ignore);
  sock.non_blocking(true, ignore);  // for the first, immediate write attempt in flush()
  last_request = Clock::now();
  if (srv->opt.idle_timeout.count() > 0) arm_idle(last_request + srv->opt.idle_timeout);
  read();
}

void ModbusTcpServer::Impl::Connection::arm_idle(Clock::time_point at) {
  idle.expires_at(at);
  idle.async_wait([c = shared_from_this()](const boost::system::error_code& ec) {
    if (ec || !c->srv) return;
    const auto deadline = c->last_request + c->srv->opt.idle_timeout;
    if (Clock::now() >= deadline)
      c->close(true);  // no complete request for the whole timeout: stalled or half-open
    else
      c->arm_idle(deadline);
  });
}

void ModbusTcpServer::Impl::Connection::read() {
  sock.async_read_some(
      asio::buffer(in.data() + end, in.size() - end),
      [c = shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
        if (!c->srv) return;
        if (ec == asio::error::eof && (c->writing || !c->out_pending.empty())) {
          // Half-closed after its last request: finish sending, then close.
          c->eof = true;
          return;
        }
        if (ec) {
          c->close(false);  // EOF or reset: the client left
          return;
        }
        c->end += n;
        c->process();
      });
}

void ModbusTcpServer::Impl::Connection::process() {
  std::size_t served = 0;
  while (srv) {
    const std::size_t avail = end - begin;
    if (avail < kMbapHeaderLen) break;
    const MbapDecoded d = decode_mbap(std::span<const std::uint8_t>(in.data() + begin, avail));
    if (!d.ok()) {
      ++srv->stats.bad_frames;
      flush();
      close(true);
      return;
    }
    if (avail < d.adu_len()) break;
    if (served == srv->opt.max_requests_per_turn) {
      // Fairness: let the bus's timer and the other connections run, then go on.
      flush();
      if (srv)
        asio::post(srv->io, [c = shared_from_this()] {
          if (c->srv) c->process();
        });
      return;
    }
    serve(d, in.data() + begin);
    begin += d.adu_len();
    ++served;
  }
  if (!srv) return;
  if (served > 0) last_request = Clock::now();
  flush();
  if (!srv) return;
  if (begin == end) {
    begin = end = 0;
  } else if (in.size() - end < kModbusTcpMaxAdu) {
    std::memmove(in.data(), in.data() + begin, end - begin);
    end -= begin;
    begin = 0;
  }
  read();
}

void ModbusTcpServer::Impl::Connection::serve(const MbapDecoded& d, const std::uint8_t* adu) {
  std::array<std::uint8_t, kModbusMaxPdu> rsp{};
  ++srv->stats.requests;
  const std::span<const std::uint8_t> pdu(adu + kMbapHeaderLen, d.pdu_len());
  std::size_t n = srv->handler.handle(d.header.unit, pdu, rsp, false);
  if (n == 0) {
    ++srv->stats.no_reply;
    return;
  }
  if (n > kModbusMaxPdu) {  // a handler bug must not overrun: answer "server device failure"
    rsp[0] = static_cast<std::uint8_t>(pdu[0] | 0x80);
    rsp[1] = kExServerDeviceFailure;
    n = 2;
  }
  if (rsp[0] & 0x80) ++srv->stats.exceptions;
  const std::size_t at = out_pending.size();
  out_pending.resize(at + kMbapHeaderLen + n);
  encode_tcp_adu(d.header.transaction_id, d.header.unit,
                 std::span<const std::uint8_t>(rsp.data(), n),
                 std::span<std::uint8_t>(out_pending.data() + at, kMbapHeaderLen + n));
  if (out_pending.size() + out_flight.size() > srv->opt.max_output) close(true);
}

void ModbusTcpServer::Impl::Connection::flush() {
  if (!srv || writing || out_pending.empty()) return;
  boost::system::error_code ec;
  const std::size_t n = sock.write_some(asio::buffer(out_pending), ec);
  if (ec && ec != asio::error::would_block && ec != asio::error::try_again) {
    close(false);
    return;
  }
  out_pending.erase(out_pending.begin(), out_pending.begin() + static_cast<std::ptrdiff_t>(n));
  if (out_pending.empty()) return;
  std::swap(out_pending, out_flight);
  writing = true;
  asio::async_write(sock, asio::buffer(out_flight),
                    [c = shared_from_this()](const boost::system::error_code& wec, std::size_t) {
                      c->writing = false;
                      if (!c->srv) return;
                      if (wec) {
                        c->close(false);
                        return;
                      }
                      c->out_flight.clear();
                      c->flush();
                      if (c->srv && c->eof && !c->writing && c->out_pending.empty())
                        c->close(false);
                    });
}

void ModbusTcpServer::Impl::Connection::close(bool bad) {
  if (!srv) return;
  Impl* s = srv;
  if (bad) ++s->stats.clients_closed_bad;
  auto keep = shared_from_this();  // forget() drops the list's reference
  detach();
  s->forget(self);
}

void ModbusTcpServer::Impl::Connection::detach() {
  srv = nullptr;
  boost::system::error_code ignore;
  idle.cancel();
  sock.close(ignore);
}

ModbusTcpServer::ModbusTcpServer(asio::io_context& io, ModbusHandler& handler, ModbusTcpOptions opt)
    : m(std::make_shared<Impl>(io, handler, std::move(opt))) {
  m->start();
}

ModbusTcpServer::~ModbusTcpServer() {
  m->close();
}

std::uint16_t ModbusTcpServer::port() const {
  return m->port;
}
const ModbusDoorStats& ModbusTcpServer::stats() const {
  return m->stats;
}
std::uint64_t ModbusTcpServer::rejected() const {
  return m->stats.clients_refused;
}
void ModbusTcpServer::close() {
  m->close();
}

}  // namespace pbvbus::gateways
