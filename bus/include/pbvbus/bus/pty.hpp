#pragma once
// Pseudo-terminals for programs outside pbvbus (the pty attachment, the Modbus RTU and SLCAN
// doors, replay into a serial port): one way to open them and one way to give them a stable name.
//
// Why the slave side stays open: while no program holds it, reads on the master side would fail
// with EIO and written octets would be lost; keeping our own descriptor lets a program close and
// reopen the pty at any time. Why raw: FDL, Modbus RTU and SLCAN octets must pass unchanged (no
// echo, no line editing, no CR/LF mapping).

#include <string>

namespace pbvbus::bus {

struct Pty {
  int master = -1;   ///< our side: non-blocking, close-on-exec
  int slave = -1;    ///< the program's side, kept open by us: raw, VMIN 1, non-blocking
  std::string path;  ///< the slave side's name (/dev/pts/N)
};

/// Opens a pseudo-terminal as described above. Throws std::system_error naming the failing call;
/// nothing stays open then.
Pty open_pty();

/// Makes `link` a symbolic link to `target`. A stale symlink of that name (an earlier run's) is
/// replaced; any other file of that name is left alone and is an error. Returns "" on success,
/// else why not.
std::string make_pty_link(const std::string& target, const std::string& link);

}  // namespace pbvbus::bus
