#include "pbvbus/fdl_traffic/fdl_responder.hpp"

#include "counting_table.hpp"

namespace pbvbus::devices {

void FdlResponder::on_request(const fdl::Indication& ind, fdl::Reply& reply) {
  using fdl::RequestFn;
  switch (ind.fn) {
    case RequestFn::SrdLow:
    case RequestFn::SrdHigh: {
      ++m_srd;
      if (m_data.empty()) {
        reply.short_ack();
        return;
      }
      const auto c = static_cast<std::uint8_t>(m_cycle++);
      if (m_data.size() <= detail::kCountingMax) {
        // The octets fill_counting() would write, straight from the table (m_data only gives
        // the length then).
        reply.respond(fdl::ResponseStatus::DL, {detail::kCounting.data() + c, m_data.size()});
        return;
      }
      fill_counting(m_data, c);
      reply.respond(fdl::ResponseStatus::DL, m_data);
      return;
    }
    case RequestFn::SdaLow:
    case RequestFn::SdaHigh:
      ++m_sda;
      reply.short_ack();
      return;
    case RequestFn::SdnLow:
    case RequestFn::SdnHigh:
      ++m_sdn;
      reply.none();
      return;
    default: ++m_other; return;
  }
}

}  // namespace pbvbus::devices
