#pragma once
// How much of a long capture the HTML page of `pbvbus timeline` holds (--max-frames).
//
// The page embeds every frame of its data, with its token spans and DP polls, so its size grows
// with the frames: about 25 octets a frame, 4.4 MB for the 10 s of examples/switched-io.textproto
// (two lines at 1.5 Mbit/s). A browser slows down well before the page stops loading, and a
// reader of a long run looks at one stretch at a time anyway.
//
// Decisions:
//  - A capture of at most `max_frames` frames (all lanes together) is embedded whole, as before;
//    the page opens at --from/--to. `max_frames` 0 means no limit.
//  - A longer capture gets a page of one window of at most `max_frames` frames: it starts at
//    --from (default the start of the capture) and ends at --to or at the start of the first
//    frame beyond the limit, whichever comes first (frames counted in start order over all
//    lanes, a frame belonging to the window when it overlaps it, as timeline.hpp defines). So
//    --from/--to choose the stretch and the limit bounds the page; frames starting at the same
//    instant as the first one left out are left out too (at most max_frames, never one more).
//    The window is never empty: it is at least 1 ns long.
//  - Only what comes with the frames is cut to the window: frames, token spans, DP polls (cycle
//    times and token holders are still worked out on the whole capture, timeline.hpp, so they
//    are the same as in a page of everything). The events, the active channels, the CPU rows and
//    the Quantum rows of the whole capture stay, and the page spans the whole capture: they are
//    few, and they are the overview a reader of a long run looks at first to find the stretch
//    worth the frames.
//    So the first view without --from/--to is still the whole run, with frames in the window
//    only.
//  - What was left out is said in the page (a note under the header) and by the command on
//    stderr: the window, how many of how many frames it holds, and how to get another window or
//    everything (page_window_note()).

#include <cstdint>
#include <optional>
#include <string>

#include "pbvbus/captures/timeline.hpp"

namespace pbvbus::captures {

/// The default of `pbvbus timeline --max-frames`: a page of about 1.5 MB (25000 frames of the
/// switched-io example made 735 kB). The 4 s multimaster capture of the README (29314 frames)
/// stays whole; the 10 s of switched-io (177044 frames) do not.
inline constexpr std::uint64_t kDefaultMaxPageFrames = 50000;

struct PageWindow {
  std::int64_t from_ns = 0;  ///< the window the page holds, [from_ns, to_ns)
  std::int64_t to_ns = 0;
  std::uint64_t frames = 0;        ///< frames in that window
  std::uint64_t total_frames = 0;  ///< frames in the whole capture
  bool cut = false;                ///< the page leaves frames of the capture out
};

/// The window of a page of at most `max_frames` frames of `whole` (a Timeline of the whole
/// capture, built without a window), for the requested --from/--to.
PageWindow page_window(const Timeline& whole, std::optional<std::int64_t> from,
                       std::optional<std::int64_t> to, std::uint64_t max_frames);

/// One line saying what the page leaves out ("" when it holds everything), e.g. "This page holds
/// the frames of 0.000000 s – 1.332524 s only (the capture: 0.000000 s – 9.999939 s): 25000 of
/// 177044 frames (--max-frames 25000); events and the rows below the lanes cover the whole
/// capture. Use --from/--to for another stretch, --max-frames 0 for all."
std::string page_window_note(const Timeline& whole, const PageWindow& w, std::uint64_t max_frames);

}  // namespace pbvbus::captures
