// WSTRING text: the engine holds a WSTRING as UTF-16 code units (IEC 61131-3, CODESYS,
// TwinCAT), source text and STRING values are UTF-8. These convert at the boundaries:
// literals, STRING <-> WSTRING conversions, and the host's std::string view of values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace plcfi::st {

// UTF-8 to code units: characters beyond the BMP become surrogate pairs; a 3-byte
// sequence of a surrogate (the lexer's "$D83D" escape) stays that one unit; a byte that
// starts no valid sequence is its Latin-1 character (a STRING '$E4' is 'ä', as the
// PLCs' STRING code page reads it).
std::u16string utf8_to_utf16(std::string_view s);
// Code units to UTF-8; a lone surrogate as its 3-byte sequence (the inverse of the above).
std::string utf16_to_utf8(std::u16string_view s);

// The WSTRING at p: its code units before the terminator, at most cap.
std::u16string load_wstring(const uint8_t* p, size_t cap);
// Stores s at p, a WSTRING of capacity cap code units: truncated, then terminated.
void store_wstring(uint8_t* p, size_t cap, std::u16string_view s);

}  // namespace plcfi::st
