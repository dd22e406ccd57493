#include "pbvbus/tcp_door/tcp_accept.hpp"

#include <cstring>

namespace pbvbus::gateways::tcp_accept {

void cap_send_buffer(int fd) {
  const int sndbuf = kKernelSendBuffer;
  ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &sndbuf, sizeof sndbuf);
}

AcceptBackoff::AcceptBackoff(boost::asio::io_context& io, std::string who, DoorLog log)
    : m_timer(io), m_who(std::move(who)), m_log(std::move(log)) {}

AcceptBackoff::~AcceptBackoff() {
  m_alive.reset();
  m_timer.cancel();
}

void AcceptBackoff::failed(int err, std::function<void()> retry) {
  if (!m_in_episode) {
    m_in_episode = true;
    m_since = std::chrono::steady_clock::now();
    ++m_episodes;
    if (m_log)
      m_log(m_who + ": accept failed: " + std::strerror(err) + "; new clients wait, retrying every " +
            std::to_string(kAcceptRetry.count()) + " ms");
  }
  ++m_pauses;
  std::weak_ptr<bool> alive = m_alive;
  m_timer.expires_after(kAcceptRetry);
  // A completed wait may already be queued when the owner goes: `alive` says so.
  m_timer.async_wait([alive, retry = std::move(retry)](const boost::system::error_code& ec) {
    if (ec || alive.expired()) return;
    retry();
  });
}

void AcceptBackoff::succeeded() {
  if (!m_in_episode) return;
  m_in_episode = false;
  if (m_log) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                        std::chrono::steady_clock::now() - m_since)
                        .count();
    m_log(m_who + ": accepting again after " + std::to_string(ms) + " ms");
  }
}

}  // namespace pbvbus::gateways::tcp_accept
