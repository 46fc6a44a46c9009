// Source files and locations: every token, AST node and diagnostic points back here.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace plcfi::st {

// 1-based line and column; file is an index into SourceManager. line 0 = no location.
struct SourceLoc {
  uint32_t file = 0;
  uint32_t line = 0;
  uint32_t col = 0;
  bool valid() const { return line != 0; }
};

struct SourceFile {
  std::string path;     // as given by the user (shown in messages)
  std::string text;     // whole content
  std::vector<uint32_t> line_starts;  // byte offset of each line start

  std::string_view line_text(uint32_t line) const;  // without the line break
};

// Owns all loaded sources of one compilation. Not thread-safe; one per compile.
class SourceManager {
 public:
  // Adds a buffer; returns its file index.
  uint32_t add(std::string path, std::string text);
  // Reads a file; returns false and fills err when it cannot be read.
  bool load(const std::string& path, uint32_t* index, std::string* err);

  const SourceFile& file(uint32_t index) const { return *files_[index]; }
  size_t size() const { return files_.size(); }

 private:
  std::vector<std::unique_ptr<SourceFile>> files_;
};

// IEC names are case-insensitive: compare and hash through this canonical form.
std::string canon(std::string_view name);
bool iequals(std::string_view a, std::string_view b);

}  // namespace plcfi::st
