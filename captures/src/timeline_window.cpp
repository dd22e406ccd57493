// Decisions: timeline_window.hpp.
#include "pbvbus/captures/timeline_window.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>

namespace pbvbus::captures {

namespace {

// timeline.hpp "Window": a frame belongs to [from, to) when it overlaps it (a frame without
// length when it starts in it).
bool overlaps(const TimelineFrame& f, std::int64_t from, std::int64_t to) {
  return f.start_ns < to && (f.end_ns > from || (f.end_ns == f.start_ns && f.start_ns >= from));
}

std::string seconds(std::int64_t ns) {
  char b[48];
  std::snprintf(b, sizeof b, "%lld.%06lld s", static_cast<long long>(ns / 1000000000),
                static_cast<long long>((ns % 1000000000) / 1000));
  return b;
}

}  // namespace

PageWindow page_window(const Timeline& whole, std::optional<std::int64_t> from,
                       std::optional<std::int64_t> to, std::uint64_t max_frames) {
  PageWindow w;
  for (const auto& lane : whole.lanes) w.total_frames += lane.frames.size();
  w.from_ns = whole.from_ns;
  w.to_ns = whole.to_ns;
  w.frames = w.total_frames;
  if (max_frames == 0 || w.total_frames <= max_frames) return w;

  w.from_ns = from.value_or(whole.from_ns);
  const std::int64_t limit = to.value_or(whole.to_ns);
  std::vector<std::int64_t> starts;
  for (const auto& lane : whole.lanes)
    for (const auto& f : lane.frames)
      if (overlaps(f, w.from_ns, limit)) starts.push_back(f.start_ns);
  std::sort(starts.begin(), starts.end());
  w.to_ns = limit;
  if (starts.size() > max_frames) w.to_ns = starts[max_frames];
  w.to_ns = std::max(w.to_ns, w.from_ns + 1);
  w.frames = 0;
  for (const auto& lane : whole.lanes)
    for (const auto& f : lane.frames) w.frames += overlaps(f, w.from_ns, w.to_ns) ? 1 : 0;
  w.cut = w.frames < w.total_frames;
  return w;
}

std::string page_window_note(const Timeline& whole, const PageWindow& w, std::uint64_t max_frames) {
  if (!w.cut) return {};
  return "This page holds the frames of " + seconds(w.from_ns) + " \u2013 " + seconds(w.to_ns) +
         " only (the capture: " + seconds(whole.from_ns) + " \u2013 " + seconds(whole.to_ns) + "): " +
         std::to_string(w.frames) + " of " + std::to_string(w.total_frames) + " frames (--max-frames " +
         std::to_string(max_frames) +
         "); events and the rows below the lanes cover the whole capture. Use --from/--to for another "
         "stretch, --max-frames 0 for all.";
}

}  // namespace pbvbus::captures
