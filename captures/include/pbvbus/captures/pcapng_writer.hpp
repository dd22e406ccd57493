#pragma once
// pcapng capture writer (design.md "Captures"; pcapng per draft-ietf-opsawg-pcapng).
//
// A bus::Tap. A capture is what an analyzer clipped onto the cable at one point sees, so the
// usual way in is a probe: line.add_tap(writer, bus::ProbePoint{a}) (declared first with
// add_probe() to choose its interface name); every frame that reaches that point becomes an
// Enhanced Packet Block on the probe's interface. A whole-line tap (line.add_tap(writer),
// declared with add_line()) records every transmission from its sender's side instead: during a
// cable cut both partitions interleave there, which no analyzer could see. Line events and
// higher-layer events become records on the "events" interface (USER1, event_record.hpp).
//
// Decisions (where the pcapng spec is silent for a bus):
//  - One IDB per probe (or per whole-line tap): link type USER0 (147) unless asked for 257,
//    if_speed = baud, if_tsresol = 9 (ns); if_name = the line's name, or what add_probe() was
//    given (e.g. "A@14" when a line has several probes); if_description
//    "PROFIBUS-DP 1.5 Mbit/s, probe at station 14" (the `where` given to add_probe(), else the
//    attachment's label), "PROFIBUS-DP 1.5 Mbit/s" for a whole-line tap; "MPI ..." instead of
//    "PROFIBUS-DP ..." for a line marked with mark_mpi(). Interfaces the caller
//    did not declare are declared when the line first reports something (event or frame), all
//    of the writer's taps on that line at once, in the order they were added; a lazily declared
//    probe is named after the line, or "LINE@label" when the writer has other taps there.
//  - Timestamp = virtual time of the start bit of the first character, in ns (rounded down);
//    events at their time.
//  - Records are written in order of timestamp (start of frame), across all interfaces, and in
//    order of arrival for equal times. Frames reach taps at their end, so a frame that overlaps
//    a longer one that started earlier (a collision, a babbling transmitter), and an event
//    during a frame, are held back until every transmission still on the wire of every line
//    the writer knows started at or after them (bus::Line::earliest_start_in_flight()). The
//    common case — nothing else on the wire — goes straight out. flush() writes whatever is
//    still held: call it when the run is over (a record that arrives after a flush() with an
//    earlier start than what was flushed is written late, out of order). Declare every line
//    before the run (add_line/add_probe): a line the writer does not know yet cannot hold
//    records back.
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
//    `wireshark -k -i -` sees frames as they happen, held records once released), or a
//    callback. Otherwise blocks collect in a 1 MiB buffer that is written in one go. Nothing is
//    allocated per frame once the hold-back buffers have grown to the largest overlap.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pbvbus/bus/line.hpp"
#include "pbvbus/bus/tap.hpp"
#include "pbvbus/captures/event_record.hpp"
#include "pbvbus/captures/pcapng_format.hpp"
#include "pbvbus/fdl/decoded_frame.hpp"

namespace pbvbus::captures {

/// What write_s7_pdu() knows about an S7 PDU besides its octets.
struct S7PduInfo {
  /// epb_flags direction: Inbound = towards the S7 server (a client's job), Outbound = from it
  /// (the server's ack or ack-data); Unknown writes no direction.
  enum class Direction : std::uint8_t { Unknown = 0, Inbound = 1, Outbound = 2 };
  Direction direction = Direction::Unknown;
  /// IPv4 addresses (host order, 127.0.0.1 = 0x7F000001) and TCP ports of sender and receiver,
  /// for door traffic: written as exported-PDU tags (tshark shows them as the packet's source
  /// and destination). 0 = left out.
  std::uint32_t src_ip = 0;
  std::uint32_t dst_ip = 0;
  std::uint16_t src_port = 0;
  std::uint16_t dst_port = 0;
  /// opt_comment of the record, e.g. "door connection 3 -> CPU rack 0 slot 3" ("" = none).
  std::string_view comment;
};

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

  /// Declares the whole-line interface of a line now (for line.add_tap(writer)). Returns the
  /// interface id; adding the same line again returns the same id.
  std::uint32_t add_line(const bus::Line& line);
  /// Declares the interface of the probe at attachment `at` of `line` (for
  /// line.add_tap(writer, bus::ProbePoint{at})). `name` empty: the line's name; `where` empty:
  /// the attachment's label. Adding the same probe again returns the same id.
  std::uint32_t add_probe(const bus::Line& line, bus::AttachmentId at, std::string_view name = {},
                          std::string_view where = {});
  /// Declares any interface. `speed` 0 = no if_speed option.
  std::uint32_t add_interface(std::string_view name, std::string_view description,
                              pcapng::LinkType type, std::uint64_t speed);
  /// The "events" interface (USER1), created on first use.
  std::uint32_t events_interface();

