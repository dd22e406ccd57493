#pragma once
// Counts heap allocations made through global operator new in this test binary
// (alloc_count_helpers.cpp replaces it), so that tests can check a hot path allocates nothing.

#include <cstdint>

namespace pbvbus::test {
std::uint64_t allocation_count();
}
