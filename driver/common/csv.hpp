// One field of a CSV file as RFC 4180 writes it: as it is, or in double quotes (with inner
// quotes doubled) when it holds a comma, a quote or a line break.
#pragma once

#include <string>

namespace plcfi::common {

inline std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace plcfi::common
