// The captures suite's tshark helpers (tests/captures/tshark_helpers.hpp), compiled into this
// suite too: the test CMake links each suite's own *_helpers.cpp files only.
#include "../captures/tshark_helpers.cpp"  // NOLINT(bugprone-suspicious-include)
