#include "pbvbus/bus/line.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <stdexcept>

namespace pbvbus::bus {

namespace {
constexpr Ticks kNeverHeard = INT64_MIN / 4;
constexpr std::uint64_t kTagTimer = 0, kTagTxStart = 1, kTagBabble = 2;
/// Octets per babble burst: long enough to keep the event rate low, short enough that a fault
/// repair (babble off) takes effect within a few character times.
constexpr std::size_t kBabbleBurst = 32;

/// Idle time at `start` of a receiver that last heard something until `heard` (kNeverHeard:
/// nothing since power-on).
Ticks idle_since(Ticks heard, Ticks start) {
  return heard == kNeverHeard ? kIdleForever : std::max<Ticks>(0, start - heard);
}

/// Destination address octet of an FDL frame, or -1 if the frame has none (SC, garbage).
int frame_da(std::span<const std::uint8_t> b) {
  if (b.empty()) return -1;
  switch (b[0]) {
    case 0x10:
    case 0xA2:
    case 0xDC: return b.size() > 1 ? b[1] & 0x7F : -1;
    case 0x68: return b.size() > 4 ? b[4] & 0x7F : -1;
    default: return -1;
  }
}
}  // namespace

struct Line::Transmission {
  std::uint64_t id = 0;
  Attachment* from = nullptr;
  std::vector<std::uint8_t> bytes;
  std::size_t sent_len = 0;
  Ticks start = 0;
  Ticks end = 0;
  std::uint16_t flags = 0;
  bool cut_counted = false;  // counted in LineStats::partial already
  Mask rx;
  std::uint64_t probes = 0;  // probe taps (bits of m_probes) still hearing it
  /// What the layers above worked out from `bytes` (frame_memo.hpp): handed to every receiver
  /// and tap; emptied whenever `bytes` change.
  mutable FrameMemo memo;
  /// How receivers' idle time before this frame is known (see Line::settle_heard()):
  ///  - lazy (the usual case): from m_heard_until[i] and `seg_heard_before`, the end of the
  ///    latest activity on the sender's segment in the current epoch before this frame;
  ///  - eager (after a fault in flight): `idle_before[i]`, valid where rx is set.
  bool lazy_idle = true;
  Ticks seg_heard_before = 0;
  std::array<Ticks, kMaxAttachments> idle_before{};
};

class Line::Port final : public DevicePort {
 public:
  Port(Line& l, Attachment& a) : m_line(l), m_att(a) {}
  Ticks now() const override { return m_line.m_sched.now(); }
  Baud baud() const override { return m_line.m_baud; }
  void transmit(Ticks start, std::span<const std::uint8_t> bytes) override;
  void set_timer(Ticks at) override;
  bool receiving() const override;
  void receive_filter_changed() override;
  bool medium_fault() const override { return m_line.m_short; }

 private:
  Line& m_line;
  Attachment& m_att;
};

struct Line::Attachment final : EventTarget {
  Attachment(Line& l, int i, Device& d, std::string lbl)
      : line(l), id(i), dev(&d), label(std::move(lbl)), port(l, *this) {}

  void on_event(Ticks now, std::uint64_t tag) override {
    const std::uint64_t kind = tag & 3, value = tag >> 2;
    if (kind == kTagTimer) {
      if (value != timer_gen) return;  // superseded by an earlier wake-up
      next_event = kNever;
      if (!powered) return;
      if (deadline <= now) {
        deadline = kNever;
        dev->on_timer(now);
        line.refresh_filter(static_cast<std::size_t>(id));
      } else if (deadline != kNever) {
        arm(deadline);  // the deadline was postponed after this wake-up was queued
      }
    } else if (kind == kTagTxStart) {
      if (value != power_epoch || pending.empty()) return;
      if (uart_busy_until > now) {
        // The UART is still shifting out the previous telegram: this one follows back to back.
        line.m_sched.schedule(uart_busy_until, *this, tag);
        return;
      }
      // The pending transmission due now: earliest start, then order of request.
      std::unique_ptr<Transmission> t;
      if (pending.size() == 1) {  // the usual case
        t = std::move(pending.front().tx);
        pending.clear();
      } else {
        auto it = std::min_element(pending.begin(), pending.end(), [](const auto& a, const auto& b) {
          return a.start != b.start ? a.start < b.start : a.seq < b.seq;
        });
        t = std::move(it->tx);
        pending.erase(it);
      }
      line.start_transmission(*this, std::move(t), false);
    } else if (kind == kTagBabble) {
      if (value == babble_epoch) line.babble_burst(*this);
    }
  }

