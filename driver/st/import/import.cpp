// Which reader a file goes to, by its extension (case-insensitive, as Windows tools
// write them), and which files of a library folder are read.
#include "import/import.hpp"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace plcfi::st {

namespace {

std::string extension_of(std::string_view path) {
  size_t slash = path.find_last_of("/\\");
  std::string_view name = slash == std::string_view::npos ? path : path.substr(slash + 1);
  size_t dot = name.rfind('.');
  return dot == std::string_view::npos ? std::string() : canon(name.substr(dot + 1));
}

}  // namespace

InputKind input_kind(std::string_view path) {
  std::string ext = extension_of(path);
  if (ext == "XML") return InputKind::PlcopenXml;
  if (ext == "PLCPROJ" || ext == "TCPOU" || ext == "TCDUT" || ext == "TCGVL" || ext == "TCIO" || ext == "TCTTO")
    return InputKind::TwinCat;
  return InputKind::St;
}

bool library_sources(const std::string& dir, std::vector<std::string>* files, std::string* err) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (!fs::exists(status)) {
    *err = "--library '" + dir + "': no such directory";
    return false;
  }
  if (!fs::is_directory(status)) {
    *err = "--library '" + dir + "': not a directory";
    return false;
  }
  std::vector<std::string> projects, sources, compiled;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!name.empty() && name[0] == '.') {
      if (it->is_directory(ec)) it.disable_recursion_pending();
      continue;
    }
    if (!it->is_regular_file(ec)) continue;
    const std::string path = it->path().string();
    const std::string ext = extension_of(path);
    if (ext == "PLCPROJ") projects.push_back(path);
    else if (ext == "ST" || ext == "XML" || (input_kind(path) == InputKind::TwinCat)) sources.push_back(path);
    else if (ext == "LIBRARY" || ext == "COMPILED-LIBRARY") compiled.push_back(path);
  }
  if (ec) {
    *err = "--library '" + dir + "': " + ec.message();
    return false;
  }
  std::vector<std::string>& found = projects.empty() ? sources : projects;
  if (found.empty()) {
    *err = "--library '" + dir + "': no ST sources (.st), TwinCAT files (.plcproj, .TcPOU, .TcDUT, .TcGVL, ...) or PLCopen XML (.xml) in it";
    if (!compiled.empty())
      *err += " (a .library or .compiled-library file is a compiled library plcfi cannot read: give the library's sources)";
    return false;
  }
  std::sort(found.begin(), found.end());
  files->insert(files->end(), found.begin(), found.end());
  return true;
}

}  // namespace plcfi::st
