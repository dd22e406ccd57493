// Redundant two-channel I/O with passivation (h_redundant_io.hpp; docs/h-redundant-io.md has
// the rules with the manual's lines and the decisions).
#include "pbvbus/s7h/h_redundant_io.hpp"

#include <algorithm>
#include <stdexcept>

namespace pbvbus::devices {

namespace {

bool get_bit(std::span<const std::uint8_t> b, std::uint32_t n) {
  return (b[n / 8] >> (n % 8)) & 1U;
}
void set_bit(std::span<std::uint8_t> b, std::uint32_t n, bool v) {
  const auto m = static_cast<std::uint8_t>(1U << (n % 8));
  b[n / 8] = static_cast<std::uint8_t>(v ? (b[n / 8] | m) : (b[n / 8] & ~m));
}
std::int32_t get_word(std::span<const std::uint8_t> b, std::uint32_t ch) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((b[2 * ch] << 8) | b[2 * ch + 1]));
}
void set_word(std::span<std::uint8_t> b, std::uint32_t ch, std::int32_t v) {
  const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
  b[2 * ch] = static_cast<std::uint8_t>(u >> 8);
  b[2 * ch + 1] = static_cast<std::uint8_t>(u & 0xFF);
}

bool fits(std::uint32_t addr, std::uint32_t len, std::size_t size) {
  return static_cast<std::uint64_t>(addr) + len <= size;
}
bool overlap(std::uint32_t a, std::uint32_t b, std::uint32_t len) {
  return a < b + len && b < a + len;
}

}  // namespace

std::string RedundantIo::validate(const std::vector<RedIoPairSpec>& pairs) {
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const auto& p = pairs[i];
    const std::string n = "redundant I/O pair " + std::to_string(i) + ": ";
    if (p.length == 0) return n + "length 0";
    if ((p.kind == RedIoKind::AI || p.kind == RedIoKind::AO) && p.length % 2 != 0)
      return n + "analog length " + std::to_string(p.length) + " is not a whole number of words";
    if (overlap(p.address_low, p.address_high, p.length))
      return n + "module_L at " + std::to_string(p.address_low) + " and module_H at " +
             std::to_string(p.address_high) + " overlap";
    if (p.address_low > p.address_high)
      return n + "module_L (the valid value) must be at the lower address";
    if (p.discrepancy_time < 0) return n + "negative discrepancy time";
    if (p.kind == RedIoKind::AI && p.end_value <= 0) return n + "end value must be > 0";
    for (std::size_t j = 0; j < i; ++j) {
      const auto& q = pairs[j];
      if (is_input(p.kind) != is_input(q.kind)) continue;
      for (std::uint32_t a : {p.address_low, p.address_high})
        for (std::uint32_t b : {q.address_low, q.address_high})
          if (a < b + q.length && b < a + p.length)
            return n + "module at " + std::to_string(a) + " overlaps pair " + std::to_string(j);
    }
  }
  return "";
}

RedundantIo::RedundantIo(std::vector<RedIoPairSpec> pairs) : m_specs(std::move(pairs)) {
  if (auto e = validate(m_specs); !e.empty()) throw std::invalid_argument(e);
  m_state.resize(m_specs.size());
  m_work.resize(m_specs.size());
  for (std::size_t i = 0; i < m_specs.size(); ++i) {
    const auto& s = m_specs[i];
    auto& w = m_work[i];
    w.last_raw[0].assign(s.length, 0);
    w.last_raw[1].assign(s.length, 0);
    w.last_valid.assign(s.length, 0);
    w.track.assign(s.kind == RedIoKind::DI ? s.length * 8 : s.length / 2, Track{});
  }
}

void RedundantIo::reset_tracks(std::size_t i) {
  for (auto& t : m_work[i].track) t = Track{};
  m_state[i].discrepant = false;
  m_state[i].expired = false;
}

void RedundantIo::passivate(bus::Ticks now, std::size_t i, RedModule m, RedIoCause cause,
                            std::uint16_t code) {
  auto& st = m_state[i];
  const int k = static_cast<int>(m);
  if (st.passivated[k]) return;
  st.passivated[k] = true;
  st.cause[k] = cause;
  reset_tracks(i);
  RedIoEvent e;
  e.time = now;
  e.code = code;
  e.kind = m_specs[i].kind;
  e.pair = i;
  e.module = k;
  e.address = k == 0 ? m_specs[i].address_low : m_specs[i].address_high;
  add(e);
}

