// The one JSON library of the project (nlohmann-json) and the two layouts plcfi writes:
// compact lines (the campaign journal) and spaced one-line objects (the --json outputs).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace plcfi::common {

// Objects keep their keys in insertion order, so an output's field order is the code's.
using Json = nlohmann::ordered_json;

// {"a":1,"b":[1,2]}: no spaces. Invalid UTF-8 in a string becomes U+FFFD instead of an
// exception (a program's STRING may hold any byte).
std::string json_compact(const Json& j);

// {"a": 1, "b": [1, 2]}: one line, a space after ':' and ','.
std::string json_line(const Json& j);

// Parses one JSON text. On error: false, *err the reason ("syntax error while parsing
// value - invalid literal; last read: 'x'") and *column the 1-based position in `text`
// where parsing stopped.
bool json_parse(const std::string& text, Json* out, std::string* err, size_t* column);

}  // namespace plcfi::common
