#include "groups.hpp"

namespace pbvbus::conformance::detail {

void add_read_service_tests(std::vector<TestCase>& /*out*/) {}

}  // namespace pbvbus::conformance::detail