  void arm(Ticks at) {
    // One queued wake-up per attachment: an earlier one moves the entry still queued (a
    // superseded slot-time timer no longer runs as an event of its own).
    next_event = at;
    line.m_sched.schedule(timer_slot, at, *this, (++timer_gen << 2) | kTagTimer);
  }

  struct Pending {
    Ticks start;
    std::uint64_t seq;
    std::unique_ptr<Transmission> tx;  ///< from the line's pool, its bytes filled in
  };

  Line& line;
  int id;
  Device* dev;
  std::string label;
  Port port;
  bool powered = false;
  bool xcvr_ok = true;
  bool babbling = false;
  bool cut_after = false;
  int segment = 0;
  /// End of the device's own current telegram (not babble): a UART sends one at a time.
  Ticks uart_busy_until = kNeverHeard;
  // Timer: one wanted deadline; `next_event` is the earliest wake-up still valid in the queue.
  Ticks deadline = kNever;
  Ticks next_event = kNever;
  std::uint64_t timer_gen = 0;
  Scheduler::TimerSlot timer_slot;
  std::vector<Pending> pending;
  std::uint64_t pending_seq = 0;
  std::uint64_t power_epoch = 0;
  std::uint64_t babble_epoch = 0;
};

void Line::Port::transmit(Ticks start, std::span<const std::uint8_t> bytes) {
  if (!m_att.powered || bytes.empty()) return;
  Ticks now = m_line.m_sched.now();
  if (start < now) start = now;
  // Always through the queue, even at `now`: a device answering from inside on_frame() must not
  // start a transmission while the line is still delivering the previous one.
  std::unique_ptr<Transmission> t = m_line.take_transmission();
  t->bytes.assign(bytes.begin(), bytes.end());
  m_att.pending.push_back({start, m_att.pending_seq++, std::move(t)});
  m_line.m_sched.schedule(start, m_att, (m_att.power_epoch << 2) | kTagTxStart);
}

void Line::Port::receive_filter_changed() { m_line.refresh_filter(static_cast<std::size_t>(m_att.id)); }

void Line::Port::set_timer(Ticks at) {
  m_att.deadline = at;
  if (!m_att.powered || at == kNever) return;
  if (at < m_att.next_event) m_att.arm(at);
}

bool Line::Port::receiving() const {
  const Ticks now = m_line.m_sched.now();
  const auto bit = static_cast<std::size_t>(m_att.id);
  for (const auto& t : m_line.m_in_flight)
    if (t->start <= now && t->rx.test(bit)) return true;
  return false;
}

// --------------------------------------------------------------------------------------------

Line::Line(Scheduler& sched, std::string name, Baud baud, std::uint64_t seed)
    : m_sched(sched), m_name(std::move(name)), m_baud(baud),
      m_rng(seed ^ 0x9E3779B97F4A7C15ULL) {}

Line::~Line() {
  // Queued timer entries point at their attachments' slots: withdraw them (the scheduler
  // outlives its lines).
  for (auto& a : m_atts) m_sched.cancel(a->timer_slot);
}

AttachmentId Line::attach(Device& dev, std::string label) {
  if (m_atts.size() >= kMaxAttachments) throw std::length_error("line " + m_name + ": too many attachments");
  settle_heard();
  const int id = static_cast<int>(m_atts.size());
  m_atts.push_back(std::make_unique<Attachment>(*this, id, dev, std::move(label)));
  dev.bind(m_atts.back()->port);
  m_devs.push_back(&dev);
  m_heard_until.push_back(kNeverHeard);
  m_filter.push_back(kReceiveAll);
  m_receive_all.set(static_cast<std::size_t>(id));
  recompute_segments();
  refresh_listening();
  refresh_filter(static_cast<std::size_t>(id));
  return id;
}

Device& Line::device(AttachmentId a) { return *m_atts.at(static_cast<std::size_t>(a))->dev; }
const std::string& Line::label(AttachmentId a) const { return m_atts.at(static_cast<std::size_t>(a))->label; }
bool Line::powered(AttachmentId a) const { return m_atts.at(static_cast<std::size_t>(a))->powered; }
bool Line::cut_after(AttachmentId a) const { return m_atts.at(static_cast<std::size_t>(a))->cut_after; }

void Line::start() {
  for (auto& a : m_atts)
    if (!a->powered) set_power(a->id, true);
}

void Line::add_tap(Tap& tap) {
  m_taps.push_back(&tap);
  if (std::find(m_event_taps.begin(), m_event_taps.end(), &tap) == m_event_taps.end())
    m_event_taps.push_back(&tap);
}

void Line::add_tap(Tap& tap, ProbePoint p) {
  if (p.at < 0 || p.at >= attachment_count())
    throw std::out_of_range("line " + m_name + ": no attachment " + std::to_string(p.at) +
                            " to put a probe at");
  if (m_probes.size() >= static_cast<std::size_t>(kMaxProbes))
    throw std::length_error("line " + m_name + ": too many probes");
  m_probes.push_back({&tap, p.at});
  if (std::find(m_event_taps.begin(), m_event_taps.end(), &tap) == m_event_taps.end())
    m_event_taps.push_back(&tap);
  refresh_probes();
}

void Line::remove_tap(Tap& tap) {
  std::erase(m_taps, &tap);
  std::erase(m_event_taps, &tap);
  // Probe bits of frames on the wire follow the probes' new indices.
  for (std::size_t k = m_probes.size(); k-- > 0;) {
    if (m_probes[k].tap != &tap) continue;
    m_probes.erase(m_probes.begin() + static_cast<std::ptrdiff_t>(k));
    const std::uint64_t below = (std::uint64_t{1} << k) - 1;
    for (auto& t : m_in_flight) {
      const std::uint64_t above = k + 1 < 64 ? (t->probes >> (k + 1)) << k : 0;
      t->probes = (t->probes & below) | above;
    }
  }
  refresh_probes();
}

bool Line::is_whole_line_tap(const Tap& tap) const {
  return std::find(m_taps.begin(), m_taps.end(), &tap) != m_taps.end();
}

std::vector<AttachmentId> Line::probe_points(const Tap& tap) const {
  std::vector<AttachmentId> v;
  for (const ProbeTap& p : m_probes)
    if (p.tap == &tap) v.push_back(p.at);
  return v;
}

void Line::refresh_probes() {
  m_probe_by_segment.assign(m_listening.size(), 0);
  if (m_short) return;
  for (std::size_t k = 0; k < m_probes.size(); ++k) {
    const auto seg = static_cast<std::size_t>(m_atts[static_cast<std::size_t>(m_probes[k].at)]->segment);
    m_probe_by_segment[seg] |= std::uint64_t{1} << k;
  }
}

Ticks Line::earliest_start_in_flight() const {
  Ticks t = m_tapping_start;
  for (const auto& x : m_in_flight) t = std::min(t, x->start);
  return t;
}

std::unique_ptr<Line::Transmission> Line::take_transmission() {
  if (m_pool.empty()) {
    auto t = std::make_unique<Transmission>();
    t->bytes.reserve(256);  // the longest FDL telegram (SD2, LE = 249) is 255 octets
    return t;
  }
  std::unique_ptr<Transmission> t = std::move(m_pool.back());
  m_pool.pop_back();
  return t;
}

std::uint64_t Line::next_random() {
  // splitmix64: small, fast and the same on every platform (std distributions are not).
  std::uint64_t z = (m_rng += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

bool Line::can_hear(const Attachment& rx, const Attachment& tx) const {
  return !m_short && rx.powered && rx.xcvr_ok && tx.powered && tx.xcvr_ok && rx.segment == tx.segment;
}

bool Line::connected(AttachmentId a, AttachmentId b) const {
  return can_hear(*m_atts.at(static_cast<std::size_t>(a)), *m_atts.at(static_cast<std::size_t>(b)));
}

void Line::refresh_filter(std::size_t i) {
  int f = m_devs[i]->receive_filter();
  if (f < 0 || f > 126) f = kReceiveAll;
  const int old = m_filter[i];
  if (f == old) return;
  if (old == kReceiveAll) {
    m_receive_all.reset(i);
    m_filtered.set(i);
  } else {
    m_by_addr[static_cast<std::size_t>(old)].reset(i);
  }
  if (f == kReceiveAll) {
    m_receive_all.set(i);
    m_filtered.reset(i);
  } else {
    m_by_addr[static_cast<std::size_t>(f)].set(i);
  }
  m_filter[i] = f;
}

bool Line::accepts(std::size_t i, int da) const {
  const int f = m_filter[i];
  return f == kReceiveAll || da == f || da == 127;
}

void Line::refresh_listening() {
  m_listening.assign(m_atts.empty() ? 1 : static_cast<std::size_t>(m_atts.back()->segment) + 1, Mask{});
  m_seg_heard.assign(m_listening.size(), kNeverHeard);  // a new epoch (settle_heard() came first)
  refresh_probes();
  if (m_short) return;
  for (auto& a : m_atts)
    if (a->powered && a->xcvr_ok) m_listening[static_cast<std::size_t>(a->segment)].set(static_cast<std::size_t>(a->id));
}

void Line::settle_heard() {
  // Frames on the wire get their receivers' idle times now, from the epoch's values.
  for (auto& t : m_in_flight) {
    if (!t->lazy_idle) continue;
    t->rx.for_each([&](std::size_t i) {
      t->idle_before[i] = idle_since(std::max(m_heard_until[i], t->seg_heard_before), t->start);
    });
    t->lazy_idle = false;
  }
  // Listeners have heard their segment's latest activity.
  for (std::size_t s = 0; s < m_listening.size(); ++s) {
    const Ticks h = m_seg_heard[s];
    if (h == kNeverHeard) continue;
    m_listening[s].for_each([&](std::size_t i) { m_heard_until[i] = std::max(m_heard_until[i], h); });
  }
  m_seg_heard.assign(m_listening.size(), kNeverHeard);
}

void Line::recompute_segments() {
  int seg = 0;
  for (auto& a : m_atts) {
    a->segment = seg;
    if (a->cut_after) ++seg;
  }
}

// Characters of `t` that overlap [from, to) get garbled.
static void garble(std::vector<std::uint8_t>& bytes, Ticks t_start, Ticks char_ticks, Ticks from,
                   Ticks to, std::uint64_t noise) {
  if (to <= from) return;
  const auto n = static_cast<Ticks>(bytes.size());
  Ticks first = std::max<Ticks>(0, (from - t_start) / char_ticks);
  Ticks last = std::min<Ticks>(n, (to - t_start + char_ticks - 1) / char_ticks);
  for (Ticks i = first; i < last; ++i) {
    // "| 1": the XOR mask is never zero, so an overlapped character always differs.
    bytes[static_cast<std::size_t>(i)] ^= static_cast<std::uint8_t>((noise >> ((i % 8) * 8)) | 1);
  }
}

void Line::apply_noise(Transmission& t) {
  if (m_noise_ppb == 0) return;
  bool any = false;
  for (auto& byte : t.bytes) {
    // 11-bit character: start(0), 8 data LSB first, even parity, stop(1).
    const std::uint8_t parity = static_cast<std::uint8_t>(__builtin_popcount(byte) & 1);
    std::uint32_t ch = (static_cast<std::uint32_t>(byte) << 1) | (static_cast<std::uint32_t>(parity) << 9) | (1u << 10);
    std::uint32_t flips = 0;
    for (int bit = 0; bit < 11; ++bit)
      if (next_random() % 1'000'000'000ULL < m_noise_ppb) flips |= 1u << bit;
    if (!flips) continue;
    any = true;
    ch ^= flips;
    const auto data = static_cast<std::uint8_t>((ch >> 1) & 0xFF);
    if ((ch & 1u) != 0 || (ch & (1u << 10)) == 0) t.flags |= kRxFraming;
    if (static_cast<std::uint32_t>(__builtin_popcount(data) & 1) != ((ch >> 9) & 1u)) t.flags |= kRxParity;
    byte = data;
  }
  if (any) ++m_stats.noisy;
}

void Line::start_transmission(Attachment& from, std::unique_ptr<Transmission> t, bool babble) {
  if (!from.powered) {
    m_pool.push_back(std::move(t));
    return;
  }
  const Ticks now = m_sched.now();
  const Ticks char_ticks = chars_to_ticks(1, m_baud);
  const Ticks end = now + static_cast<Ticks>(t->bytes.size()) * char_ticks;
  ++m_stats.frames;
  m_stats.octets += t->bytes.size();
  if (!babble) from.uart_busy_until = end;
  if (m_short || !from.xcvr_ok) {
    // Nothing reaches the cable (or the cable carries nothing readable).
    ++m_stats.lost;
    m_pool.push_back(std::move(t));
    return;
  }
  t->id = ++m_next_tx_id;
  t->from = &from;
  t->sent_len = t->bytes.size();
  t->start = now;
  t->end = end;
  t->flags = babble ? kRxBabble : 0;
  t->cut_counted = false;
  t->memo.clear();
  // Everyone listening on the sender's segment (the sender is listening: it got this far).
  t->rx = m_listening[static_cast<std::size_t>(from.segment)];
  t->probes = m_probe_by_segment[static_cast<std::size_t>(from.segment)];
  const auto self = static_cast<std::size_t>(from.id);
  t->rx.reset(self);
  // Everyone listening on the segment hears this frame until `end`, the sender included (RS-485
  // transceivers hear themselves): one per-segment value instead of one per listener
  // (settle_heard()). What each receiver had heard before it is what its idle time is made of.
  Ticks& seg_heard = m_seg_heard[static_cast<std::size_t>(from.segment)];
  t->lazy_idle = true;
  t->seg_heard_before = seg_heard;
  seg_heard = std::max(seg_heard, end);

  // Overlap with anything else on the same segment corrupts both.
  for (auto& o : m_in_flight) {
    if (o->from->segment != from.segment || o->end <= now) continue;
    if (!(o->flags & kRxCollision)) ++m_stats.collisions;
    if (!(t->flags & kRxCollision)) ++m_stats.collisions;
    o->flags |= kRxCollision;
    t->flags |= kRxCollision;
    garble(o->bytes, o->start, char_ticks, now, std::min(o->end, t->end), next_random());
    garble(t->bytes, t->start, char_ticks, now, std::min(o->end, t->end), next_random());
    o->memo.clear();  // a cut-short view of `o` may have been decoded already
  }
  apply_noise(*t);
  m_sched.schedule(t->end, *this, t->id);
  m_in_flight.push_back(std::move(t));
}

void Line::deliver(Transmission& t, std::size_t to, std::size_t len, std::uint16_t extra_flags, Ticks end) {
  Device& dev = *m_devs[to];
  RxFrame f;
  f.bytes = std::span<const std::uint8_t>(t.bytes.data(), len);
  f.start = t.start;
  f.end = end;
  // Idle as this receiver's UART saw it when the first start bit arrived: zero if it was still
  // hearing something (a collision), "forever" if nothing since power-on.
  f.idle_before = t.lazy_idle ? idle_since(std::max(m_heard_until[to], t.seg_heard_before), t.start)
                              : t.idle_before[to];
  f.flags = static_cast<std::uint16_t>(t.flags | extra_flags);
  f.memo = &t.memo;
  dev.on_frame(f);
  refresh_filter(to);
}

TapFrame Line::tap_view(const Transmission& t, std::size_t len, std::uint16_t extra_flags,
                        Ticks end) const {
  TapFrame f;
  f.line = this;
  f.bytes = std::span<const std::uint8_t>(t.bytes.data(), len);
  f.start = t.start;
  f.end = end;
  f.flags = static_cast<std::uint16_t>(t.flags | extra_flags);
  f.sender = static_cast<std::uint16_t>(t.from->id);
  f.sent_len = static_cast<std::uint32_t>(t.sent_len);
  f.memo = &t.memo;
  return f;
}

void Line::tap_frame(const Transmission& t, std::size_t len, std::uint16_t extra_flags, Ticks end) {
  if (m_taps.empty()) return;
  TapFrame f = tap_view(t, len, extra_flags, end);
  for (Tap* tap : m_taps) tap->on_frame(f);
}

void Line::probe_frame(const Transmission& t, std::uint64_t probes, std::size_t len,
                       std::uint16_t extra_flags, Ticks end) {
  TapFrame f = tap_view(t, len, extra_flags, end);
  for (std::uint64_t b = probes; b != 0; b &= b - 1) {
    const ProbeTap& p = m_probes[static_cast<std::size_t>(std::countr_zero(b))];
    f.probe = static_cast<std::int16_t>(p.at);
    p.tap->on_frame(f);
  }
}

void Line::on_event(Ticks, std::uint64_t tag) { end_transmission(tag); }

void Line::end_transmission(std::uint64_t id) {
  // Detach from the in-flight list first: receivers may start new transmissions (queued).
  auto it = std::find_if(m_in_flight.begin(), m_in_flight.end(),
                         [&](const auto& p) { return p->id == id; });
  if (it == m_in_flight.end()) return;  // already ended early by a fault
  std::unique_ptr<Transmission> owned = std::move(*it);
  m_in_flight.erase(it);
  const Ticks end = owned->end;
  // Receivers whose filter takes this frame: receive-all, its DA, or everyone for DA 127.
  const int da = frame_da(owned->bytes);
  Mask to;
  // Only the words that hold attachments (one up to 64 stations).
  const std::size_t words = (m_devs.size() + 63) / 64;
  for (std::size_t k = 0; k < words; ++k) {
    std::uint64_t want = m_receive_all.w[k];
    if (da >= 0) want |= m_by_addr[static_cast<std::size_t>(da)].w[k];
    if (da == 127) want |= m_filtered.w[k];
    to.w[k] = owned->rx.w[k] & want;
  }
  to.for_each([&](std::size_t i) { deliver(*owned, i, owned->bytes.size(), 0, end); });
  // Until every tap has it, the frame still counts as on the wire (earliest_start_in_flight):
  // a tap told first must not take it for gone while the others are still to be told.
  m_tapping_start = owned->start;
  tap_frame(*owned, owned->bytes.size(), 0, owned->end);
  if (owned->probes != 0) probe_frame(*owned, owned->probes, owned->bytes.size(), 0, owned->end);
  m_tapping_start = kNever;
  m_pool.push_back(std::move(owned));
}

void Line::truncate_in_flight() {
  const Ticks now = m_sched.now();
  const Ticks char_ticks = chars_to_ticks(1, m_baud);
  Mask touched;  // attachments that stopped hearing something at `now`
  for (std::size_t i = 0; i < m_in_flight.size();) {
    Transmission& t = *m_in_flight[i];
    if (t.end <= now) {
      // Completely on the wire already (its end event runs later in this tick): only a
      // receiver that has just lost power or its transceiver misses it.
      t.rx.for_each([&](std::size_t bit) {
        if (!m_atts[bit]->powered || !m_atts[bit]->xcvr_ok) t.rx.reset(bit);
      });
      ++i;
      continue;
    }
    const auto done = static_cast<std::size_t>(std::clamp<Ticks>((now - t.start) / char_ticks, 0,
                                                                 static_cast<Ticks>(t.bytes.size())));
    const bool sender_gone = m_short || !t.from->powered || !t.from->xcvr_ok;
    // Probes that lose the sender (all of them if it is gone): the characters so far.
    const std::uint64_t lost_probes =
        sender_gone ? t.probes
                    : t.probes & ~m_probe_by_segment[static_cast<std::size_t>(t.from->segment)];
    if (lost_probes != 0) {
      t.probes &= ~lost_probes;
      if (done > 0) probe_frame(t, lost_probes, done, kRxPartial, now);
    }
    const Mask rx = t.rx;
    rx.for_each([&](std::size_t bit) {
      Attachment& a = *m_atts[bit];
      if (!sender_gone && can_hear(a, *t.from)) return;
      t.rx.reset(bit);
      touched.set(bit);
      if (!t.cut_counted) {
        t.cut_counted = true;
        ++m_stats.partial;
      }
      if (a.powered && a.xcvr_ok && done > 0 && accepts(bit, frame_da(std::span(t.bytes).first(done))))
        deliver(t, bit, done, kRxPartial, now);
    });
    if (sender_gone) {
      // The frame ends here for everybody, the tap included.
      if (!t.cut_counted) ++m_stats.partial;
      tap_frame(t, done, kRxPartial, now);
      touched.set(static_cast<std::size_t>(t.from->id));
      t.from->uart_busy_until = std::min(t.from->uart_busy_until, now);
      std::unique_ptr<Transmission> owned = std::move(m_in_flight[i]);
      m_in_flight.erase(m_in_flight.begin() + static_cast<std::ptrdiff_t>(i));
      m_pool.push_back(std::move(owned));
      continue;
    }
    ++i;
  }
  // What those attachments heard now ends here, or with the frames they still hear. (For one
  // that lost power this does not matter: power-on starts from "never heard".)
  touched.for_each([&](std::size_t bit) {
    Ticks h = now;
    for (const auto& t : m_in_flight)
      if (t->from == m_atts[bit].get() || t->rx.test(bit)) h = std::max(h, t->end);
    m_heard_until[bit] = h;
  });
}

void Line::join_in_flight() {
  const Ticks now = m_sched.now();
  const Ticks char_ticks = chars_to_ticks(1, m_baud);
  for (auto& t : m_in_flight) {
    if (t->end <= now) continue;
    // Stations that can now hear the sender hear the rest of the frame: not a frame they can
    // receive (they missed its start), but activity that keeps them from counting idle.
    for (auto& a : m_atts)
      if (a.get() != t->from && !t->rx.test(static_cast<std::size_t>(a->id)) && can_hear(*a, *t->from)) {
        Ticks& h = m_heard_until[static_cast<std::size_t>(a->id)];
        h = std::max(h, t->end);
      }
  }
  // Frames from formerly separate segments that are both still on the wire now overlap.
  for (std::size_t i = 0; i < m_in_flight.size(); ++i) {
    for (std::size_t j = i + 1; j < m_in_flight.size(); ++j) {
      Transmission& x = *m_in_flight[i];
      Transmission& y = *m_in_flight[j];
      if (x.end <= now || y.end <= now || x.from->segment != y.from->segment) continue;
      if ((x.flags & kRxCollision) && (y.flags & kRxCollision)) continue;  // already damaged
      if (!(x.flags & kRxCollision)) ++m_stats.collisions;
      if (!(y.flags & kRxCollision)) ++m_stats.collisions;
      x.flags |= kRxCollision;
      y.flags |= kRxCollision;
      garble(x.bytes, x.start, char_ticks, now, std::min(x.end, y.end), next_random());
      garble(y.bytes, y.start, char_ticks, now, std::min(x.end, y.end), next_random());
      x.memo.clear();
      y.memo.clear();
    }
  }
}

void Line::emit_event(LineEventKind k, int a, int b, std::uint64_t v) {
  LineEvent e{this, m_sched.now(), k, a, b, v};
  for (Tap* tap : m_event_taps) tap->on_line_event(e);
}

void Line::set_cut_after(AttachmentId a, bool cut) {
  auto& att = *m_atts.at(static_cast<std::size_t>(a));
  if (att.cut_after == cut) return;
  settle_heard();
  att.cut_after = cut;
  recompute_segments();
  refresh_listening();
  if (cut) truncate_in_flight();
  else join_in_flight();
  emit_event(cut ? LineEventKind::CableCut : LineEventKind::CableRepaired, a,
             a + 1 < attachment_count() ? a + 1 : -1);
}

void Line::set_cut_between(AttachmentId a, AttachmentId b, bool cut) {
  set_cut_after(std::min(a, b), cut);
}

void Line::set_short_circuit(bool on) {
  if (m_short == on) return;
  settle_heard();
  m_short = on;
  refresh_listening();
  if (on) truncate_in_flight();
  emit_event(on ? LineEventKind::ShortCircuit : LineEventKind::ShortRepaired);
}

void Line::set_noise(std::uint64_t errors_per_billion) {
  m_noise_ppb = std::min<std::uint64_t>(errors_per_billion, 1'000'000'000ULL);
  emit_event(m_noise_ppb ? LineEventKind::NoiseOn : LineEventKind::NoiseOff, -1, -1, m_noise_ppb);
}

void Line::set_power(AttachmentId id, bool on) {
  auto& a = *m_atts.at(static_cast<std::size_t>(id));
  if (a.powered == on) return;
  settle_heard();
  const Ticks now = m_sched.now();
  if (!on) {
    a.powered = false;
    refresh_listening();
    for (auto& p : a.pending) m_pool.push_back(std::move(p.tx));
    a.pending.clear();
    ++a.power_epoch;
    ++a.timer_gen;
    a.deadline = a.next_event = kNever;
    ++a.babble_epoch;
    truncate_in_flight();
    emit_event(LineEventKind::PowerOff, id);
    a.dev->on_power_off(now);
    refresh_filter(static_cast<std::size_t>(id));
  } else {
    a.powered = true;
    a.uart_busy_until = kNeverHeard;
    m_heard_until[static_cast<std::size_t>(id)] = kNeverHeard;
    refresh_listening();
    join_in_flight();  // the rest of a frame already on the wire is activity it does hear
    emit_event(LineEventKind::PowerOn, id);
    a.dev->on_power_on(now);
    refresh_filter(static_cast<std::size_t>(id));
    if (a.babbling) babble_burst(a);
  }
}

void Line::set_transceiver_ok(AttachmentId id, bool ok) {
  auto& a = *m_atts.at(static_cast<std::size_t>(id));
  if (a.xcvr_ok == ok) return;
  settle_heard();
  a.xcvr_ok = ok;
  refresh_listening();
  if (!ok) truncate_in_flight();
  else join_in_flight();
  emit_event(ok ? LineEventKind::TransceiverRepaired : LineEventKind::TransceiverFailed, id);
}

void Line::set_babbling(AttachmentId id, bool on) {
  auto& a = *m_atts.at(static_cast<std::size_t>(id));
  if (a.babbling == on) return;
  a.babbling = on;
  ++a.babble_epoch;
  emit_event(on ? LineEventKind::BabbleOn : LineEventKind::BabbleOff, id);
  if (on && a.powered) babble_burst(a);
}

void Line::babble_burst(Attachment& a) {
  if (!a.babbling || !a.powered) return;
  // Garbage in bursts, back to back: the line never goes idle while it lasts.
  std::unique_ptr<Transmission> junk = take_transmission();
  junk->bytes.resize(kBabbleBurst);
  for (auto& b : junk->bytes) b = static_cast<std::uint8_t>(next_random());
  const Ticks end = m_sched.now() + chars_to_ticks(static_cast<std::int64_t>(kBabbleBurst), m_baud);
  start_transmission(a, std::move(junk), true);
  m_sched.schedule(end, a, (a.babble_epoch << 2) | kTagBabble);
}

}  // namespace pbvbus::bus
