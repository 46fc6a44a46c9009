// Source buffers, line tables and the case-insensitive name helpers.
#include "source.hpp"

#include <cctype>

#include "common/file.hpp"

namespace plcfi::st {

std::string_view SourceFile::line_text(uint32_t line) const {
  if (line == 0 || line > line_starts.size()) return {};
  size_t begin = line_starts[line - 1];
  size_t end = line < line_starts.size() ? line_starts[line] : text.size();
  while (end > begin && (text[end - 1] == '\n' || text[end - 1] == '\r')) --end;
  return std::string_view(text).substr(begin, end - begin);
}

uint32_t SourceManager::add(std::string path, std::string text) {
  auto f = std::make_unique<SourceFile>();
  f->path = std::move(path);
  f->text = std::move(text);
  f->line_starts.push_back(0);
  for (size_t i = 0; i < f->text.size(); ++i)
    if (f->text[i] == '\n') f->line_starts.push_back(static_cast<uint32_t>(i + 1));
  files_.push_back(std::move(f));
  return static_cast<uint32_t>(files_.size() - 1);
}

bool SourceManager::load(const std::string& path, uint32_t* index, std::string* err) {
  std::string text;
  if (!common::read_file(path, common::kMaxSourceBytes, &text, err)) return false;
  *index = add(path, std::move(text));
  return true;
}

uint32_t SourceManager::add_generated(std::string name, std::string text, std::vector<LineOrigin> origins) {
  std::vector<SourceFile::Origin> resolved;
  resolved.reserve(origins.size());
  for (auto& o : origins) {
    SourceFile::Origin r;
    if (!o.path.empty() && o.line != 0) {
      bool found = false;
      for (uint32_t f = 0; f < files_.size() && !found; ++f)
        if (files_[f]->path == o.path && files_[f]->origins.empty()) r.file = f, found = true;
      std::string err;
      if (!found && !load(o.path, &r.file, &err)) o.line = 0;
    }
    r.where = std::move(o);
    resolved.push_back(std::move(r));
  }
  uint32_t index = add(std::move(name), std::move(text));
  files_[index]->origins = std::move(resolved);
  return index;
}

SourceLoc SourceManager::origin(SourceLoc loc, std::string* context) const {
  if (loc.file >= files_.size() || loc.line == 0) return loc;
  const auto& origins = files_[loc.file]->origins;
  if (loc.line > origins.size()) return loc;
  const auto& [o, file] = origins[loc.line - 1];
  if (o.line == 0) {
    if (context && !o.context.empty()) *context = o.context;
    return loc;
  }
  if (context) *context = o.context;
  uint32_t col = o.col;
  if (o.exact_columns && loc.col > o.prefix) {
    uint32_t offset = loc.col - o.prefix - 1;
    if (!o.col_map.empty()) offset = offset < o.col_map.size() ? o.col_map[offset] : o.col_map.back() + 1;
    col += offset;
  }
  return SourceLoc{file, o.line, col};
}

std::string canon(std::string_view name) {
  std::string out(name);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::toupper(static_cast<unsigned char>(a[i])) != std::toupper(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

}  // namespace plcfi::st
