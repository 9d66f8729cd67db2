// Counts heap allocations in a test binary: linking bbw_test_alloc_counter replaces the global
// operator new/delete with counting versions. Use it in a binary of its own.
#pragma once

namespace bbw::test {

long allocation_count();  // global operator new calls so far (relaxed atomic)

}  // namespace bbw::test
