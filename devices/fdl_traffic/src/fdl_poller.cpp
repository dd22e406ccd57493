#include "pbvbus/fdl_traffic/fdl_poller.hpp"

#include "pbvbus/fdl_traffic/fdl_responder.hpp"

#include "counting_table.hpp"

namespace pbvbus::devices {

FdlPoller::FdlPoller(std::vector<PollItem> items)
    : m_items(std::move(items)),
      m_stats(m_items.size()),
      m_visit_done(m_items.size(), 0),
      m_seq(m_items.size(), 0) {
  for (std::size_t k = 0; k < m_items.size(); ++k)
    m_by_prio[fdl::fn_is_high_priority(m_items[k].fn) ? 0 : 1].push_back(k);
}

PollStats FdlPoller::total() const {
  PollStats t;
  for (const auto& s : m_stats) {
    t.requests += s.requests;
    t.ok += s.ok;
    t.no_response += s.no_response;
    t.sent += s.sent;
    t.retries += s.retries;
    t.data_octets += s.data_octets;
  }
  return t;
}

void FdlPoller::on_power_on(bus::Ticks) {
  // A restarted master begins a fresh visit; counters stay (they describe the whole run).
  ++m_visit;
}

bool FdlPoller::next_request(fdl::Priority prio, bus::Ticks, fdl::Request& out) {
  const int p = prio == fdl::Priority::High ? 0 : 1;
  const std::vector<std::size_t>& list = m_by_prio[p];
  const std::size_t n = list.size();
  // The station asks again after every message cycle, so the common case (the item at the
  // cursor is due) costs one look; only the last, unsuccessful ask of a visit scans the list.
  std::size_t& cursor = m_cursor[p];
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t pos = cursor + i < n ? cursor + i : cursor + i - n;
    const std::size_t k = list[pos];
    if (m_visit_done[k] == m_visit) continue;
    const PollItem& it = m_items[k];
    m_visit_done[k] = m_visit;
    cursor = pos + 1 < n ? pos + 1 : 0;
    out.da = it.da;
    out.fn = it.fn;
    out.dsap.reset();
    out.ssap.reset();
    const std::uint8_t seq = m_seq[k]++;
    if (it.length <= detail::kCountingMax) {  // the same octets, copied in one go
      const std::uint8_t* from = detail::kCounting.data() + seq;
      out.data.assign(from, from + it.length);
    } else {
      out.data.resize(it.length);
      fill_counting(out.data, seq);
    }
    out.tag = k;
    return true;
  }
  return false;
}

void FdlPoller::on_confirmation(const fdl::Confirmation& con) {
  if (con.tag >= m_stats.size()) return;
  PollStats& s = m_stats[con.tag];
  ++s.requests;
  s.retries += con.retries;
  switch (con.result) {
    case fdl::Confirmation::Result::Ok:
      ++s.ok;
      s.data_octets += con.data.size();
      break;
    case fdl::Confirmation::Result::NoResponse: ++s.no_response; break;
    case fdl::Confirmation::Result::Sent: ++s.sent; break;
  }
}

void FdlPoller::on_token(bus::Ticks, bus::Ticks trr) {
  ++m_tokens;
  ++m_visit;
  // The station reports 0 for the first token after power-on or after (re)entering the ring:
  // there is no previous receipt to measure a rotation from.
  if (trr > 0) m_trr.push_back(trr);
}

}  // namespace pbvbus::devices
