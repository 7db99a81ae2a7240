#include "io/base64.h"

#include <array>

namespace waxwork {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

constexpr uint8_t kInvalid = 0xFF;
constexpr uint8_t kPadding = 0xFE;
constexpr uint8_t kSpace = 0xFD;

constexpr std::array<uint8_t, 256> make_decode_table() {
    std::array<uint8_t, 256> table{};
    for (auto& entry : table) entry = kInvalid;
    for (int i = 0; i < 64; ++i) table[static_cast<uint8_t>(kAlphabet[i])] = static_cast<uint8_t>(i);
    table[static_cast<uint8_t>('=')] = kPadding;
    for (char c : {' ', '\t', '\n', '\r', '\f', '\v'}) table[static_cast<uint8_t>(c)] = kSpace;
    return table;
}

constexpr std::array<uint8_t, 256> kDecode = make_decode_table();

}  // namespace

void append_base64(const void* data, size_t size, std::string& out) {
    const auto* bytes = static_cast<const uint8_t*>(data);
    const size_t start = out.size();
    out.resize(start + (size + 2) / 3 * 4);
    char* o = out.data() + start;
    size_t i = 0;
    for (; i + 3 <= size; i += 3) {
        const uint32_t v = (uint32_t{bytes[i]} << 16) | (uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
        *o++ = kAlphabet[(v >> 18) & 63];
        *o++ = kAlphabet[(v >> 12) & 63];
        *o++ = kAlphabet[(v >> 6) & 63];
        *o++ = kAlphabet[v & 63];
    }
    if (i < size) {
        uint32_t v = uint32_t{bytes[i]} << 16;
        if (i + 1 < size) v |= uint32_t{bytes[i + 1]} << 8;
        *o++ = kAlphabet[(v >> 18) & 63];
        *o++ = kAlphabet[(v >> 12) & 63];
        *o++ = i + 1 < size ? kAlphabet[(v >> 6) & 63] : '=';
        *o++ = '=';
    }
}

std::optional<std::vector<uint8_t>> decode_base64(std::string_view text) {
    std::vector<uint8_t> out(text.size() / 4 * 3 + 3);
    uint8_t* o = out.data();
    const auto* in = reinterpret_cast<const uint8_t*>(text.data());
    const uint8_t* const end = in + text.size();
    while (in < end && kDecode[*in] == kSpace) ++in;
    // Fast path: whole groups of four alphabet characters (all values < 64, so their OR is < 64).
    while (end - in >= 4) {
        const uint8_t a = kDecode[in[0]], b = kDecode[in[1]], c = kDecode[in[2]], d = kDecode[in[3]];
        if ((a | b | c | d) >= 64) break;
        const uint32_t v = (uint32_t{a} << 18) | (uint32_t{b} << 12) | (uint32_t{c} << 6) | d;
        o[0] = static_cast<uint8_t>(v >> 16);
        o[1] = static_cast<uint8_t>(v >> 8);
        o[2] = static_cast<uint8_t>(v);
        o += 3;
        in += 4;
    }
    // General path: whitespace anywhere, padding at the end of any group.
    std::array<uint8_t, 4> group{};
    int filled = 0;
    for (; in < end; ++in) {
        const uint8_t value = kDecode[*in];
        if (value == kSpace) continue;
        if (value == kInvalid) return std::nullopt;
        group[filled++] = value;
        if (filled < 4) continue;
        filled = 0;
        // Valid groups: four symbols, "xxx=" (2 bytes) or "xx==" (1 byte).
        if (group[0] == kPadding || group[1] == kPadding) return std::nullopt;
        if (group[2] == kPadding && group[3] != kPadding) return std::nullopt;
        const uint32_t v = (uint32_t{group[0]} << 18) | (uint32_t{group[1]} << 12) |
                           (group[2] == kPadding ? 0u : uint32_t{group[2]} << 6) |
                           (group[3] == kPadding ? 0u : uint32_t{group[3]});
        *o++ = static_cast<uint8_t>(v >> 16);
        if (group[2] != kPadding) *o++ = static_cast<uint8_t>(v >> 8);
        if (group[3] != kPadding) *o++ = static_cast<uint8_t>(v);
    }
    if (filled != 0) return std::nullopt;
    out.resize(static_cast<size_t>(o - out.data()));
    return out;
}

}  // namespace waxwork
