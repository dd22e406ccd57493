#pragma once
// One RS-485 segment (design.md "The line").
//
// Carries 11-bit UART characters at the line's baud. Frames are delivered to each receiver as
// one event at the end of their last stop bit; what every station observes is the same as with
// character-by-character delivery:
//  - two transmissions that overlap in time on the same piece of cable corrupt each other's
//    overlapping characters (PROFIBUS has no collision detection; receivers see the damage);
//  - noise flips bits (seeded), which a receiver sees as parity, framing or FCS errors;
//  - a fault during a frame (cut, short, power loss, transceiver failure) ends it early, and
//    receivers that lose the sender see a partial frame at the moment of the fault;
//  - each receiver is told how long its segment was idle before the frame, which is what
//    the FDL layer needs for the TSYN rule.
// Propagation delay is taken as zero: at 12 Mbit/s 100 m of cable is ~6 bit times, less than
// min TSDR, and PROFIBUS timing is specified at the stations.
//
// A device's own telegrams never overlap each other: if it asks for a start while its previous
// telegram is still going out, the new one follows back to back (one UART per station).
//
// Taps come in two kinds (tap.hpp):
//  - Whole-line taps (add_tap(tap)) see each transmission once, from its sender's side of the
//    cable: a frame that a cable cut keeps from some receivers appears whole (the far side
//    receives it partial), while a frame cut short at its source (sender's power or transceiver
//    lost, short circuit) appears partial. Statistics (LineStats) and line tests use them.
//  - Probe taps (add_tap(tap, ProbePoint{a})) sit at the cable position of attachment `a` and
//    see what a receiver with a working transceiver at that position would see, whatever the
//    state of the station attached there (powered or not, transceiver working or not):
//      * the frames of senders on the probe's segment when the frame started, the station at
//        the probe's own position included;
//      * a frame whose sender a cut or short separates from the probe mid-frame ends there,
//        partial (kRxPartial, the whole characters received until then; nothing if not one
//        character had arrived), as do frames cut short at their source;
//      * corrupted as its segment saw it: collisions and noise belong to the transmission, and
//        a transmission only ever reaches its own segment, so a collision on the far side of a
//        cut never shows at the probe, and one after a repair does (join_in_flight);
//      * nothing while the line is shorted, nothing of a frame whose start it did not hear
//        (a repair joining it to a frame already on the wire).
//    A probe is a tap, not a station: it never transmits, takes no part in the idle-time
//    bookkeeping and changes nothing that the stations observe. At most kMaxProbes per line.
// Transmissions that never reach the cable (short circuit, failed transceiver) are counted in
// LineStats::lost and reach no tap. Line events reach every tap once (not once per probe).
// Taps are called at the end of a frame, so frames that overlap reach them out of start order;
// earliest_start_in_flight() tells a tap which starts can still come (captures use it to write
// in start order).
//
// Receive filters are cached: the line re-reads Device::receive_filter() after every call into
// the device, and on DevicePort::receive_filter_changed().
//
// Attachments keep the order in which they were attached: that is their position along the
// cable, which is what a cable cut between two stations refers to.

#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pbvbus/bus/device.hpp"
#include "pbvbus/bus/scheduler.hpp"
#include "pbvbus/bus/tap.hpp"

namespace pbvbus::bus {

using AttachmentId = int;

/// Where a probe tap sits: at the cable position of attachment `at`.
struct ProbePoint {
  AttachmentId at = 0;
};

struct LineStats {
  std::uint64_t frames = 0;       ///< transmissions started
  std::uint64_t collisions = 0;   ///< transmissions damaged by overlap
  std::uint64_t noisy = 0;        ///< transmissions with at least one flipped bit
  std::uint64_t partial = 0;      ///< transmissions cut short by a fault (for anyone)
  std::uint64_t lost = 0;         ///< transmissions nobody could hear (short, dead transceiver)
  std::uint64_t octets = 0;       ///< octets put on the wire
};

class Line final : private EventTarget {
 public:
  static constexpr int kMaxAttachments = 256;
  /// Probe taps per line (each in-flight frame keeps one bit per probe).
  static constexpr int kMaxProbes = 64;

  Line(Scheduler& sched, std::string name, Baud baud, std::uint64_t seed = 1);
  ~Line();
  Line(const Line&) = delete;
  Line& operator=(const Line&) = delete;

  const std::string& name() const { return m_name; }
  Baud baud() const { return m_baud; }
  Ticks bit_ticks() const { return ticks_per_bit(m_baud); }
  Scheduler& scheduler() { return m_sched; }
  int index() const { return m_index; }
  void set_index(int i) { m_index = i; }

