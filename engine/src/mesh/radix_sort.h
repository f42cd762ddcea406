// A stable least-significant-digit radix sort of 64-bit keys, for the mesh checks' millions of
// packed edge and cell keys: three or four passes over the keys where std::sort compares each
// about log2(n) times (mesh_b at 400 cells: 4.1 million edge keys in about a fifth of the time).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace sdfcsg::detail {

// Sorts `items` by the bits [low, high) of key(item), a uint64_t, in place (with a buffer of
// the same size), keeping the order of items whose bits there are equal. Digits of 11 bits
// (2,048 counters, in the first level of cache); a digit that every item shares takes no pass.
template <class T, class Key> void radixSort(std::vector<T>& items, int low, int high, Key key) {
    constexpr int kDigit = 11;
    std::vector<T> buffer(items.size());
    for (int shift = low; shift < high; shift += kDigit) {
        const int width = high - shift < kDigit ? high - shift : kDigit;
        const uint64_t mask = (uint64_t(1) << width) - 1;
        std::array<size_t, size_t(1) << kDigit> start{};
        for (const T& item : items)
            ++start[(key(item) >> shift) & mask];
        if (!items.empty() && start[(key(items[0]) >> shift) & mask] == items.size()) continue;
        size_t at = 0;
        for (size_t& s : start) {
            const size_t count = s;
            s = at;
            at += count;
        }
        for (const T& item : items)
            buffer[start[(key(item) >> shift) & mask]++] = item;
        items.swap(buffer);
    }
}

inline void radixSort(std::vector<uint64_t>& keys, int low, int high) {
    radixSort(keys, low, high, [](uint64_t k) { return k; });
}

// The number of bits that values below `n` take.
inline int bitsFor(uint64_t n) {
    int bits = 0;
    while (bits < 64 && (uint64_t(1) << bits) < n)
        ++bits;
    return bits;
}

} // namespace sdfcsg::detail