  /// Marks `line` as an MPI subnet (protocol-facts.md §H): its interfaces get the if_description
  /// "MPI 187.5 kbit/s[, probe at ...]" instead of "PROFIBUS-DP ...", which the Lua dissector
  /// and the timeline take as "decode MPI here" (captures/README.md "MPI and S7"). Call it
  /// before the line's interfaces are declared (add_line/add_probe or the line's first record);
  /// false if one of them already is (it keeps its description).
  bool mark_mpi(const bus::Line& line);
  /// Declares an interface for S7 PDUs: link type 252 (LINKTYPE_WIRESHARK_UPPER_PDU), no
  /// speed; `description` empty: "S7 PDUs (exported PDU for s7comm)". Several are allowed (e.g.
  /// one per door or per CPU); each call declares a new one.
  std::uint32_t add_s7_interface(std::string_view name, std::string_view description = {});
  /// Writes one S7 PDU (starting with 0x32, §H.4; written as given) at virtual time `time` on an
  /// interface from add_s7_interface(), in time order with the frames: the exported-PDU tags
  /// (heuristic dissector "s7comm_cotp", then IPv4 addresses and TCP ports when `info` has
  /// them, then the end tag) and the PDU. False (nothing written) for an interface that is not
  /// an S7 interface or once the sink failed.
  bool write_s7_pdu(std::uint32_t iface, bus::Ticks time, std::span<const std::uint8_t> s7_pdu,
                    const S7PduInfo& info = {});

  /// Writes one telegram as it was on the wire (or at the probe) on its interface, in start
  /// order (held back while an earlier transmission is still on the wire).
  void write_frame(const bus::TapFrame& f);
  /// Writes an event record at virtual time `time` (the current time) on the events interface,
  /// in time order with the frames.
  void write_event(bus::Ticks time, const EventRecord& e);

  // bus::Tap
  void on_frame(const bus::TapFrame& f) override { write_frame(f); }
  void on_line_event(const bus::LineEvent& e) override;

  /// Writes every held record and the buffered blocks to the sink (see "Records are written in
  /// order" above).
  bool flush();
  /// Records accepted but held back for start-time order.
  std::size_t held() const { return m_held.size(); }
  /// False once the sink reported an error; nothing more is written then.
  bool ok() const { return m_ok; }
  const std::string& error() const { return m_error; }

  std::uint64_t frames_written() const { return m_frames; }
  std::uint64_t events_written() const { return m_events; }
  std::uint64_t s7_pdus_written() const { return m_s7_pdus; }

 private:
  struct LineIf {
    const bus::Line* line;
    int probe;  ///< attachment of the probe; -1 whole-line
    std::uint32_t id;
  };
  /// A record waiting for start-time order: its encoded block in m_hold.
  struct Held {
    bus::Ticks ts;
    std::size_t off;
    std::size_t len;
  };
  /// The interface of a frame from `line` at `probe` (the last one asked is kept at hand).
  std::uint32_t interface_for(const bus::Line& line, int probe) {
    if (&line == m_last_line && probe == m_last_probe) return m_last_id;
    return find_interface(line, probe);
  }
  std::uint32_t find_interface(const bus::Line& line, int probe);
  std::uint32_t declare(const bus::Line& line, int probe, std::string_view name,
                        std::string_view where);
  /// Declares the interfaces of all of this writer's taps on `line` not declared yet.
  void declare_taps_of(const bus::Line& line);
  void write_shb();
  /// Encodes an EPB and writes it now or holds it back: `ts` its time, `now` the current time.
  void put_epb(bus::Ticks ts, bus::Ticks now, std::uint32_t if_id,
               std::span<const std::uint8_t> data, std::uint32_t flags, std::string_view comment);
  /// Writes the held records with a time up to `upto`.
  void release(bus::Ticks upto);
  /// The earliest start still on the wire of the lines the writer knows.
  bus::Ticks earliest_in_flight() const;
  void block_done();
  std::uint8_t* reserve(std::size_t n);
  bool flush_buffer();

  Sink m_sink;
  PcapngWriterOptions m_opts;
  std::vector<std::uint8_t> m_buf;
  std::size_t m_len = 0;
  std::vector<LineIf> m_lines;
  std::vector<const bus::Line*> m_known_lines;  ///< each line once
  const bus::Line* m_last_line = nullptr;
  int m_last_probe = -2;
  std::uint32_t m_last_id = 0;
  std::vector<Held> m_held;          ///< ordered by ts, then arrival
  std::vector<std::uint8_t> m_hold;  ///< their blocks
  std::vector<std::uint8_t> m_hold_spare;
  std::uint32_t m_next_if = 0;
  std::int64_t m_events_if = -1;
  std::int64_t m_unknown_if = -1;
  std::string m_comment;
  fdl::DecodedFrame m_scratch;  ///< decode_once()'s scratch (a frame without a memo)
  std::vector<std::uint8_t> m_event_buf;
  bool m_ok = true;
  std::string m_error;
  std::uint64_t m_frames = 0;
  std::uint64_t m_events = 0;
  std::uint64_t m_s7_pdus = 0;
  std::vector<const bus::Line*> m_mpi_lines;
  std::vector<std::uint32_t> m_s7_ifs;
  std::vector<std::uint8_t> m_s7_buf;
};

/// Link-layer error bits and the comment for one frame (shared with the tests and inspect).
/// `comment` receives the reasons in words ("" for a good frame); returns the epb_flags value.
std::uint32_t classify_frame(std::span<const std::uint8_t> bytes, std::uint16_t rx_flags,
                             std::uint32_t sent_len, std::string& comment);

/// Text of a line event, e.g. "cable cut between 'master 3' and 'slave 10'".
std::string describe_line_event(const bus::LineEvent& e);

}  // namespace pbvbus::captures