bool RedundantIo::module_fault(bus::Ticks now, std::size_t pair, RedModule m, RedIoCause cause,
                               bool incoming) {
  if (pair >= m_specs.size()) return false;
  if (cause != RedIoCause::Ob82 && cause != RedIoCause::Ob85) return false;
  const int k = static_cast<int>(m);
  auto& st = m_state[pair];
  if (!incoming) {
    // The fault has gone: the module may be depassivated again (Table 7-5 byte 2 bits 2-5).
    st.fault_present[k] = false;
    return true;
  }
  st.fault_present[k] = true;
  passivate(now, pair, m, cause,
            cause == RedIoCause::Ob82 ? kRedIoOb82Passivated : kRedIoOb85Passivated);
  return true;
}

std::optional<std::size_t> RedundantIo::find_pair(std::uint32_t address, bool output) const {
  for (std::size_t i = 0; i < m_specs.size(); ++i)
    if (is_input(m_specs[i].kind) != output && module_at(i, address)) return i;
  return std::nullopt;
}

std::optional<RedModule> RedundantIo::module_at(std::size_t i, std::uint32_t address) const {
  if (i >= m_specs.size()) return std::nullopt;
  const auto& s = m_specs[i];
  if (address >= s.address_low && address < s.address_low + s.length) return RedModule::L;
  if (address >= s.address_high && address < s.address_high + s.length) return RedModule::H;
  return std::nullopt;
}

bool RedundantIo::request_depassivation(bus::Ticks, DepassivationTrigger t) {
  if (t == DepassivationTrigger::Fc451) {
    // FC 451 "if at least one redundant module is passivated" (001 L6590-6591).
    const bool any = std::any_of(m_state.begin(), m_state.end(), [](const RedIoPairState& s) {
      return s.passivated[0] || s.passivated[1];
    });
    if (!any) return false;
  }
  m_depa_pending = t;
  return true;
}

void RedundantIo::depassivate(bus::Ticks now) {
  std::uint32_t count = 0;
  for (std::size_t i = 0; i < m_specs.size(); ++i) {
    auto& st = m_state[i];
    bool any = false;
    for (int k = 0; k < 2; ++k) {
      if (!st.passivated[k] || st.fault_present[k]) continue;  // a present fault: stays
      st.passivated[k] = false;
      st.cause[k] = RedIoCause::None;
      ++count;
      any = true;
    }
    if (any) {
      reset_tracks(i);
      m_work[i].seen = false;  // the next reading starts afresh (no "signal change" from it)
    }
  }
  if (count == 0) return;  // nothing was passivated (or every passivated module is still faulty)
  RedIoEvent e;
  e.time = now;
  e.code = kRedIoDepassivated;
  e.count = count;
  add(e);
}

void RedundantIo::red_in(bus::Ticks now, std::span<std::uint8_t> pii) {
  if (now < 0) return;
  if (m_depa_pending) {
    // "After one of these events the depassivation is carried out in FB 450 RED_IN"
    // (001 L6596-6597).
    m_depa_pending.reset();
    depassivate(now);
  }
  for (std::size_t i = 0; i < m_specs.size(); ++i) {
    const auto& s = m_specs[i];
    if (!is_input(s.kind)) continue;
    if (!fits(s.address_low, s.length, pii.size()) || !fits(s.address_high, s.length, pii.size()))
      continue;
    if (s.kind == RedIoKind::DI)
      run_di(now, i, pii);
    else
      run_ai(now, i, pii);
  }
}

