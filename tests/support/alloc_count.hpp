#pragma once
// Counts heap allocations made through global operator new in this test binary
// (each suite that counts has an alloc_count_helpers.cpp that replaces it: tests/bus,
// tests/hotpath), so that tests can check a hot path allocates nothing.

#include <cstdint>

namespace pbvbus::test {
std::uint64_t allocation_count();
}
