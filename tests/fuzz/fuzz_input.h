#pragma once
// Reads a fuzzer's bytes as a stream of small choices; past the end every
// read is 0, so any input, however short, decodes to something.

#include <cstddef>
#include <cstdint>

namespace glint::fuzz {

class Input {
public:
    Input(const uint8_t* data, size_t size) : data_(data), size_(size) {}

    uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
    uint32_t u32() {
        uint32_t v = 0;
        for (int i = 0; i < 4; ++i) v = v << 8 | byte();
        return v;
    }
    // In [0, n); 0 when n is 0.
    uint32_t below(uint32_t n) { return n == 0 ? 0 : (n <= 256 ? byte() % n : u32() % n); }
    bool flag() { return (byte() & 1) != 0; }
    bool empty() const { return pos_ >= size_; }

private:
    const uint8_t* data_;
    size_t size_;
    size_t pos_ = 0;
};

} // namespace glint::fuzz