void RedundantIo::run_di(bus::Ticks now, std::size_t i, std::span<std::uint8_t> pii) {
  const auto& s = m_specs[i];
  auto& st = m_state[i];
  auto& w = m_work[i];
  const std::span<std::uint8_t> low = pii.subspan(s.address_low, s.length);
  const std::vector<std::uint8_t> raw_l(low.begin(), low.end());
  const std::span<const std::uint8_t> raw_h = pii.subspan(s.address_high, s.length);
  const std::span<const std::uint8_t> raw[2] = {raw_l, raw_h};
  const std::uint32_t bits = s.length * 8;

  // Pass 1 (both modules active): the discrepancy analysis, 001 L5928-5959.
  if (!st.passivated[0] && !st.passivated[1]) {
    std::optional<RedModule> to_passivate;
    std::uint32_t localized_bit = 0;
    for (std::uint32_t b = 0; b < bits && !to_passivate; ++b) {
      auto& t = w.track[b];
      const bool l = get_bit(raw_l, b), h = get_bit(raw_h, b);
      if (!t.differing) {
        if (l == h) {
          set_bit(w.last_valid, b, l);
          continue;
        }
        t.differing = true;  // first seen: mark it and start the discrepancy time
        t.since = now;
      } else if (!t.reported && l == h) {
        // Equal again within the discrepancy time: the analysis simply goes on (L5936-5938).
        t = Track{};
        set_bit(w.last_valid, b, l);
        continue;
      }
      if (!t.reported) {
        if (now - t.since >= s.discrepancy_time) {
          // Expired: 7960, no passivation yet (L5949-5954). A change seen at this same call is
          // not yet "another signal change" after the expiry: that needs a later RED_IN.
          t.reported = true;
          RedIoEvent e;
          e.time = now;
          e.code = kRedIoDiDiscrepancy;
          e.kind = s.kind;
          e.pair = i;
          e.address = s.address_low;
          e.bit = b;
          add(e);
        }
        continue;
      }
      // Expired and reported: the next signal change localizes the error (L5957-5959): the
      // module that changed stays, the other one is passivated. Both changing at once says
      // nothing; the episode goes on.
      const bool cl = w.seen && get_bit(w.last_raw[0], b) != l;
      const bool ch = w.seen && get_bit(w.last_raw[1], b) != h;
      if (cl != ch) {
        to_passivate = cl ? RedModule::H : RedModule::L;
        localized_bit = b;
      }
    }
    if (to_passivate) {
      passivate(now, i, *to_passivate, RedIoCause::DiDiscrepancy, kRedIoDiPassivated);
      m_events.back().bit = localized_bit;
    }
  }

  // Pass 2: the value at module_L's address.
  st.discrepant = false;
  st.expired = false;
  const int active = st.passivated[0] ? (st.passivated[1] ? -1 : 1) : (st.passivated[1] ? 0 : 2);
  for (std::uint32_t b = 0; b < bits; ++b) {
    bool v = false;  // both passivated: "zeros" (L5961-5962)
    if (active == 0 || active == 1) {
      v = get_bit(raw[active], b);
      set_bit(w.last_valid, b, v);
    } else if (active == 2) {
      const auto& t = w.track[b];
      if (!t.differing) {
        v = get_bit(raw_l, b);
      } else {
        st.discrepant = true;
        st.expired = st.expired || t.reported;
        // During the time: the last agreeing value (L5934-5936); after the expiry, until the
        // next change: the configured reaction (L5953-5954).
        v = t.reported && s.di_reaction == DiReaction::Value1 ? true : get_bit(w.last_valid, b);
      }
    }
    set_bit(low, b, v);
  }
  w.last_raw[0] = raw_l;
  w.last_raw[1].assign(raw_h.begin(), raw_h.end());
  w.seen = true;
}

void RedundantIo::run_ai(bus::Ticks now, std::size_t i, std::span<std::uint8_t> pii) {
  const auto& s = m_specs[i];
  auto& st = m_state[i];
  auto& w = m_work[i];
  const std::span<std::uint8_t> low = pii.subspan(s.address_low, s.length);
  const std::vector<std::uint8_t> raw_l(low.begin(), low.end());
  const std::span<const std::uint8_t> raw_h = pii.subspan(s.address_high, s.length);
  const std::span<const std::uint8_t> raw[2] = {raw_l, raw_h};
  const std::uint32_t channels = s.length / 2;
  // The window, exactly: |a − b| · 1000 ≤ end_value · tolerance_permille.
  const std::int64_t window_x1000 =
      static_cast<std::int64_t>(s.end_value) * static_cast<std::int64_t>(s.tolerance_permille);

  // Overflow 7FFF / underflow 8000 on an active module: passivated at once (decision, L6330).
  st.overflow = false;
  for (int k = 0; k < 2; ++k)
    for (std::uint32_t c = 0; c < channels; ++c) {
      const std::int32_t v = get_word(raw[k], c);
      if (v != 0x7FFF && v != -0x8000) continue;
      st.overflow = true;
      if (!st.passivated[k]) {
        passivate(now, i, static_cast<RedModule>(k), RedIoCause::Overflow,
                  kRedIoOverflowPassivated);
        m_events.back().bit = c;
      }
    }

  if (!st.passivated[0] && !st.passivated[1]) {
    // The tolerance window and the discrepancy time (001 L6139-6182).
    for (std::uint32_t c = 0; c < channels; ++c) {
      auto& t = w.track[c];
      const std::int32_t a = get_word(raw_l, c), b = get_word(raw_h, c);
      const std::int64_t diff = a > b ? a - b : b - a;
      if (diff * 1000 <= window_x1000) {
        t = Track{};  // inside: the analysis goes on (L6178-6179)
        continue;
      }
      if (!t.differing) {
        t.differing = true;
        t.since = now;
      }
      if (now - t.since >= s.discrepancy_time) {
        // The module with the configured accepted value stays, the other is passivated
        // (L6170-6176). Equal values cannot be outside the window.
        const bool l_is_max = a > b;
        const bool keep_l = (s.accepted == AiAcceptedValue::Max) == l_is_max;
        passivate(now, i, keep_l ? RedModule::H : RedModule::L, RedIoCause::AiDiscrepancy,
                  kRedIoAiPassivated);
        m_events.back().bit = c;
        break;
      }
    }
  }

  st.discrepant = false;
  st.expired = false;
  const int active = st.passivated[0] ? (st.passivated[1] ? -1 : 1) : (st.passivated[1] ? 0 : 2);
  for (std::uint32_t c = 0; c < channels; ++c) {
    std::int32_t v = 0;  // both passivated: 0, as for DI (decision)
    if (active == 0 || active == 1) {
      v = get_word(raw[active], c);
      set_word(w.last_valid, c, v);
    } else if (active == 2) {
      if (!w.track[c].differing) {
        const std::int32_t a = get_word(raw_l, c), b = get_word(raw_h, c);
        v = s.accepted == AiAcceptedValue::Max ? std::max(a, b) : std::min(a, b);
        set_word(w.last_valid, c, v);
      } else {
        st.discrepant = true;
        v = get_word(w.last_valid, c);  // the last valid value (L6166-6168)
      }
    }
    set_word(low, c, v);
  }
  w.seen = true;
}

