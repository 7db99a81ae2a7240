// Exact, locale-independent number formatting for the ASCII mesh writers (Gmsh, MEDIT, TetGen).
// std::to_chars gives the shortest text that parses back to the same double, so foreign formats
// keep geometry bit-exact, and it is several times faster than printf("%.17g").
#pragma once

#include <charconv>
#include <cstdint>
#include <string>

namespace waxwork {

inline void append_number(std::string& out, double value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, result.ptr);
}

inline void append_number(std::string& out, int64_t value) {
    char buffer[24];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, result.ptr);
}

}  // namespace waxwork
