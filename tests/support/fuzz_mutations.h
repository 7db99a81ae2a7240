// Deterministic mutations of a valid file's bytes, for the fuzzing tests: each case is a few edits
// drawn from one seeded generator, so a failing case is reproduced by its seed and index alone.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace waxwork::testing {

// Values that break readers: non-numbers, overflow, underflow, negatives, index extremes, and
// float's range edge.
inline const std::vector<std::string>& hostile_numbers() {
    static const std::vector<std::string> values = {
        "nan", "-nan", "inf", "-inf", "1e308", "-1e308", "1e400", "3.5e38", "1e13", "1e-320", "0", "-0", "-1",
        "2147483648", "9223372036854775808", "18446744073709551615", "4294967295", "1.5", "x", "", "0x10", "+1"};
    return values;
}

class ByteMutator {
public:
    explicit ByteMutator(uint64_t seed) : random_(seed) {}

    // One to three edits of `text` (never the same text back, except by chance).
    std::string mutate(std::string text) {
        const int edits = 1 + static_cast<int>(pick(3));
        for (int i = 0; i < edits; ++i) text = edit(std::move(text));
        return text;
    }

    size_t pick(size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<size_t>(0, n - 1)(random_); }

private:
    // [begin, end) of a random line.
    std::pair<size_t, size_t> some_line(const std::string& text) {
        const size_t at = pick(text.size());
        size_t begin = text.rfind('\n', at);
        begin = begin == std::string::npos ? 0 : begin + 1;
        size_t end = text.find('\n', at);
        end = end == std::string::npos ? text.size() : end + 1;
        return {begin, end};
    }

    // [begin, end) of a random run of number characters, or {npos, npos}.
    std::pair<size_t, size_t> some_number(const std::string& text) {
        auto is_number_char = [](char c) { return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == 'e' || c == '+'; };
        for (int tries = 0; tries < 16; ++tries) {
            size_t at = pick(text.size());
            if (at >= text.size() || !(text[at] >= '0' && text[at] <= '9')) continue;
            size_t begin = at, end = at;
            while (begin > 0 && is_number_char(text[begin - 1])) --begin;
            while (end < text.size() && is_number_char(text[end])) ++end;
            return {begin, end};
        }
        return {std::string::npos, std::string::npos};
    }

    std::string edit(std::string text) {
        if (text.empty()) return "\n";
        switch (pick(9)) {
        case 0: {  // flip one bit
            text[pick(text.size())] ^= static_cast<char>(1u << pick(8));
            return text;
        }
        case 1:  // truncate
            return text.substr(0, pick(text.size()));
        case 2: {  // drop a line
            const auto [begin, end] = some_line(text);
            return text.erase(begin, end - begin);
        }
        case 3: {  // repeat a line
            const auto [begin, end] = some_line(text);
            return text.insert(begin, text.substr(begin, end - begin));
        }
        case 4:
        case 5: {  // a hostile number in place of a number
            const auto [begin, end] = some_number(text);
            if (begin == std::string::npos) return text;
            const auto& values = hostile_numbers();
            return text.replace(begin, end - begin, values[pick(values.size())]);
        }
        case 6:  // a NUL byte
            return text.insert(pick(text.size() + 1), 1, '\0');
        case 7: {  // swap two lines
            const auto [a0, a1] = some_line(text);
            const std::string line = text.substr(a0, a1 - a0);
            text.erase(a0, a1 - a0);
            if (text.empty()) return line;
            const auto [b0, b1] = some_line(text);
            (void)b1;
            return text.insert(b0, line);
        }
        default: {  // a run of random bytes
            std::string junk(1 + pick(16), '\0');
            for (char& c : junk) c = static_cast<char>(pick(256));
            return text.insert(pick(text.size() + 1), junk);
        }
        }
    }

    std::mt19937_64 random_;
};

}  // namespace waxwork::testing
