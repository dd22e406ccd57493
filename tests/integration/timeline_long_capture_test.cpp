// `pbvbus timeline` on a long capture (captures/timeline_window.hpp): the 10 s of
// examples/switched-io.textproto (two lines at 1.5 Mbit/s, 177044 frames) made a 4.4 MB page; by
// default the page now holds the frames of a window of at most 50000 frames and says so,
// --max-frames 0 gives everything, and --from chooses where the window starts.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "pbvbus/tools/commands.hpp"

namespace pbvbus::tools {
namespace {

namespace fs = std::filesystem;

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The frame count of the page's header line ("2 lanes · 25000 frames · ...").
long frames_in_page(const std::string& page) {
  std::smatch m;
  static const std::regex re("<div id=\"info\">[0-9]+ lanes? \xC2\xB7 ([0-9]+) frames");
  if (!std::regex_search(page, m, re)) return -1;
  return std::stol(m[1]);
}

// The header line after the frame count: "N events · FROM – TO".
std::string overview(const std::string& page) {
  std::smatch m;
  static const std::regex re(" frames \xC2\xB7 ([0-9]+ events \xC2\xB7 [^<]*)<");
  return std::regex_search(page, m, re) ? m[1].str() : std::string();
}

class TimelineLongCapture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    s_dir = new std::string((fs::temp_directory_path() / ("pbvbus_tl_long_" + std::to_string(::getpid()))).string());
    fs::create_directories(*s_dir);
    std::ostringstream out, err;
    s_rc = cmd_run({PBVBUS_SOURCE_DIR "/examples/switched-io.textproto", "--capture", capture(), "--quiet"}, out,
                   err);
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*s_dir, ec);
    delete s_dir;
  }
  static std::string capture() { return *s_dir + "/sw.pcapng"; }
  static std::string path(const char* name) { return *s_dir + "/" + name; }
  static inline std::string* s_dir = nullptr;
  static inline int s_rc = -1;
};

TEST_F(TimelineLongCapture, DefaultPageIsBoundedAndSaysWhatItLeavesOut) {
  ASSERT_EQ(s_rc, 0);
  std::ostringstream out, err;
  ASSERT_EQ(cmd_timeline({capture(), "-o", path("default.html")}, out, err), 0) << err.str();
  const std::string page = read(path("default.html"));
  // At most 50000 frames: about 1.5 MB instead of 4.4 MB.
  EXPECT_LT(page.size(), 1'800'000u);
  const long frames = frames_in_page(page);
  EXPECT_GT(frames, 49'000);
  EXPECT_LE(frames, 50'000);
  // The note, in the page and on stderr: from the start of the capture, N of M frames.
  const std::regex note("This page holds the frames of 0\\.000000 s \xE2\x80\x93 ([0-9.]+) s only \\(the "
                        "capture: 0\\.000000 s \xE2\x80\x93 [0-9]+\\.[0-9]+ s\\): ([0-9]+) of ([0-9]+) frames "
                        "\\(--max-frames 50000\\); events and the rows below the lanes cover the whole capture\\. "
                        "Use --from/--to for another stretch, --max-frames 0 for all\\.");
  std::smatch m;
  const std::string e = err.str();
  ASSERT_TRUE(std::regex_search(e, m, note)) << e;
  EXPECT_EQ(std::stol(m[2]), frames);
  EXPECT_EQ(std::stol(m[3]), 177'032);  // 10 s of two lines at 1.5 Mbit/s (IMs switching in their own time)
  EXPECT_NE(page.find("<p id=\"note\" class=\"note\"><strong>This page holds the frames of 0.000000 s"),
            std::string::npos);
  // The overview stays whole: the same events and the same span as the page of everything (the
  // fault script runs to 9 s, long after the window).
  std::ostringstream out2, err2;
  ASSERT_EQ(cmd_timeline({capture(), "-o", path("whole.html"), "--max-frames", "0"}, out2, err2), 0);
  EXPECT_EQ(overview(page), overview(read(path("whole.html"))));
  EXPECT_NE(overview(page), "");
}

TEST_F(TimelineLongCapture, MaxFramesZeroHoldsEverythingAndFromChoosesTheWindow) {
  ASSERT_EQ(s_rc, 0);
  std::ostringstream out, err;
  ASSERT_EQ(cmd_timeline({capture(), "-o", path("all.html"), "--max-frames", "0"}, out, err), 0) << err.str();
  EXPECT_EQ(err.str(), "");
  const std::string all = read(path("all.html"));
  EXPECT_GT(all.size(), 3'000'000u);
  EXPECT_EQ(all.find("id=\"note\""), std::string::npos);

  std::ostringstream out2, err2;
  ASSERT_EQ(cmd_timeline({capture(), "-o", path("w.html"), "--from", "5s", "--max-frames", "2000"}, out2, err2), 0)
      << err2.str();
  const std::string w = read(path("w.html"));
  EXPECT_LE(frames_in_page(w), 2000);
  EXPECT_GT(frames_in_page(w), 1900);
  EXPECT_LT(w.size(), 250'000u);
  EXPECT_NE(err2.str().find("This page holds the frames of 5.000000 s \xE2\x80\x93 5."), std::string::npos)
      << err2.str();

  std::ostringstream out3, err3;
  EXPECT_EQ(cmd_timeline({capture(), "--max-frames", "x"}, out3, err3), 2);
  EXPECT_NE(err3.str().find("--max-frames needs a number of frames"), std::string::npos) << err3.str();
}

}  // namespace
}  // namespace pbvbus::tools
