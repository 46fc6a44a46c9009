// JSON string escaping for the commands' --json output.
#pragma once

#include <string>

#include <fmt/format.h>

namespace plcfi::cli {

inline std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("\\u{:04x}", static_cast<int>(c));
    else out += c;
  }
  return out;
}

}  // namespace plcfi::cli
