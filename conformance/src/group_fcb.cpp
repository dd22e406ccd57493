#include "groups.hpp"

namespace pbvbus::conformance::detail {

void add_fcb_tests(std::vector<TestCase>& /*out*/) {}

}  // namespace pbvbus::conformance::detail
