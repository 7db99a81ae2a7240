// Base64 (RFC 4648) for the binary DataArrays of VTK XML files.
//
// Hand-written because no Debian C++ package offers it as a small dependency (Boost.Beast's detail
// code is not public API) and the codec is short; it is a hot path for 500K-tet volumes, so it uses
// lookup tables and no per-character branching beyond whitespace.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace waxwork {

// Appends the base64 encoding of `size` bytes at `data` to `out`, with '=' padding.
void append_base64(const void* data, size_t size, std::string& out);

// Decodes base64 text, ignoring whitespace. Padding may end any 4-character group, not only the
// last one, because some writers encode a header and its data as two separate base64 streams that
// end up concatenated. nullopt when the text has a character outside the alphabet or a final group
// of fewer than 4 characters.
std::optional<std::vector<uint8_t>> decode_base64(std::string_view text);

}  // namespace waxwork
