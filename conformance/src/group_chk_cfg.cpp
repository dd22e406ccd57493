#include "groups.hpp"

namespace pbvbus::conformance::detail {

void add_chk_cfg_tests(std::vector<TestCase>& /*out*/) {}

}  // namespace pbvbus::conformance::detail