  /// Attaches `dev` at the next position along the cable. The device stays unpowered until
  /// power_on() (or start()).
  AttachmentId attach(Device& dev, std::string label = {});
  int attachment_count() const { return static_cast<int>(m_atts.size()); }
  Device& device(AttachmentId a);
  const std::string& label(AttachmentId a) const;
  bool powered(AttachmentId a) const;

  /// Powers every attachment that is not yet powered, at the current time.
  void start();

  /// A whole-line tap: every transmission, from its sender's side (see the file comment).
  void add_tap(Tap& tap);
  /// A probe tap at the cable position of attachment `p.at` (std::out_of_range if there is no
  /// such attachment, std::length_error beyond kMaxProbes). One tap may sit at several points
  /// (TapFrame::probe tells them apart) and be a whole-line tap too. A probe added while frames
  /// are on the wire hears only frames that start later.
  void add_tap(Tap& tap, ProbePoint p);
  /// Removes every registration of `tap` (whole-line and probes).
  void remove_tap(Tap& tap);
  int probe_count() const { return static_cast<int>(m_probes.size()); }
  /// Where `tap` sits on this line: whether it is a whole-line tap, and its probe positions in
  /// the order they were added (for a tap that declares itself lazily, e.g. a capture).
  bool is_whole_line_tap(const Tap& tap) const;
  std::vector<AttachmentId> probe_points(const Tap& tap) const;

  /// The earliest start among the transmissions still on the wire (anywhere on the line, cut
  /// short or not yet delivered; the one whose end the taps are being told about included), or
  /// kNever if there is none. Every frame that a tap will still be told about starts at or after
  /// min(this, now).
  Ticks earliest_start_in_flight() const;

  // --- faults and repairs (each takes effect at the scheduler's current time) ---------------
  /// Cuts the cable between position `a` and the position after it (a, a+1). Both sides go on
  /// working as separate segments.
  void set_cut_after(AttachmentId a, bool cut);
  /// Cuts between two attachments: at the cable position right after the first of the two.
  void set_cut_between(AttachmentId a, AttachmentId b, bool cut);
  /// A short circuit: nothing can be received anywhere on the line.
  void set_short_circuit(bool on);
  /// Bit error rate in errors per 10^9 bits; 0 = no noise.
  void set_noise(std::uint64_t errors_per_billion);
  void set_power(AttachmentId a, bool on);
  /// A failed transceiver neither drives nor hears the line; the device does not notice.
  void set_transceiver_ok(AttachmentId a, bool ok);
  /// A babbling transmitter drives garbage continuously until stopped.
  void set_babbling(AttachmentId a, bool on);

  bool short_circuit() const { return m_short; }
  bool cut_after(AttachmentId a) const;
  /// Whether a and b can currently hear each other (same segment, line not shorted).
  bool connected(AttachmentId a, AttachmentId b) const;

  const LineStats& stats() const { return m_stats; }

 private:
  struct Attachment;
  struct Transmission;
  /// A set of attachments, iterable by set bit without scanning every attachment.
  struct Mask {
    std::array<std::uint64_t, kMaxAttachments / 64> w{};
    void set(std::size_t i) { w[i >> 6] |= std::uint64_t{1} << (i & 63); }
    void reset(std::size_t i) { w[i >> 6] &= ~(std::uint64_t{1} << (i & 63)); }
    bool test(std::size_t i) const { return (w[i >> 6] >> (i & 63)) & 1; }
    void clear() { w.fill(0); }
    template <class F>
    void for_each(F&& f) const {
      for (std::size_t k = 0; k < w.size(); ++k)
        for (std::uint64_t b = w[k]; b != 0; b &= b - 1)
          f(k * 64 + static_cast<std::size_t>(std::countr_zero(b)));
    }
  };

  class Port;
  friend class Port;

