// The user program of an H-CPU: one OB 1 over a ProcessImage (devices/h_program.hpp).
#include "pbvbus/s7h/h_program.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

#include "pbvbus/s7h/h_dp_sfc.hpp"

namespace pbvbus::devices {
namespace {

constexpr std::uint8_t kCounterStarted = 0x01;
constexpr std::uint8_t kMonitorDiffering = 0x01;
constexpr std::uint8_t kMonitorRaised = 0x02;

std::int64_t get_i64(std::span<const std::uint8_t> p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[static_cast<std::size_t>(i)];
  return static_cast<std::int64_t>(v);
}
void put_i64(std::span<std::uint8_t> p, std::int64_t s) {
  auto v = static_cast<std::uint64_t>(s);
  for (int i = 7; i >= 0; --i, v >>= 8) p[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v);
}
std::uint32_t get_u32(std::span<const std::uint8_t> p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         p[3];
}
/// The low `width` octets of v, big-endian.
void put_be(std::span<std::uint8_t> p, std::uint32_t v, std::size_t width) {
  for (std::size_t i = width; i-- > 0; v >>= 8) p[i] = static_cast<std::uint8_t>(v);
}

/// a + b for b > 0, saturating at the largest Ticks (a scan near the end of time must not
/// overflow; nothing realistic gets there: 2^63 ticks are 80 years).
bus::Ticks sat_add(bus::Ticks a, bus::Ticks b) {
  return a > std::numeric_limits<bus::Ticks>::max() - b ? std::numeric_limits<bus::Ticks>::max()
                                                         : a + b;
}

void run_counter(const CounterNetwork& n, std::span<std::uint8_t> state,
                 std::span<std::uint8_t> piq, bus::Ticks now) {
  bus::Ticks next = get_i64(state.subspan(0, 8));
  std::uint32_t value = get_u32(state.subspan(8, 4));
  if (!(state[12] & kCounterStarted)) {
    // First scan: the epoch. Value 0, the first period starts now.
    next = sat_add(now, n.period);
    value = 0;
    state[12] = kCounterStarted;
  } else if (now >= next) {
    // Every boundary in (last boundary, now]: next, next + period, ... ≤ now.
    const bus::Ticks passed = (now - next) / n.period + 1;
    value += static_cast<std::uint32_t>(static_cast<std::uint64_t>(passed) * n.step);
    const bus::Ticks advance = passed > (std::numeric_limits<bus::Ticks>::max() / n.period)
                                   ? std::numeric_limits<bus::Ticks>::max()
                                   : passed * n.period;
    next = sat_add(next, advance);
  }
  put_i64(state.subspan(0, 8), next);
  put_be(state.subspan(8, 4), value, 4);
  put_be(piq.subspan(n.output, n.width), value, n.width);
  if (n.pulse_high > 0) {
    const bus::Ticks period_start = next - n.period;  // next ≥ period: now ≥ 0 at the epoch
    const bool high = now >= period_start && now - period_start < n.pulse_high;
    const auto bit = static_cast<std::uint8_t>(1u << n.pulse_bit);
    std::uint8_t& q = piq[n.pulse_output];
    q = high ? static_cast<std::uint8_t>(q | bit) : static_cast<std::uint8_t>(q & ~bit);
  }
}

void run_monitor(const DiscrepancyNetwork& n, std::uint32_t index, std::span<std::uint8_t> state,
                 std::span<const std::uint8_t> pii, std::span<std::uint8_t> piq, bus::Ticks now,
                 std::vector<ProgramEvent>& events) {
  const auto a = pii.subspan(n.input_a, n.length);
  const auto b = pii.subspan(n.input_b, n.length);
  auto last = state.subspan(Program::kMonitorStateHeaderBytes, n.length);
  auto out = piq.subspan(n.to_output, n.length);
  bool differ = false;
  for (std::size_t i = 0; i < n.length; ++i) {
    const auto d = static_cast<std::uint8_t>((a[i] ^ b[i]) & n.mask);
    if (d) differ = true;
    const auto agreed = static_cast<std::uint8_t>(n.mask & ~d);
    last[i] = static_cast<std::uint8_t>((last[i] & d) | (a[i] & agreed));
    out[i] = static_cast<std::uint8_t>((a[i] & ~n.mask) | last[i]);
  }
  std::uint8_t& flags = state[8];
  auto event = [&](bool incoming) {
    events.push_back(ProgramEvent{now, kDiscrepancyError, incoming, index, n.input_a, n.input_b,
                                  n.length, -1});
  };
  if (differ) {
    if (!(flags & kMonitorDiffering)) {
      flags = kMonitorDiffering;
      put_i64(state.subspan(0, 8), now);
    }
    const bus::Ticks since = get_i64(state.subspan(0, 8));
    // ≥: expired when the whole discrepancy time has run (header comment).
    if (!(flags & kMonitorRaised) && now >= since && now - since >= n.discrepancy_time) {
      flags |= kMonitorRaised;
      event(true);
    }
  } else {
    if (flags & kMonitorRaised) event(false);
    flags = 0;
    put_i64(state.subspan(0, 8), 0);
  }
}

}  // namespace

Program::Program(ProgramSpec spec, std::size_t pii_bytes, std::size_t piq_bytes)
    : spec_(std::move(spec)), pii_bytes_(pii_bytes), piq_bytes_(piq_bytes) {
  auto errors = validate(spec_, pii_bytes, piq_bytes);
  if (!errors.empty()) throw std::invalid_argument(errors.front());
  memory_bytes_ = spec_.counters.size() * kCounterStateBytes;
  monitor_offsets_.reserve(spec_.monitors.size());
  for (const auto& m : spec_.monitors) {
    monitor_offsets_.push_back(memory_bytes_);
    memory_bytes_ += kMonitorStateHeaderBytes + m.length;
  }
}

std::size_t Program::counter_state_offset(std::size_t counter) const {
  return counter * kCounterStateBytes;
}
std::size_t Program::monitor_state_offset(std::size_t monitor) const {
  return monitor < monitor_offsets_.size() ? monitor_offsets_[monitor] : memory_bytes_;
}

ProcessImage Program::make_image() const { return ProcessImage(pii_bytes_, piq_bytes_, memory_bytes_); }

bool Program::fits(const ProcessImage& image) const {
  return image.pii().size() == pii_bytes_ && image.piq().size() == piq_bytes_ &&
         image.memory().size() >= memory_bytes_;
}

bool Program::scan(ProcessImage& image, bus::Ticks now, std::vector<ProgramEvent>& events) const {
  if (now < 0 || !fits(image)) return false;
  const auto pii = image.pii();
  const auto piq = image.piq();
  const auto mem = image.memory();
  for (const auto& n : spec_.copies)
    std::copy_n(pii.begin() + n.from_input, n.length, piq.begin() + n.to_output);
  for (std::size_t i = 0; i < spec_.counters.size(); ++i)
    run_counter(spec_.counters[i], mem.subspan(counter_state_offset(i), kCounterStateBytes), piq,
                now);
  for (std::size_t i = 0; i < spec_.monitors.size(); ++i) {
    const auto& m = spec_.monitors[i];
    run_monitor(m, static_cast<std::uint32_t>(i),
                mem.subspan(monitor_offsets_[i], kMonitorStateHeaderBytes + m.length), pii, piq,
                now, events);
  }
  run_dp_sfcs(spec_, pii, piq, mem, now);  // SFC 14/15 (h_dp_sfc.hpp)
  return true;
}

void Program::set_io_modules(std::vector<IoModuleExtent> modules) { spec_.io_modules = std::move(modules); }

std::vector<ProgramEvent> Program::scan(ProcessImage& image, bus::Ticks now) const {
  std::vector<ProgramEvent> events;
  scan(image, now, events);
  return events;
}

}  // namespace pbvbus::devices
