// The range allocator behind device-memory suballocation; no GPU needed.
#include "glint/gpu/memory.h"

#include <doctest/doctest.h>

#include <random>
#include <vector>

using glint::gpu::RangeAllocator;

TEST_CASE("range allocator honours alignment and keeps the padding free") {
    RangeAllocator r(1024);
    const auto a = r.allocate(10, 1);
    REQUIRE(a);
    CHECK(*a == 0);
    const auto b = r.allocate(100, 256);
    REQUIRE(b);
    CHECK(*b == 256);
    // The 246 bytes of padding between a and b are still usable.
    const auto c = r.allocate(200, 8);
    REQUIRE(c);
    CHECK(*c >= 10);
    CHECK(*c + 200 <= 256);
    CHECK(r.used() == 310);
}

TEST_CASE("range allocator refuses what does not fit and bad alignments") {
    RangeAllocator r(256);
    CHECK_FALSE(r.allocate(257, 1));
    CHECK_FALSE(r.allocate(0, 1));
    CHECK_FALSE(r.allocate(16, 3));
    REQUIRE(r.allocate(256, 256));
    CHECK_FALSE(r.allocate(1, 1));
}

TEST_CASE("range allocator coalesces neighbours on free") {
    RangeAllocator r(300);
    const auto a = *r.allocate(100, 1);
    const auto b = *r.allocate(100, 1);
    const auto c = *r.allocate(100, 1);
    r.free(a, 100);
    r.free(c, 100);
    CHECK(r.freeRangeCount() == 2);
    r.free(b, 100);
    CHECK(r.freeRangeCount() == 1);
    CHECK(r.empty());
    CHECK(r.allocate(300, 1) == 0u);
}

TEST_CASE("range allocator never hands out overlapping ranges (random workload)") {
    std::mt19937 rng(1234);
    RangeAllocator r(1 << 20);
    struct Live { uint64_t offset, size; };
    std::vector<Live> live;
    for (int step = 0; step < 5000; ++step) {
        if (!live.empty() && (rng() % 3 == 0)) {
            const size_t i = rng() % live.size();
            r.free(live[i].offset, live[i].size);
            live.erase(live.begin() + static_cast<std::ptrdiff_t>(i));
            continue;
        }
        const uint64_t size = 1 + rng() % 4096;
        const uint64_t alignment = uint64_t(1) << (rng() % 9);
        if (auto o = r.allocate(size, alignment)) {
            REQUIRE(*o % alignment == 0);
            REQUIRE(*o + size <= r.capacity());
            for (const auto& l : live) {
                REQUIRE((*o + size <= l.offset || l.offset + l.size <= *o));
            }
            live.push_back({*o, size});
        }
    }
    uint64_t used = 0;
    for (const auto& l : live) used += l.size;
    CHECK(r.used() == used);
    for (const auto& l : live) r.free(l.offset, l.size);
    CHECK(r.empty());
    CHECK(r.freeRangeCount() == 1);
}
