// The session handle (h_s7_session.hpp): every call goes to the model, which owns the state.
#include "pbvbus/s7h/h_s7_session.hpp"

#include "pbvbus/s7h/h_system.hpp"

namespace pbvbus::devices {

std::string_view to_string(S7Route r) {
  switch (r) {
    case S7Route::AdHoc: return "ad-hoc";
    case S7Route::Standard: return "standard";
    case S7Route::FaultTolerant: return "fault-tolerant";
    case S7Route::Routing: return "routing";
  }
  return "?";
}

std::string_view to_string(S7CloseReason r) {
  switch (r) {
    case S7CloseReason::None: return "alive";
    case S7CloseReason::Refused: return "refused";
    case S7CloseReason::CpuLost: return "CPU lost";
    case S7CloseReason::LinkUp: return "link-up (R8)";
    case S7CloseReason::ConnectionLost: return "connection lost";
    case S7CloseReason::Switchover: return "switchover (routing)";
    case S7CloseReason::Closed: return "closed";
    case S7CloseReason::ProtocolError: return "protocol error";
  }
  return "?";
}

HS7Session& HS7Session::operator=(HS7Session&& o) noexcept {
  if (this != &o) {
    if (m_model != nullptr) m_model->s7_release(m_id);
    m_model = o.m_model;
    m_id = o.m_id;
    o.m_model = nullptr;
  }
  return *this;
}

HS7Session::~HS7Session() {
  if (m_model != nullptr) m_model->s7_release(m_id);
}

std::vector<std::uint8_t> HS7Session::handle(std::span<const std::uint8_t> pdu) {
  return m_model != nullptr ? m_model->s7_handle(m_id, pdu) : std::vector<std::uint8_t>{};
}

void HS7Session::close() {
  if (m_model == nullptr) return;
  if (auto* s = m_model->s7_find(m_id)) m_model->s7_finish(*s, S7CloseReason::Closed, "closed");
}

}  // namespace pbvbus::devices
