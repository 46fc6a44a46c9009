// Layouts of JSON output on top of nlohmann-json's own scalar serialization.
#include "common/json.hpp"

namespace plcfi::common {

namespace {

std::string scalar_text(const Json& j) { return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace); }

void append_line(const Json& j, std::string* out) {
  if (j.is_object()) {
    *out += '{';
    bool first = true;
    for (const auto& [key, value] : j.items()) {
      if (!first) *out += ", ";
      first = false;
      *out += scalar_text(Json(key));
      *out += ": ";
      append_line(value, out);
    }
    *out += '}';
  } else if (j.is_array()) {
    *out += '[';
    for (size_t i = 0; i < j.size(); ++i) {
      if (i) *out += ", ";
      append_line(j[i], out);
    }
    *out += ']';
  } else {
    *out += scalar_text(j);
  }
}

}  // namespace

std::string json_compact(const Json& j) { return scalar_text(j); }

std::string json_line(const Json& j) {
  std::string out;
  append_line(j, &out);
  return out;
}

bool json_parse(const std::string& text, Json* out, std::string* err, size_t* column) {
  try {
    *out = Json::parse(text);
    return true;
  } catch (const nlohmann::json::parse_error& e) {
    // what() is "[json.exception.parse_error.101] parse error at line 1, column 4: REASON":
    // the caller names its own file, line and column, so only REASON is kept.
    const std::string what = e.what();
    const size_t at = what.find("parse error at ");
    const size_t reason = at == std::string::npos ? std::string::npos : what.find(": ", at);
    *err = reason == std::string::npos ? what : what.substr(reason + 2);
    *column = e.byte == 0 ? 1 : e.byte;
    return false;
  } catch (const nlohmann::json::exception& e) {
    *err = e.what();
    *column = 1;
    return false;
  }
}

}  // namespace plcfi::common