std::vector<std::uint8_t> RedundantIo::red_out(std::span<const std::uint8_t> piq) const {
  std::vector<std::uint8_t> out(piq.begin(), piq.end());
  for (std::size_t i = 0; i < m_specs.size(); ++i) {
    const auto& s = m_specs[i];
    if (is_input(s.kind)) continue;
    if (!fits(s.address_low, s.length, out.size()) || !fits(s.address_high, s.length, out.size()))
      continue;
    const auto& st = m_state[i];
    const std::span<const std::uint8_t> value = piq.subspan(s.address_low, s.length);
    const std::span<std::uint8_t> mod[2] = {std::span(out).subspan(s.address_low, s.length),
                                            std::span(out).subspan(s.address_high, s.length)};
    const bool both = !st.passivated[0] && !st.passivated[1];
    for (int k = 0; k < 2; ++k) {
      if (st.passivated[k]) {  // a passivated output module is written 0 (decision)
        std::fill(mod[k].begin(), mod[k].end(), std::uint8_t{0});
        continue;
      }
      if (s.kind == RedIoKind::DO || !both) {  // DO alike on both; a lone module: the value
        std::copy(value.begin(), value.end(), mod[k].begin());
        continue;
      }
      // AO, both active: the two outputs are wired in parallel and their currents add, so each
      // module drives half; module_H takes the odd unit, the sum is exact (decision).
      for (std::uint32_t c = 0; c < s.length / 2; ++c) {
        const std::int32_t v = get_word(value, c);
        set_word(mod[k], c, k == 0 ? v / 2 : v - v / 2);
      }
    }
  }
  return out;
}

std::uint16_t RedundantIo::modul_status_word(std::size_t i) const {
  const auto& s = m_specs.at(i);
  const auto& st = m_state.at(i);
  // 001 Table 7-5. Most bits are "0 = the condition is present".
  std::uint8_t b1 = 0, b2 = 0;
  auto set = [](std::uint8_t& b, int n, bool v) {
    if (v) b = static_cast<std::uint8_t>(b | (1U << n));
  };
  set(b1, 0, st.cause[0] != RedIoCause::Ob82);
  set(b1, 1, st.cause[1] != RedIoCause::Ob82);
  set(b1, 2, !(s.kind == RedIoKind::AI && st.overflow));
  set(b1, 3, true);  // no channel information in the model
  set(b1, 4, !(is_input(s.kind) && st.expired));
  set(b1, 5, !(is_input(s.kind) && st.discrepant));
  set(b1, 6, !st.passivated[0]);
  set(b1, 7, !st.passivated[1]);
  for (int k = 0; k < 2; ++k) {
    const bool gone = st.passivated[k] && !st.fault_present[k];
    set(b2, 2 + k, gone && st.cause[k] == RedIoCause::Ob85);
    set(b2, 4 + k, gone && st.cause[k] == RedIoCause::Ob82);
    set(b2, 6 + k, st.cause[k] != RedIoCause::Ob85);
  }
  return static_cast<std::uint16_t>((b1 << 8) | b2);
}

std::uint8_t RedundantIo::status_byte() const {
  // 001 Table 7-4 (bits 0, 1 reserved; bit 5 channel information and bit 7 global passivation
  // are not modelled: 0).
  std::uint8_t b = 0;
  for (std::size_t i = 0; i < m_specs.size(); ++i) {
    const auto& st = m_state[i];
    if (m_specs[i].kind == RedIoKind::AO) b |= 1U << 2;
    for (int k = 0; k < 2; ++k) {
      if (!st.passivated[k]) continue;
      b |= 1U << 6;
      if (st.cause[k] == RedIoCause::Ob85) b |= 1U << 3;
      if (st.cause[k] == RedIoCause::Ob82) b |= 1U << 4;
    }
  }
  return b;
}

}  // namespace pbvbus::devices