  void on_event(Ticks now, std::uint64_t tag) override;  // end of transmission `tag`
  /// Puts `t`'s bytes on the wire now (it goes back to the pool afterwards).
  void start_transmission(Attachment& from, std::unique_ptr<Transmission> t, bool babble);
  /// A transmission from the pool (bytes to be filled in); pending transmissions are pooled
  /// objects too, so a frame's bytes are copied once, from the device into the line.
  std::unique_ptr<Transmission> take_transmission();
  /// After a repair that joins segments or revives a transceiver: receivers start hearing the
  /// rest of frames already on the wire (as garbage), and frames that now share the cable
  /// corrupt each other from here on.
  void join_in_flight();
  void end_transmission(std::uint64_t id);
  /// Hands a frame (or its first `len` octets) to one receiver; filtering is the caller's job.
  void deliver(Transmission& t, std::size_t to, std::size_t len, std::uint16_t extra_flags, Ticks end);
  /// Re-reads attachment i's receive filter into the cache (after every call into the device).
  void refresh_filter(std::size_t i);
  /// Whether attachment i's (cached) filter takes a frame with destination `da` (-1: none).
  bool accepts(std::size_t i, int da) const;
  /// What the taps see of transmission `t` (its first `len` octets), whole-line or at a probe.
  TapFrame tap_view(const Transmission& t, std::size_t len, std::uint16_t extra_flags,
                    Ticks end) const;
  void tap_frame(const Transmission& t, std::size_t len, std::uint16_t extra_flags, Ticks end);
  /// Hands the frame (or its first `len` octets) to the probes in `probes` (bits of m_probes).
  void probe_frame(const Transmission& t, std::uint64_t probes, std::size_t len,
                   std::uint16_t extra_flags, Ticks end);
  /// Rebuilds m_probe_by_segment and m_event_taps after a change of taps or of topology.
  void refresh_probes();
  void apply_noise(Transmission& t);
  void recompute_segments();
  /// Rebuilds m_listening after any change of power, transceiver, cut or short.
  void refresh_listening();
  /// Ends an epoch of the idle-time bookkeeping: writes every listener's m_heard_until from
  /// m_seg_heard and gives the frames on the wire their receivers' idle times. Called before
  /// anything changes who listens on which segment (attach, power, transceiver, cut, short).
  void settle_heard();
  /// After a topology or power change: cut short every in-flight frame for receivers that can
  /// no longer hear its sender.
  void truncate_in_flight();
  bool can_hear(const Attachment& rx, const Attachment& tx) const;
  void emit_event(LineEventKind k, int a = -1, int b = -1, std::uint64_t v = 0);
  void babble_burst(Attachment& a);
  std::uint64_t next_random();

  Scheduler& m_sched;
  std::string m_name;
  Baud m_baud;
  int m_index = 0;
  std::vector<std::unique_ptr<Attachment>> m_atts;
  std::vector<Tap*> m_taps;  ///< whole-line taps
  struct ProbeTap {
    Tap* tap;
    AttachmentId at;
  };
  std::vector<ProbeTap> m_probes;
  /// Per segment: the probes (bits of m_probes) that hear it; none while the line is shorted.
  std::vector<std::uint64_t> m_probe_by_segment;
  std::vector<Tap*> m_event_taps;  ///< every tap once, in order of first registration
  /// Start of the frame whose end the taps are being told about (kNever otherwise).
  Ticks m_tapping_start = kNever;
  std::vector<std::unique_ptr<Transmission>> m_in_flight;
  /// Transmissions recycled (pending, on the wire, done), so that the per-frame path does not
  /// allocate once the line has warmed up.
  std::vector<std::unique_ptr<Transmission>> m_pool;
  // Hot per-attachment state, indexed by attachment id, kept contiguous for the per-frame loops.
  std::vector<Device*> m_devs;
  /// End of the last activity an attachment has heard or is hearing (frames received, cut
  /// short for it or still on the wire, its own transmissions); the start of its idle time.
  /// For a listener, only up to the start of the current epoch (see m_seg_heard).
  std::vector<Ticks> m_heard_until;
  /// Per segment: attachments that are powered and have a working transceiver (none while
  /// the line is shorted).
  std::vector<Mask> m_listening;
  /// Per segment: end of the latest activity on it in the current epoch (kNeverHeard: none).
  /// Between two changes of who listens where (an epoch), every listener of a segment hears
  /// every frame on it, so a listener has heard until max(m_heard_until, this): a frame costs
  /// one update instead of one per listener. settle_heard() folds it into m_heard_until.
  std::vector<Ticks> m_seg_heard;
  /// Cached receive filters (kReceiveAll or 0..126) and the masks built from them, so that a
  /// frame reaches its addressee without asking 32 other stations whether they want it.
  std::vector<int> m_filter;
  std::vector<Mask> m_by_addr = std::vector<Mask>(128);
  Mask m_receive_all;  ///< attachments with kReceiveAll
  Mask m_filtered;     ///< attachments with an address filter
  bool m_short = false;
  std::uint64_t m_noise_ppb = 0;
  std::uint64_t m_rng;
  std::uint64_t m_next_tx_id = 0;
  LineStats m_stats;
};

}  // namespace pbvbus::bus
