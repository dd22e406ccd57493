#pragma once
// `pbvbus replay CAPTURE --to PTY` (docs/replay.md): plays a capture's frames
// raw into a serial port for an analyzer program, with the original pacing scaled by a speed
// ratio (wall time). This is the one part of replay that does I/O.
//
// Decisions:
//  - Frames: every record of every USER0/257 interface in file order, or only those of one line
//    (`line`); event records are not played. Damaged records are played as recorded (an
//    analyzer on a real bus sees those octets too).
//  - Pacing: record k is written at wall time (ts_k − ts_first) · den / num after the start
//    (`speed` N/M as in PacedRunner: 1/10 plays ten times slower). A write never waits for the
//    reader: the port is non-blocking, octets the port does not take wait in a bounded buffer
//    (`max_buffer`); a frame that does not fit is dropped whole and counted. At the end the
//    buffer gets `drain_ms` to go out (with a created pty, also until the reader has read
//    what the pty holds: FIONREAD on our slave handle); what is left then counts as dropped. So a reader that does
//    not read makes the player finish on time with a count of dropped octets, never hang.
//  - The port: open_serial_target() creates a pseudo-terminal (slave side in raw mode, kept open
//    by the player so a reader may open and close it) and makes `link` a symbolic link to it
//    (replacing an old symlink, never a file), or opens an existing tty/pty path (raw mode when it
//    is a terminal).

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

namespace pbvbus::conformance {

struct SerialPlayOptions {
  std::uint32_t speed_num = 1, speed_den = 1;  ///< virtual : wall
  std::string line;                            ///< "" = every line interface
  std::size_t max_buffer = 64 * 1024;
  int drain_ms = 1000;
};

struct SerialPlayStats {
  std::uint64_t frames = 0;           ///< frames of the capture to play
  std::uint64_t frames_written = 0;   ///< accepted whole (written or buffered)
  std::uint64_t frames_dropped = 0;
  std::uint64_t octets_written = 0;   ///< taken by the port
  std::uint64_t octets_dropped = 0;   ///< dropped frames' octets + what was left at the end
  std::int64_t wall_ms = 0;
};

/// A serial port to play into. Closes (and removes its link) when destroyed.
class SerialTarget {
 public:
  ~SerialTarget();
  SerialTarget(const SerialTarget&) = delete;
  SerialTarget& operator=(const SerialTarget&) = delete;
  int fd() const { return m_fd; }
  /// Our handle on a created pty's slave side (-1 for an opened path).
  int slave_fd() const { return m_slave; }
  /// The device path (the pty's slave side, or the path opened).
  const std::string& path() const { return m_path; }

 private:
  friend std::unique_ptr<SerialTarget> open_serial_target(const std::string&, bool, std::string&);
  SerialTarget() = default;
  int m_fd = -1;
  int m_slave = -1;
  std::string m_path;
  std::string m_link;
};

/// `create_pty`: a new pty linked at `path`; else opens `path` (a tty). nullptr + error on failure.
std::unique_ptr<SerialTarget> open_serial_target(const std::string& path, bool create_pty,
                                                 std::string& error);

/// Plays the capture `data` into `target`. nullopt + error on a capture that cannot be read or
/// has nothing to play.
std::optional<SerialPlayStats> play_to_serial(std::span<const std::uint8_t> data,
                                              SerialTarget& target, const SerialPlayOptions& opts,
                                              std::string& error);

}  // namespace pbvbus::conformance
