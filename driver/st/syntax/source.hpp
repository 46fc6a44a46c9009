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

// Where a line of generated text (a requirement monitor, the precondition program, an
// imported POU) came from: the user's file and the position of the text copied into it,
// so a diagnostic in the generated line points into the user's file.
struct LineOrigin {
  std::string path;       // the user's file; empty: the line has no origin (boilerplate)
  uint32_t line = 0;      // position of the copied text's first character there
  uint32_t col = 0;
  uint32_t prefix = 0;    // columns of generated text before the copy on this line
  // Offset in the copy -> offset in the user's text, when the copy was rewritten (an
  // operator spelled another way); empty: the same columns.
  std::vector<uint32_t> col_map;
  bool exact_columns = true;  // false: every column of the line points at `col`
  // An importer wrote this line itself (an LD/FBD network's statement, jump or label), as
  // opposed to user text copied from the file: it may use what only importers write
  // (jumps in any dialect, hidden temporaries; see Parser::synthesized_line).
  bool generated = false;
  std::string context;        // appended to the message, in parentheses ("in the precondition of ...")
};

struct SourceFile {
  std::string path;     // as given by the user (shown in messages)
  std::string text;     // whole content
  std::vector<uint32_t> line_starts;  // byte offset of each line start
  // Generated text only: one entry per line (index = line - 1), resolved to file indexes.
  struct Origin {
    LineOrigin where;
    uint32_t file = 0;
  };
  std::vector<Origin> origins;
  // A file of a library given as sources (--library): its code is library code, like the
  // libraries plcfi brings (no warnings, coverage or listing of its own).
  bool library = false;

  std::string_view line_text(uint32_t line) const;  // without the line break
};

// Owns all loaded sources of one compilation. Not thread-safe; one per compile.
class SourceManager {
 public:
  // Adds a buffer; returns its file index.
  uint32_t add(std::string path, std::string text);
  // Reads a file; returns false and fills err when it cannot be read.
  bool load(const std::string& path, uint32_t* index, std::string* err);
  // Adds generated text whose lines came from the users' files (`origins`, index = line
  // - 1; shorter is fine). The origin files are read once, here, so messages can show
  // their lines; one that cannot be read leaves its lines without an origin.
  uint32_t add_generated(std::string name, std::string text, std::vector<LineOrigin> origins);
  // Where `loc` points in the user's file (itself when it is not in generated text with
  // an origin); *context gets the origin's context text, or stays as it is.
  SourceLoc origin(SourceLoc loc, std::string* context = nullptr) const;

  const SourceFile& file(uint32_t index) const { return *files_[index]; }
  // Marks the files from `first` on (the ones a library's sources were loaded into) as
  // library files.
  void mark_library(uint32_t first) {
    for (size_t i = first; i < files_.size(); ++i) files_[i]->library = true;
  }
  size_t size() const { return files_.size(); }

 private:
  std::vector<std::unique_ptr<SourceFile>> files_;
};

// IEC names are case-insensitive: compare and hash through this canonical form.
std::string canon(std::string_view name);
bool iequals(std::string_view a, std::string_view b);

}  // namespace plcfi::st
