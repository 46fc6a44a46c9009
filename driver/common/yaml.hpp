// The one strict YAML document reader of the project's spec files (campaigns, TSDs, fault
// classes, io sections, EDTL requirements, plant parameters), on yaml-cpp.
//
// Strict means: a duplicate key anywhere in the document, an unknown key, a missing
// required key and a value of the wrong type are all errors, because a typo in a spec
// must never fall back to a default silently. Every error reads "FILE:LINE:COL: message"
// in one wording:
//   unknown key 'K' in WHAT (expected one of: A, B, C)
//   duplicate key 'K' (first at LINE:COL)
//   missing key 'K' in WHAT
//   WHAT: expected a map | a list | a single value | an integer | a number | true or false
//         | A, B or C, got 'TEXT' | a list | a map | nothing
//   WHAT: N is outside LO..HI
//   WHAT: expected a duration, got 'TEXT': DETAIL
// A loader calls the getters and throws nothing itself but through fail(); the errors are
// exceptions (InputError) because they unwind a recursive loader at start-up; an entry
// point turns them into a message with catch_input_error().
#pragma once

#include <cstdint>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <string_view>

#include <yaml-cpp/yaml.h>

#include "common/file.hpp"

namespace plcfi::common {

// A user's bad input; what() is the whole message, location included.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs f(); an InputError becomes false and its message in *err.
template <class F>
bool catch_input_error(std::string* err, F&& f) {
  try {
    f();
    return true;
  } catch (const InputError& e) {
    *err = e.what();
    return false;
  } catch (const YAML::Exception& e) {
    // A loader's slip (a subscript on a scalar): still a message, never a crash.
    *err = std::string("YAML: ") + e.what();
    return false;
  }
}

class YamlDoc {
 public:
  // Reads `path` (at most max_bytes) and parses it. Throws InputError on a file error,
  // a syntax error or a duplicate key.
  static YamlDoc open(const std::string& path, size_t max_bytes = kMaxSpecBytes);
  // The same on text already in memory; `path` names it in messages.
  static YamlDoc parse(const std::string& path, const std::string& text);

  const std::string& path() const { return path_; }
  const YAML::Node& root() const { return root_; }

  // 1-based line and column of a node ("quoted" scalars: the column of the quote).
  uint32_t line(const YAML::Node& n) const;
  uint32_t col(const YAML::Node& n) const;
  // The column where a scalar's text starts (after a quote).
  uint32_t text_col(const YAML::Node& n) const;
  std::string where(const YAML::Node& n) const;  // "FILE:LINE:COL"

  [[noreturn]] void fail(const YAML::Node& n, const std::string& message) const;
  // At `offset` characters into a one-line scalar's text.
  [[noreturn]] void fail_in(const YAML::Node& n, size_t offset, const std::string& message) const;

  // A map whose every key is one of `known`. A null node passes when allow_null (an empty
  // section "slider:" is an empty map).
  void check_keys(const YAML::Node& map, std::initializer_list<std::string_view> known, std::string_view what,
                  bool allow_null = false) const;
  // map[key], which must exist.
  YAML::Node required(const YAML::Node& map, const char* key, std::string_view what) const;
  // A list (allow_empty: possibly empty); returns it for a range-for. By value (a node is
  // a shared handle): a reference would dangle in `for (auto& x : doc.list(doc.required(...)))`.
  YAML::Node list(const YAML::Node& n, std::string_view what, bool allow_empty = false) const;

  std::string scalar(const YAML::Node& n, std::string_view what) const;
  // Decimal or 0x hexadecimal, within [lo, hi].
  int64_t integer(const YAML::Node& n, std::string_view what, int64_t lo = INT64_MIN, int64_t hi = INT64_MAX) const;
  double number(const YAML::Node& n, std::string_view what) const;  // finite
  bool boolean(const YAML::Node& n, std::string_view what) const;    // true/false (any case), yes/no, on/off
  // A duration in nanoseconds (see common/duration.hpp), at least min_ns.
  int64_t duration(const YAML::Node& n, std::string_view what, int64_t min_ns = 0) const;
  // One of `allowed`, spelt exactly.
  std::string word(const YAML::Node& n, std::string_view what, std::initializer_list<std::string_view> allowed) const;

  // "'text'", "a list", "a map", "nothing": what a message says was found.
  static std::string describe(const YAML::Node& n);

 private:
  YamlDoc(std::string path, YAML::Node root) : path_(std::move(path)), root_(std::move(root)) {}
  void check_duplicates(const YAML::Node& n, size_t* budget) const;

  std::string path_;
  YAML::Node root_;
};

// "a, b or c": a list of choices in a message.
std::string choice_list(std::initializer_list<std::string_view> items, std::string_view last_sep = " or ");

}  // namespace plcfi::common
