#pragma once
// pcapng capture writer (design.md "Captures"; pcapng per draft-ietf-opsawg-pcapng).
//
// A bus::Tap: add it to lines (line.add_tap(writer)) and every frame becomes an Enhanced Packet
// Block on the line's interface; line events and higher-layer events become records on the
// "events" interface (USER1, event_record.hpp).
//
// Decisions (where the pcapng spec is silent for a bus):
//  - One IDB per line: if_name = line name, if_description "PROFIBUS-DP <baud> bit/s",
//    if_speed = baud, if_tsresol = 9 (ns). Link type USER0 (147) unless asked for 257.
//  - Timestamp = virtual time of the start bit of the first character, in ns (rounded down).
//    Frames reach taps at their end, events at their time, so timestamps in the file are not
//    strictly increasing (an event during a frame precedes it in the file); Wireshark sorts
//    nothing and shows them in file order, which is the order things became known.
//  - epb_flags direction bits stay 0 (on a bus nothing is inbound or outbound); the
//    link-layer error bits say what went wrong:
//      collision                                  -> bit 24 symbol error
//      parity/framing error (noise), FCS mismatch -> bit 31 CRC error
//      partial (cut short by a fault), truncated  -> bit 29 packet too short
//      babbling transmitter                       -> bit 28 wrong inter-frame gap
//      unknown/second/end delimiter wrong         -> bit 26 start frame delimiter error
//      octets after the end of the frame          -> bit 30 packet too long
//    Every bad frame also gets an opt_comment with the reasons in words, e.g.
//    "collision, FCS mismatch" or "partial: 4 of 11 octets". Frames that are well formed on
//    the wire but break an FDL rule (reserved FC, SA 127, bad extension chain) get a comment and
//    no error bit: the link layer delivered them intact.
//  - A partial frame's original length equals its captured length: the octets that were on
//    the wire are all there; what the sender meant to send is in the comment.
//  - Sinks: a file, "-" for stdout (streamed: flushed after every block so that
//    `wireshark -k -i -` sees frames as they happen), or a callback. Otherwise blocks collect in
//    a 1 MiB buffer that is written in one go. Nothing is allocated per frame.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_format.hpp"

namespace pbvbus::bus {
class Line;
}

namespace pbvbus::captures {

struct PcapngWriterOptions {
  /// Link type of the line interfaces: User0 (default) or ProfibusDl.
  pcapng::LinkType line_link_type = pcapng::LinkType::User0;
  /// Flush after every block (set automatically for "-").
  bool streaming = false;
  /// shb_userappl
  std::string application = "pbvbus";
};

class PcapngWriter final : public bus::Tap {
 public:
  /// Receives finished octets; returns false on an I/O error (the writer then stops).
  using Sink = std::function<bool(std::span<const std::uint8_t>)>;

  /// Writes to `sink`. The Section Header Block goes out at once.
  explicit PcapngWriter(Sink sink, PcapngWriterOptions opts = {});
  ~PcapngWriter();
  PcapngWriter(const PcapngWriter&) = delete;
  PcapngWriter& operator=(const PcapngWriter&) = delete;

  /// Opens a file ("-" = stdout, streamed). nullptr with a reason in `error` on failure.
  static std::unique_ptr<PcapngWriter> open(const std::string& path, PcapngWriterOptions opts,
                                            std::string* error = nullptr);

  /// Declares the interface of a line now (otherwise it is added on the line's first frame).
  /// Returns the interface id; adding the same line again returns the same id.
  std::uint32_t add_line(const bus::Line& line);
  /// Declares any interface. `speed` 0 = no if_speed option.
  std::uint32_t add_interface(std::string_view name, std::string_view description,
                              pcapng::LinkType type, std::uint64_t speed);
  /// The "events" interface (USER1), created on first use.
  std::uint32_t events_interface();

  /// Writes one telegram as it was on the wire on `line`'s interface.
  void write_frame(const bus::TapFrame& f);
  /// Writes an event record at virtual time `time` on the events interface.
  void write_event(bus::Ticks time, const EventRecord& e);

  // bus::Tap
  void on_frame(const bus::TapFrame& f) override { write_frame(f); }
  void on_line_event(const bus::LineEvent& e) override;

  /// Writes buffered blocks to the sink.
  bool flush();
  /// False once the sink reported an error; nothing more is written then.
  bool ok() const { return m_ok; }
  const std::string& error() const { return m_error; }

  std::uint64_t frames_written() const { return m_frames; }
  std::uint64_t events_written() const { return m_events; }

 private:
  struct LineIf {
    const bus::Line* line;
    std::uint32_t id;
  };
  std::uint32_t interface_for(const bus::Line& line);
  void write_shb();
  void write_epb(std::uint32_t if_id, std::int64_t ts_ns, std::span<const std::uint8_t> data,
                 std::uint32_t flags, std::string_view comment);
  void block_done();
  std::uint8_t* reserve(std::size_t n);

  Sink m_sink;
  PcapngWriterOptions m_opts;
  std::vector<std::uint8_t> m_buf;
  std::size_t m_len = 0;
  std::vector<LineIf> m_lines;
  const bus::Line* m_last_line = nullptr;
  std::uint32_t m_last_id = 0;
  std::uint32_t m_next_if = 0;
  std::int64_t m_events_if = -1;
  std::int64_t m_unknown_if = -1;
  std::string m_comment;
  std::vector<std::uint8_t> m_event_buf;
  bool m_ok = true;
  std::string m_error;
  std::uint64_t m_frames = 0;
  std::uint64_t m_events = 0;
};

/// Link-layer error bits and the comment for one frame (shared with the tests and inspect).
/// `comment` receives the reasons in words ("" for a good frame); returns the epb_flags value.
std::uint32_t classify_frame(std::span<const std::uint8_t> bytes, std::uint16_t rx_flags,
                             std::uint32_t sent_len, std::string& comment);

/// Text of a line event, e.g. "cable cut between 'master 3' and 'slave 10'".
std::string describe_line_event(const bus::LineEvent& e);

}  // namespace pbvbus::captures
