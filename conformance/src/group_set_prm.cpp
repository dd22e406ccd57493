#include "groups.hpp"

namespace pbvbus::conformance::detail {

void add_set_prm_tests(std::vector<TestCase>& /*out*/) {}

}  // namespace pbvbus::conformance::detail
